// hystlab rig reset|estop NAME: the operator's commands for a rig itself, queued for hystlabd
// through the db file (as campaign commands are); the daemon acts on them within 0.1 s.
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/db/store.hpp"

namespace hystlab::cli {
namespace {
const char* kRigHelp = R"(usage: hystlab rig reset NAME [--db hystlab.db]
       hystlab rig estop NAME [--db hystlab.db]

estop triggers the rig's e-stop at once, from any state; it stays latched in hystlabd as in the
controller. reset releases the rig's e-stop and fault signals; the latch clears when the rig then
reports ready without e-stop or fault (GET /api/rigs/NAME shows the state, or why it refused).
Nothing arms while a rig is latched.
)";
}  // namespace

int run_rig_cmd(const Args& args) {
  if (print_help_if_asked(args, kRigHelp) || args.size() < 2) {
    if (args.size() < 2) std::cout << kRigHelp;
    return args.size() < 2 ? 2 : 0;
  }
  const std::string verb = args[0], name = args[1];
  if (verb != "reset" && verb != "estop") throw CliError("unknown rig verb '" + verb + "' (reset or estop)");
  const Options opt(Args(args.begin() + 2, args.end()), {"db"}, {});
  db::Store store(opt.get("db", "hystlab.db"));
  std::string names;
  bool found = false;
  for (const auto& n : store.rig_names()) {
    found = found || n == name;
    names += (names.empty() ? "" : ", ") + n;
  }
  if (!found) throw CliError("no rig named '" + name + "'" + (names.empty() ? "" : " (the daemon's rigs: " + names + ")"));
  store.add_rig_command(name, verb, now_iso8601());
  std::cout << verb << " sent to rig '" << name << "'\n";
  return 0;
}

}  // namespace hystlab::cli
