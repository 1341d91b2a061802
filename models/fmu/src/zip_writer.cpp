#include "zip_writer.hpp"

#include <array>
#include <limits>
#include <stdexcept>

namespace hystlab::fmu {
namespace {
constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t n = 0; n < 256; ++n) {
    std::uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1U) ? 0xedb88320U ^ (c >> 1) : c >> 1;
    t[n] = c;
  }
  return t;
}
constexpr auto kCrcTable = make_crc_table();
// 1980-01-01 00:00 in MS-DOS form: a fixed time, so the same element gives the same archive.
constexpr std::uint16_t kDosTime = 0, kDosDate = (0 << 9) | (1 << 5) | 1;

void u16(std::string& o, std::uint32_t v) {
  o.push_back(static_cast<char>(v & 0xffU));
  o.push_back(static_cast<char>((v >> 8) & 0xffU));
}
void u32(std::string& o, std::uint32_t v) {
  u16(o, v & 0xffffU);
  u16(o, v >> 16);
}
std::uint32_t checked32(std::size_t v, const char* what) {
  if (v > std::numeric_limits<std::uint32_t>::max()) throw std::length_error(std::string("zip: ") + what + " over 4 GiB");
  return static_cast<std::uint32_t>(v);
}
}  // namespace

std::uint32_t crc32(std::string_view data) {
  std::uint32_t c = 0xffffffffU;
  for (const char ch : data) c = kCrcTable[(c ^ static_cast<unsigned char>(ch)) & 0xffU] ^ (c >> 8);
  return c ^ 0xffffffffU;
}

void ZipWriter::add(std::string_view name, std::string_view data, std::uint32_t mode) {
  Entry e{std::string(name), crc32(data), checked32(data.size(), "an entry"), checked32(out_.size(), "the archive"), mode};
  u32(out_, 0x04034b50U);  // local file header
  u16(out_, 20);           // version needed: 2.0
  u16(out_, 0);            // flags
  u16(out_, 0);            // method: stored
  u16(out_, kDosTime);
  u16(out_, kDosDate);
  u32(out_, e.crc);
  u32(out_, e.size);
  u32(out_, e.size);
  u16(out_, checked32(name.size(), "a name"));
  u16(out_, 0);
  out_ += name;
  out_ += data;
  entries_.push_back(std::move(e));
}

std::string ZipWriter::finish() {
  const std::uint32_t dir_start = checked32(out_.size(), "the archive");
  for (const Entry& e : entries_) {
    u32(out_, 0x02014b50U);     // central directory header
    u16(out_, (3U << 8) | 20);  // made by: Unix, 2.0 (the mode below is Unix's)
    u16(out_, 20);
    u16(out_, 0);
    u16(out_, 0);
    u16(out_, kDosTime);
    u16(out_, kDosDate);
    u32(out_, e.crc);
    u32(out_, e.size);
    u32(out_, e.size);
    u16(out_, static_cast<std::uint32_t>(e.name.size()));
    u16(out_, 0);                          // extra
    u16(out_, 0);                          // comment
    u16(out_, 0);                          // disk
    u16(out_, 0);                          // internal attributes
    u32(out_, (0100000U | e.mode) << 16);  // external: a regular file with its permission bits
    u32(out_, e.offset);
    out_ += e.name;
  }
  const std::uint32_t dir_size = checked32(out_.size() - dir_start, "the directory");
  u32(out_, 0x06054b50U);  // end of central directory
  u16(out_, 0);
  u16(out_, 0);
  u16(out_, checked32(entries_.size(), "the entry count"));
  u16(out_, static_cast<std::uint32_t>(entries_.size()));
  u32(out_, dir_size);
  u32(out_, dir_start);
  u16(out_, 0);
  return std::move(out_);
}

}  // namespace hystlab::fmu
