#pragma once
// A PostgreSQL server of the test's own (Debian's postgresql-15 binaries): initdb into a
// temporary folder, a superuser "hystlab" with a password (scram-sha-256), listening on a free
// loopback port and a socket in the folder; stopped and removed with the fixture. As root (CI
// containers), the server runs as the unprivileged user "nobody", as initdb and postgres insist.
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon_process.hpp"
#include "temp_dir.hpp"

namespace hystlab::test_support {

inline std::string postgres_bindir() {
  for (const int v : {17, 16, 15, 14, 13})
    if (const std::string d = "/usr/lib/postgresql/" + std::to_string(v) + "/bin"; std::filesystem::exists(d + "/initdb")) return d;
  throw std::runtime_error("no PostgreSQL server binaries (/usr/lib/postgresql/*/bin/initdb): install Debian's postgresql");
}

class PostgresServer {
 public:
  static constexpr const char* kUser = "hystlab";
  static constexpr const char* kPassword = "lab-secret-123";

  PostgresServer() : dir_("pg"), bin_(postgres_bindir()), port_(free_port()) {
    data_ = (dir_ / "data").string();
    std::filesystem::create_directory(data_);
    dir_.write("pwfile", kPassword);
    if (::geteuid() == 0) {  // the server's files belong to nobody; the folder must let it in
      const passwd* pw = ::getpwnam("nobody");
      if (pw == nullptr) throw std::runtime_error("no user 'nobody' to run PostgreSQL as");
      ::chmod(dir_.path().c_str(), 0755);
      for (const std::string& p : {data_, (dir_ / "pwfile").string()})
        if (::chown(p.c_str(), pw->pw_uid, pw->pw_gid) != 0) throw std::runtime_error("cannot give " + p + " to nobody");
      ::chmod(data_.c_str(), 0700);
    }
    const int rc =
        run({bin_ + "/initdb", "-D", data_, "-U", kUser, "--pwfile=" + (dir_ / "pwfile").string(), "--auth=scram-sha-256", "-E", "UTF8", "--no-sync"},
            "initdb.log");
    if (rc != 0) throw std::runtime_error("initdb failed: " + read_log((dir_ / "initdb.log").string()));
    start();
    // The lab's database, as a lab's administrator would make it.
    const int c =
        run({"/usr/bin/env", "PGPASSWORD=" + std::string(kPassword), bin_ + "/createdb", "-h", "127.0.0.1", "-p", std::to_string(port_), "-U", kUser, "lab"},
            "createdb.log");
    if (c != 0) throw std::runtime_error("createdb failed: " + read_log((dir_ / "createdb.log").string()));
  }
  ~PostgresServer() { run({bin_ + "/pg_ctl", "-D", data_, "-m", "immediate", "-w", "stop"}, "stop.log"); }
  PostgresServer(const PostgresServer&) = delete;
  PostgresServer& operator=(const PostgresServer&) = delete;

  void start() {
    // The log and the socket in the data folder: the only one the server's user may write to.
    const std::string opts =
        "-p " + std::to_string(port_) + " -k " + data_ + " -c listen_addresses=127.0.0.1 -c fsync=off -c synchronous_commit=off -c full_page_writes=off";
    if (run({bin_ + "/pg_ctl", "-D", data_, "-l", data_ + "/server.log", "-w", "-t", "60", "-o", opts, "start"}, "start.log") != 0)
      throw std::runtime_error("pg_ctl start failed: " + read_log((dir_ / "start.log").string()) + read_log(data_ + "/server.log"));
  }
  // fast: clients disconnected, the server shut down cleanly (as an administrator's restart).
  void stop() {
    if (run({bin_ + "/pg_ctl", "-D", data_, "-m", "fast", "-w", "-t", "60", "stop"}, "stop.log") != 0)
      throw std::runtime_error("pg_ctl stop failed: " + read_log((dir_ / "stop.log").string()));
  }
  [[nodiscard]] int port() const noexcept { return port_; }
  // A URL without the password (as a config holds it).
  [[nodiscard]] std::string url(const std::string& db = "lab") const {
    return "postgresql://" + std::string(kUser) + "@127.0.0.1:" + std::to_string(port_) + "/" + db;
  }
  [[nodiscard]] const TempDir& dir() const noexcept { return dir_; }

 private:
  int run(std::vector<std::string> args, const std::string& log) {
    if (::geteuid() == 0) args.insert(args.begin(), {"/usr/sbin/runuser", "-u", "nobody", "--"});
    const std::string path = (dir_ / log).string();
    const int rc = run_logged(args, path);
    return rc;
  }
  TempDir dir_;
  std::string bin_, data_;
  int port_;
};

}  // namespace hystlab::test_support
