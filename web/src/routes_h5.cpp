// A run, or a whole campaign, as an HDF5 download (docs/FORMATS.md, "Runs as HDF5"). HDF5 writes
// a file, not a stream: the export goes to a fresh temporary file (bounded memory however long
// the run), which is opened and unlinked at once, so it disappears with its descriptor whether the
// client reads it all, goes away half-way, or the daemon dies; then it is sent from the descriptor.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>
#include <vector>

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

// At most this many exports at once: each compresses on a core the rig's loop may need, and a
// third request is told to come back rather than queued (503).
constexpr int kMaxH5Exports = 2;
std::atomic<int> g_h5_exports{0};

struct ExportSlot {
  ExportSlot() {
    if (g_h5_exports.fetch_add(1) >= kMaxH5Exports) {
      g_h5_exports.fetch_sub(1);
      throw ApiError(503, "busy", std::to_string(kMaxH5Exports) + " HDF5 exports are running; try again when one has finished");
    }
  }
  ExportSlot(const ExportSlot&) = delete;
  ExportSlot& operator=(const ExportSlot&) = delete;
  ~ExportSlot() { g_h5_exports.fetch_sub(1); }
};

// A name for the export beside the database (on the disk that holds the runs, not a tmpfs $TMPDIR
// that would hold the whole file in memory); removed when this goes (if still there).
struct TempName {
  explicit TempName(const std::string& db_path) {
    std::filesystem::path dir = std::filesystem::path(db_path).parent_path();
    if (dir.empty()) dir = ".";
    std::string t = (dir / "hystlab-export-XXXXXX.h5").string();
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
std::shared_ptr<OpenFile> export_to_temp(const std::string& db_path, Export export_to) {
  const ExportSlot slot;
  const TempName name(db_path);
  struct Release {
    ~Release() { db::release_export_memory(); }
  } const release;
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
  // The chunk buffer on the heap, not the stack: each export lands on another of the server's ~190
  // threads, and a 64 KiB stack buffer left that much of every thread's stack resident (stop 51:
  // 400 exports over HTTP grew the daemon 49 -> 73 MB, then flat, once every thread had served one).
  auto buf = std::make_shared<std::vector<char>>(kH5SendChunk);
  res.set_content_provider(static_cast<std::size_t>(size), "application/x-hdf5", [file, buf](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
    const ssize_t n = ::pread(file->fd, buf->data(), std::min(length, buf->size()), static_cast<off_t>(offset));
    return n > 0 && sink.write(buf->data(), static_cast<std::size_t>(n));
  });
}
}  // namespace

void add_h5_routes(httplib::Server& s, ApiContext& c) {
  s.Get(R"(/api/runs/(\d+)/samples\.h5)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          db::ReadSource& store = reader(c.db_path);
          const std::int64_t id = path_id(req);
          auto file = export_to_temp(c.db_path, [&](const std::string& path) { (void)db::export_run_h5(store, id, path); });
          send_file(res, std::move(file), "run-" + std::to_string(id) + ".h5");
        }));
  s.Get(R"(/api/campaigns/(\d+)/samples\.h5)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          db::ReadSource& store = reader(c.db_path);
          const std::int64_t id = path_id(req);
          auto file = export_to_temp(c.db_path, [&](const std::string& path) { (void)db::export_campaign_h5(store, id, path); });
          send_file(res, std::move(file), "campaign-" + std::to_string(id) + ".h5");
        }));
}

}  // namespace hystlab::web
