#pragma once
// A ZIP archive of stored (uncompressed) entries, enough for an FMU: local headers, a central
// directory and its end record (APPNOTE 6.3, no ZIP64: each entry and the whole under 4 GiB).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hystlab::fmu {

class ZipWriter {
 public:
  // mode: the Unix permission bits kept in the entry (0644 for files, 0755 for the binary).
  void add(std::string_view name, std::string_view data, std::uint32_t mode = 0644);
  [[nodiscard]] std::string finish();

 private:
  struct Entry {
    std::string name;
    std::uint32_t crc, size, offset, mode;
  };
  std::string out_;
  std::vector<Entry> entries_;
};

[[nodiscard]] std::uint32_t crc32(std::string_view data);

}  // namespace hystlab::fmu
