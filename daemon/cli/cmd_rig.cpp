// hystlab rig reset|estop|recover NAME: the operator's commands for a rig itself, sent to the running
// hystlabd over its HTTP API (daemon_client.hpp), as the page's e-stop button sends them.
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "daemon_client.hpp"

namespace hystlab::cli {
namespace {
const char* kRigHelp = R"(usage: hystlab rig reset NAME [--daemon URL] [--token T]
       hystlab rig estop NAME [--daemon URL] [--token T]
       hystlab rig recover NAME [--daemon URL] [--token T]

estop triggers the rig's e-stop at once, from any state; it stays latched in hystlabd as in the
controller. reset releases the rig's e-stop and fault signals; the latch clears when the rig then
reports ready without e-stop or fault (GET /api/rigs/NAME shows the state, or why it refused).
recover brings a load frame that has left its stroke (latched, "limit tripped") back into it:
the controller is reset into its limit recovery and the frame ramped at the safe rate to 0.5 mm
inside the configured stroke, then disabled; a reset alone cannot clear it while it is beyond.
Nothing arms while a rig is latched. All go to the running daemon: --daemon (or
$HYSTLAB_DAEMON, default http://127.0.0.1:8080), with its token when it has one ($HYSTLAB_TOKEN,
or --token, which others see in ps).
)";
}  // namespace

int run_rig_cmd(const Args& args) {
  if (print_help_if_asked(args, kRigHelp)) return 0;
  if (args.size() < 2) {  // a verb without its rig: the usage, as a refusal
    std::cout << kRigHelp;
    return 2;
  }
  const std::string verb = args[0], name = args[1];
  if (verb != "reset" && verb != "estop" && verb != "recover") throw CliError("unknown rig verb '" + verb + "' (reset, estop or recover)");
  refuse_db_option(args, "rig " + verb);
  const Options opt(Args(args.begin() + 2, args.end()), {"daemon", "token"}, {});
  const auto a = post_to_daemon(daemon_address(opt), "/api/rigs/" + url_segment(name) + "/" + verb, "");
  // done: latched and seen by the rig (or reset); pending: taken, not yet confirmed; refusals exit 2 above.
  std::cout << verb << " " << (a.value("result", "") == "done" ? "done" : "sent") << ": rig '" << a.value("rig", name) << "' is " << a.value("state", "")
            << " (" << a.value("reason", "") << ")\n";
  return 0;
}

}  // namespace hystlab::cli
