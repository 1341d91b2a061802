// A run, or a whole campaign, as an HDF5 download (docs/FORMATS.md, "Runs as HDF5"). HDF5 writes
// a file, not a stream: the export goes to a fresh temporary file (bounded memory however long
// the run), which is opened and unlinked at once, so it disappears with its descriptor whether the
// client reads it all, goes away half-way, or the daemon dies; then it is sent from the descriptor.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>

#include "hystlab/db/run_h5.hpp"
#include "routes.hpp"

namespace hystlab::web {
namespace {
constexpr std::size_t kH5SendChunk = 1U << 16;

struct OpenFile {  // a descriptor closed when the last response holding it is gone
  explicit OpenFile(int f) : fd(f) {}
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;
  ~OpenFile() { ::close(fd); }
  int fd;
};

// A name for the export in the system's temporary folder; removed when this goes (if still there).
struct TempName {
  TempName() {
    std::string t = (std::filesystem::temp_directory_path() / "hystlab-export-XXXXXX.h5").string();
    const int fd = ::mkstemps(t.data(), 3);
    if (fd < 0) throw ApiError(500, "internal error", std::string("cannot create a temporary file for the export: ") + std::strerror(errno));
    ::close(fd);
    path = t;
  }
  TempName(const TempName&) = delete;
  TempName& operator=(const TempName&) = delete;
  ~TempName() { ::unlink(path.c_str()); }
  std::string path;
};

// Runs the export into a temporary file and returns it open and already unlinked.
template <class Export>
std::shared_ptr<OpenFile> export_to_temp(Export export_to) {
  const TempName name;
  try {
    export_to(name.path);
  } catch (const db::H5ExportError& e) {
    if (e.kind == db::H5ExportError::Kind::write) throw ApiError(500, "export failed", e.what());
    throw ApiError(404, "not found", e.what());
  }
  const int fd = ::open(name.path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw ApiError(500, "export failed", std::string("cannot read the export back: ") + std::strerror(errno));
  return std::make_shared<OpenFile>(fd);  // ~TempName unlinks the name; the data lives while fd does
}

void send_file(httplib::Response& res, std::shared_ptr<OpenFile> file, const std::string& filename) {
  const off_t size = ::lseek(file->fd, 0, SEEK_END);
  if (size < 0) throw ApiError(500, "export failed", std::string("cannot size the export: ") + std::strerror(errno));
  res.set_header("Content-Disposition", "attachment; filename=\"" + filename + "\"");
  res.set_content_provider(static_cast<std::size_t>(size), "application/x-hdf5",
                           [file](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                             char buf[kH5SendChunk];
                             const ssize_t n = ::pread(file->fd, buf, std::min(length, sizeof buf), static_cast<off_t>(offset));
                             return n > 0 && sink.write(buf, static_cast<std::size_t>(n));
                           });
}
}  // namespace

void add_h5_routes(httplib::Server& s, ApiContext& c) {
  s.Get(R"(/api/runs/(\d+)/samples\.h5)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    db::Store& store = reader(c.db_path);
    const std::int64_t id = path_id(req);
    auto file = export_to_temp([&](const std::string& path) { (void)db::export_run_h5(store, id, path); });
    send_file(res, std::move(file), "run-" + std::to_string(id) + ".h5");
  }));
  s.Get(R"(/api/campaigns/(\d+)/samples\.h5)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    db::Store& store = reader(c.db_path);
    const std::int64_t id = path_id(req);
    auto file = export_to_temp([&](const std::string& path) { (void)db::export_campaign_h5(store, id, path); });
    send_file(res, std::move(file), "campaign-" + std::to_string(id) + ".h5");
  }));
}

}  // namespace hystlab::web
