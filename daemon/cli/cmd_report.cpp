// hystlab report CAMPAIGN -o report.html|report.pdf: the campaign's report, a self-contained
// document rendered by the running hystlabd from the stored data (GET /api/campaigns/ID/report.html);
// a .pdf is printed from it by Debian's Chromium, headless.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "daemon_client.hpp"

namespace hystlab::cli {
namespace {
const char* kReportHelp = R"(usage: hystlab report CAMPAIGN [-o report.html | -o report.pdf] [--daemon URL] [--token T]

The campaign's report, as a lab files it: the rig, its envelope and the plan; the data quality of
every run; for a FOT campaign the loop with the identified table over it, the Everett table as a
heatmap, every table's score on the held-out validation run with the recommended one, the training
curve and the figures of every closed cycle; for a sine campaign the transmissibility and phase per
amplitude and direction with the prediction, the resonances and the jumps; and the record of its
states. One HTML file with its figures inside (vector graphics), rendered by the running hystlabd
from the stored data. -o NAME.pdf prints it to PDF with Chromium ($CHROMIUM, default
/usr/bin/chromium). Default: hystlab-campaign-ID-report.html.
)";

// Chromium, headless, prints the HTML file to PDF; its own output is kept out of the way.
void print_pdf(const std::string& html, const std::string& pdf) {
  const char* env = std::getenv("CHROMIUM");
  const std::string chromium = env && *env ? env : "/usr/bin/chromium";
  if (!std::filesystem::exists(chromium))
    throw CliError("-o " + pdf + ": a PDF is printed by Chromium, and there is none at " + chromium + " (apt install chromium, or set $CHROMIUM)");
  const std::string out = "--print-to-pdf=" + pdf, url = "file://" + std::filesystem::absolute(html).string();
  const pid_t pid = fork();
  if (pid == 0) {
    if (const int null = open("/dev/null", O_WRONLY); null >= 0) dup2(null, 1), dup2(null, 2);
    execl(chromium.c_str(), chromium.c_str(), "--headless", "--no-sandbox", "--disable-gpu", "--no-pdf-header-footer", out.c_str(), url.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  int st = 0;
  if (pid < 0 || waitpid(pid, &st, 0) < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0 || !std::filesystem::exists(pdf))
    throw CliError("-o " + pdf + ": Chromium did not print the report (" + chromium + ")");
}
}  // namespace

int run_report(const Args& args) {
  if (print_help_if_asked(args, kReportHelp) || args.empty()) {
    if (args.empty()) std::cout << kReportHelp;
    return args.empty() ? 2 : 0;
  }
  const std::string id = args[0];
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) throw CliError("CAMPAIGN: '" + id + "' is not a campaign number");
  refuse_db_option(args, "report");
  const Options opt(Args(args.begin() + 1, args.end()), {"daemon", "token", "output"}, {});
  const std::string out = opt.has("output") ? opt.get("output") : "hystlab-campaign-" + id + "-report.html";
  const bool pdf = out.size() > 4 && out.compare(out.size() - 4, 4, ".pdf") == 0;
  const std::string html = get_from_daemon(daemon_address(opt), "/api/campaigns/" + id + "/report.html");
  const std::string html_path = pdf ? out.substr(0, out.size() - 4) + ".html" : out;
  {
    std::ofstream f(html_path, std::ios::binary);
    if (!(f << html)) throw CliError("-o " + html_path + ": cannot write it");
  }
  if (pdf) print_pdf(html_path, out);
  std::cout << "wrote " << out << (pdf ? " (and " + html_path + ")" : "") << "\n";
  return 0;
}

}  // namespace hystlab::cli
