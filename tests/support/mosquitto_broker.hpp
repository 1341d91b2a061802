#pragma once
// Debian's mosquitto (/usr/sbin/mosquitto) as a test's broker: its own config in a TempDir, on a
// free loopback port, anonymous or with a password file; stopped (SIGTERM) and started again on
// the same port (a broker restart); stopped for good with the fixture. And mosquitto_sub, a real
// client in a process of its own, whose lines ("<retain> <qos> <topic>\t<payload>") a test reads.
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "daemon_process.hpp"
#include "temp_dir.hpp"

namespace hystlab::test_support {

inline void stop_process(pid_t& pid) {
  if (pid <= 0) return;
  kill(pid, SIGTERM);
  int st = 0;
  if (!wait_until([&] { return waitpid(pid, &st, WNOHANG) == pid; }, 10)) {
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
  }
  pid = -1;
}

class MosquittoBroker {
 public:
  // user and password empty: anonymous clients allowed; else only this user (a password file).
  explicit MosquittoBroker(const std::string& user = {}, const std::string& password = {}, int port = 0) : port_(port == 0 ? free_port() : port) {
    std::ostringstream conf;
    // user root: run as root, mosquitto would switch to its own user, who cannot read this 0700
    // folder. persistence false: a restart loses every retained message (what the test wants
    // to see published again).
    conf << "listener " << port_ << " 127.0.0.1\npersistence false\nuser root\nlog_dest stdout\nlog_type all\n";
    if (user.empty()) {
      conf << "allow_anonymous true\n";
    } else {
      const std::string pw = (dir_ / "passwd").string();
      pid_t p = spawn_logged({"/usr/bin/mosquitto_passwd", "-b", "-c", pw, user, password}, (dir_ / "passwd.log").string());
      int st = 0;
      waitpid(p, &st, 0);
      if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) throw std::runtime_error("mosquitto_passwd failed: " + read_log((dir_ / "passwd.log").string()));
      conf << "allow_anonymous false\npassword_file " << pw << "\n";
    }
    dir_.write("mosquitto.conf", conf.str());
    start();
  }
  ~MosquittoBroker() { stop(); }
  MosquittoBroker(const MosquittoBroker&) = delete;
  MosquittoBroker& operator=(const MosquittoBroker&) = delete;

  // Starts it (again, on the same port) and waits until it accepts connections.
  void start() {
    if (pid_ > 0) return;
    pid_ = spawn_logged({"/usr/sbin/mosquitto", "-c", (dir_ / "mosquitto.conf").string()}, (dir_ / ("broker" + std::to_string(starts_++) + ".log")).string());
    if (!wait_until([&] { return accepts(port_); }, 10)) throw std::runtime_error("mosquitto did not listen on port " + std::to_string(port_) + ":\n" + log());
  }
  void stop() { stop_process(pid_); }
  [[nodiscard]] int port() const noexcept { return port_; }
  [[nodiscard]] std::string log() const {
    std::string all;
    for (int k = 0; k < starts_; ++k) all += read_log((dir_ / ("broker" + std::to_string(k) + ".log")).string());
    return all;
  }

 private:
  TempDir dir_{"mosquitto"};
  int port_;
  pid_t pid_ = -1;
  int starts_ = 0;
};

// mosquitto_sub on one or more topic filters (QoS 1), each message a line of its file:
// "<retain 0|1> <qos> <topic>\t<payload>".
class Subscriber {
 public:
  Subscriber(int port, const std::vector<std::string>& topics, const std::string& user = {}, const std::string& password = {}) {
    std::vector<std::string> args{"/usr/bin/mosquitto_sub", "-h", "127.0.0.1", "-p", std::to_string(port), "-q", "1", "-F", "%r %q %t\\t%p"};
    for (const auto& t : topics) args.insert(args.end(), {"-t", t});
    if (!user.empty()) args.insert(args.end(), {"-u", user, "-P", password});
    pid_ = spawn_logged(args, (dir_ / "sub.log").string());
  }
  ~Subscriber() { stop(); }
  Subscriber(const Subscriber&) = delete;
  Subscriber& operator=(const Subscriber&) = delete;
  void stop() { stop_process(pid_); }

  struct Message {
    bool retained = false;
    std::string topic, payload;
  };
  // Every complete line so far.
  [[nodiscard]] std::vector<Message> messages() const {
    std::vector<Message> out;
    std::istringstream in(read_log((dir_ / "sub.log").string()));
    std::string line;
    while (std::getline(in, line)) {
      if (in.eof()) break;  // a line still being written
      const auto tab = line.find('\t');
      if (line.size() < 4 || tab == std::string::npos) continue;
      const auto sp = line.find(' ', 2);
      out.push_back({line[0] == '1', line.substr(sp + 1, tab - sp - 1), line.substr(tab + 1)});
    }
    return out;
  }
  // The messages on one topic.
  [[nodiscard]] std::vector<Message> on(const std::string& topic) const {
    std::vector<Message> out;
    for (auto& m : messages())
      if (m.topic == topic) out.push_back(m);
    return out;
  }
  [[nodiscard]] std::string text() const { return read_log((dir_ / "sub.log").string()); }

 private:
  TempDir dir_{"mqtt-sub"};
  pid_t pid_ = -1;
};

}  // namespace hystlab::test_support
