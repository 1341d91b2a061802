// The hystlab CLI as a user runs it: the real binary, real files, exit codes and messages.
#include <doctest/doctest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <chrono>
#include <functional>
#include <string>
#include <thread>

#include "../support/daemon_process.hpp"
#include "cli_workdir.hpp"
#include "hystlab/db/store.hpp"

#include "../support/build_paths.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/loop_figures.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/table_score.hpp"

namespace fs = std::filesystem;
using namespace hystlab::models;
using hystlab::test::check_error;
using hystlab::test::Result;
using hystlab::test::slurp;
using hystlab::test::Workdir;

namespace {

std::string series_csv(const std::vector<double>& x, const std::vector<double>& f) {
  std::ostringstream s;
  s.precision(17);
  s << "time_s,displacement_mm,force_N\n";
  for (std::size_t k = 0; k < x.size(); ++k) s << static_cast<double>(k) * 0.01 << "," << x[k] << "," << f[k] << "\n";
  return s.str();
}

std::vector<double> column(const std::string& csv, int col) { return hystlab::test::csv_column(csv, col); }

const std::vector<double> kPath = ramp_through({0.0, 3.5, 1.0, 3.0, 1.5, 4.0, 0.0}, 0.01);

}  // namespace

TEST_CASE("cli: --help on every verb") {
  Workdir w;
  for (const char* verb : {"eval", "identify", "fit", "design", "calibrate", "invert", "check", "compare", "loops", "demo"}) {
    CAPTURE(verb);
    const Result r = w.run(std::string(verb) + " --help");
    CHECK(r.code == 0);
    CHECK(r.out.find(std::string("usage: hystlab ") + verb) != std::string::npos);
  }
  const Result top = w.run("--help");
  CHECK(top.code == 0);
  CHECK(top.out.find("calibrate") != std::string::npos);
}

TEST_CASE("cli: identify (virtual) then eval reproduces the library to the last digit") {
  Workdir w;
  REQUIRE(w.run("identify --model simplified --range 0,4 --subdivisions 12 -o T.json").code == 0);
  const TableDocument doc = table_from_json(slurp(w / "T.json"));
  CHECK(doc.table.grid().n == 12);
  CHECK(doc.provenance.method == "virtual-fot");
  SimplifiedSmaModel sma(table1_parameters());
  const EverettTable expected = identify_virtual(sma, Grid::make(0, 4, 12));
  for (std::size_t k = 0; k < expected.values().size(); ++k) CHECK(doc.table.values()[k] == expected.values()[k]);

  w.write("X.csv", series_csv(kPath, std::vector<double>(kPath.size(), 0.0)));
  const Result r = w.run("eval --table T.json --input X.csv -o Y.csv");
  REQUIRE(r.code == 0);
  const std::string y = slurp(w / "Y.csv");
  CHECK(y.rfind("displacement_mm,force_N\n", 0) == 0);
  const auto xs = column(y, 0), fs_ = column(y, 1);
  REQUIRE(fs_.size() == kPath.size());
  PreisachModel pm(expected);
  for (std::size_t k = 0; k < kPath.size(); ++k) {
    CHECK(xs[k] == kPath[k]);
    CHECK(fs_[k] == pm.step(kPath[k]));  // exact: shortest round-trip formatting
  }
  const Result m = w.run("eval --model simplified --input X.csv");
  REQUIRE(m.code == 0);
  SimplifiedSmaModel ref(table1_parameters());
  const auto fm = column(m.out, 1);
  REQUIRE(fm.size() == kPath.size());
  for (std::size_t k = 0; k < kPath.size(); ++k) CHECK(fm[k] == ref.step(kPath[k]));
}

TEST_CASE("cli: identify from measured FOT nodes, with drift and violation report") {
  Workdir w;
  SimplifiedSmaModel sma(table1_parameters());
  const auto nodes = run_virtual_fot(sma, Grid::make(0, 4, 6)).nodes;
  std::ostringstream csv;
  csv.precision(17);
  csv << "alpha_mm,beta_mm,force_alpha_N,force_alpha_beta_N\n";
  for (int rep = 0; rep < 2; ++rep)
    for (const FotNode& n : nodes) csv << n.alpha << "," << n.beta << "," << n.force_alpha + rep * 0.1 << "," << n.force_alpha_beta << "\n";
  w.write("nodes.csv", csv.str());
  const Result r = w.run("identify --fot nodes.csv -o T.json");
  REQUIRE(r.code == 0);
  CHECK(r.out.find("identified n = 6") != std::string::npos);
  CHECK(r.out.find("drift: max spread of f_alpha 0.1") != std::string::npos);
  CHECK(r.out.find("warning: cell") != std::string::npos);  // the SMA table is not monotone near the diagonal
  const TableDocument doc = table_from_json(slurp(w / "T.json"));
  CHECK(doc.table.node_value(6, 0) == doctest::Approx(nodes[20].everett() + 0.05));
}

TEST_CASE("cli: fit, calibrate, invert, check and compare on generated data") {
  Workdir w;
  SimplifiedSmaModel sma(table1_parameters());
  std::vector<double> f(kPath.size());
  sma.evaluate(kPath, f);
  w.write("X.csv", series_csv(kPath, f));

  // auto: both priors, each scored on held-out blocks; the SMA specimen needs negative masses.
  const Result fit = w.run("fit --data X.csv --subdivisions 10 -o F.json");
  REQUIRE(fit.code == 0);
  CAPTURE(fit.out);
  CHECK(fit.out.find("(4-fold cross-validation)") != std::string::npos);
  CHECK(fit.out.find("prior signed: signed: held-out RMS") != std::string::npos);
  const TableDocument fitted = table_from_json(slurp(w / "F.json"));
  CHECK(fitted.provenance.method == "lsq");
  CHECK(fitted.provenance.extra.at("prior") == "signed");
  CHECK(fitted.provenance.extra.at("candidates").size() == 2);
  CHECK(fitted.provenance.extra.at("heldout_rms_N").get<double>() < fitted.provenance.extra.at("candidates").at(1).at("heldout_rms_N").get<double>());
  bool negative = false;
  for (const CellWeight& c : cell_weights(fitted.table)) negative = negative || c.weight < 0.0;
  CHECK(negative);
  const Result mono = w.run("fit --data X.csv --subdivisions 10 --prior monotone --folds 3 -o M.json");
  REQUIRE(mono.code == 0);
  CHECK(mono.out.find("(3-fold cross-validation)") != std::string::npos);
  for (const CellWeight& c : cell_weights(table_from_json(slurp(w / "M.json")).table)) CHECK(c.weight >= -1e-9);
  check_error(w.run("fit --data X.csv --subdivisions 10 --prior positive -o F.json"), "signed, monotone or auto");
  check_error(w.run("fit --data X.csv --subdivisions 201 -o F.json"), "subdivisions");

  const auto loop = ramp_through({0.0, 4.0, 0.0}, 0.005);
  std::vector<double> lf(loop.size());
  sma.reset();
  sma.evaluate(loop, lf);
  w.write("loop.csv", series_csv(loop, lf));
  const Result cal = w.run("calibrate --data loop.csv --temperature 25 --clausius 5.7 -o P.json");
  REQUIRE(cal.code == 0);
  const SmaParameters p = params_from_json(slurp(w / "P.json"));
  CHECK(p.KA == doctest::Approx(40.0).epsilon(1e-3));
  CHECK(p.Af0 == doctest::Approx(21.5).epsilon(1e-3));

  REQUIRE(w.run("identify --model simplified --range 0,4 --subdivisions 24 -o T.json").code == 0);
  w.write("F.csv", "force_N\n20\n60\n100\n40\n25\n");
  const Result inv = w.run("invert --table T.json --input F.csv");
  REQUIRE(inv.code == 0);
  const auto reached = column(inv.out, 1);
  const std::vector<double> wanted{20, 60, 100, 40, 25};
  for (std::size_t k = 0; k < wanted.size(); ++k) CHECK(reached[k] == doctest::Approx(wanted[k]).epsilon(1e-6));

  const Result chk = w.run("check --data X.csv");
  REQUIRE(chk.code == 0);
  CHECK(chk.out.find("wiping-out: ") != std::string::npos);
  CHECK(chk.out.find("congruency: ") != std::string::npos);

  const Result cmp = w.run("compare --table T.json --data X.csv");
  REQUIRE(cmp.code == 0);
  CHECK(cmp.out.find("ascending") != std::string::npos);
  CHECK(cmp.out.find("descending") != std::string::npos);
  CHECK(cmp.out.find("loop energy: reference") != std::string::npos);
}

TEST_CASE("cli: loops prints every closed cycle's figures, as the library computes them") {
  Workdir w;
  SimplifiedSmaModel sma(table1_parameters());
  const auto x = ramp_through({0.0, 4.0, 0.0, 4.0, 2.0, 3.5, 0.0}, 0.005);
  std::vector<double> f(x.size());
  sma.evaluate(x, f);
  w.write("X.csv", series_csv(x, f));
  const Result text = w.run("loops --data X.csv --plateaus 1,3");
  REQUIRE(text.code == 0);
  CAPTURE(text.out);
  CHECK(text.out.find("3 closed cycle(s)") != std::string::npos);
  CHECK(text.out.find("plateau at 1 mm: loading 40 N") != std::string::npos);
  CHECK(text.out.find("Ms (1.012 mm, 40.47 N)") != std::string::npos);
  const Result js = w.run("loops --data X.csv --json --plateaus 3");
  REQUIRE(js.code == 0);
  const auto j = nlohmann::json::parse(js.out);
  LoopOptions o;
  o.plateau_at_mm = {3.0};
  // The CSV holds 17 digits: the same numbers as the library's on the same record.
  const auto lib = find_loops(x, f, o);
  REQUIRE(j.size() == lib.size());
  for (std::size_t k = 0; k < lib.size(); ++k) {
    CAPTURE(k);
    CHECK(j[k].at("energy_Nmm").get<double>() == lib[k].energy_Nmm);
    CHECK(j[k].at("damping_ratio").get<double>() == lib[k].damping_ratio);
    CHECK(j[k].at("plateaus").at(0).at("unloading_N").get<double>() == lib[k].plateaus.at(0).unloading_N);
  }
  CHECK(j[1].at("min_mm").get<double>() == doctest::Approx(2.0));  // the inner loop closes before its host
  CHECK(j[2].at("energy_Nmm").get<double>() == doctest::Approx(j[0].at("energy_Nmm").get<double>()).epsilon(1e-6));
  w.write("bad.csv", "displacement_mm,force_N\n0,0\n1,nan\n");
  check_error(w.run("loops --data bad.csv"), "bad.csv: line 3");
  check_error(w.run("loops --data X.csv --plateaus 1,x"), "option --plateaus: 'x' is not a number");
}

TEST_CASE("cli: demo writes the report, plots and tables") {
  Workdir w;
  const Result r = w.run("demo --out d");
  REQUIRE(r.code == 0);
  for (const char* f : {"report.md", "major_loop.svg", "minor_loops.svg", "random_input.svg", "table_n4.json", "table_n48.json"})
    CHECK(fs::exists(w / "d" / f));
  const std::string report = slurp(w / "d" / "report.md");
  for (const char* n : {"|   4 |", "|   8 |", "|  12 |", "|  24 |", "|  48 |"}) CHECK(report.find(n) != std::string::npos);
  CHECK(slurp(w / "d" / "major_loop.svg").find("<polyline") != std::string::npos);
  // The refined grid's rows: at each n, its error on loops about the preload below the uniform grid's.
  const auto at = report.find("## A grid refined where the part works");
  REQUIRE(at != std::string::npos);
  std::istringstream rows(report.substr(at));
  int compared = 0;
  for (std::string line; std::getline(rows, line);) {
    int n = 0;
    double uniform = 0, refined = 0;
    if (std::sscanf(line.c_str(), "| %d | %lf | %lf |", &n, &uniform, &refined) != 3) continue;
    CAPTURE(line);
    CHECK(refined < 0.75 * uniform);
    ++compared;
  }
  CHECK(compared == 3);
}

TEST_CASE("cli: every error is one line naming the problem, exit code 2") {
  Workdir w;
  REQUIRE(w.run("identify --model simplified --range 0,4 --subdivisions 4 -o T.json").code == 0);
  w.write("X.csv", "displacement_mm,force_N\n0,0\n1,2\n");
  check_error(w.run("eval --table missing.json --input X.csv"), "cannot open 'missing.json'");
  check_error(w.run("eval --table T.json --input nope.csv"), "cannot open 'nope.csv'");
  w.write("nocol.csv", "disp,force_N\n0,0\n");
  check_error(w.run("eval --table T.json --input nocol.csv"), "no column 'displacement_mm'");
  w.write("nan.csv", "displacement_mm\n0\nnan\n");
  check_error(w.run("eval --table T.json --input nan.csv"), "line 3, column 'displacement_mm': 'nan' is not a finite number");
  w.write("text.csv", "displacement_mm\n0\n1.2.3\n");
  check_error(w.run("eval --table T.json --input text.csv"), "'1.2.3' is not a number");
  w.write("empty.csv", "");
  check_error(w.run("eval --table T.json --input empty.csv"), "empty file");
  w.write("header.csv", "displacement_mm\n");
  check_error(w.run("eval --table T.json --input header.csv"), "no data rows");
  w.write("ragged.csv", "displacement_mm,force_N\n0,0\n1\n");
  check_error(w.run("eval --table T.json --input ragged.csv"), "line 3: has 1 fields");
  w.write("far.csv", "displacement_mm\n0\n4.5\n");
  check_error(w.run("eval --table T.json --input far.csv"), "outside the table's range");
  CHECK(w.run("eval --table T.json --input far.csv --clamp").code == 0);

  auto doc = nlohmann::json::parse(slurp(w / "T.json"));
  auto bad = doc;
  bad["version"] = 7;
  w.write("v7.json", bad.dump());
  check_error(w.run("eval --table v7.json --input X.csv"), "unknown format version 7");
  bad = doc;
  bad["nodes_mm"][3] = 0.1;
  w.write("nonmono.json", bad.dump());
  check_error(w.run("eval --table nonmono.json --input X.csv"), "non-monotone grid");
  w.write("broken.json", "{\"format\": ");
  check_error(w.run("eval --table broken.json --input X.csv"), "table file 'broken.json' is not JSON: line 1, column 12");

  check_error(w.run("identify --model simplified --range 0,4 --subdivisions 0 -o U.json"), "--subdivisions");
  check_error(w.run("identify --model simplified --range 4,0 --subdivisions 4 -o U.json"), "greater than the start");
  check_error(w.run("identify --model simplified --range 0,4 -o U.json"), "missing required option --subdivisions");
  check_error(w.run("identify --model magic --range 0,4 --subdivisions 4 -o U.json"), "unknown model 'magic'");
  CHECK_FALSE(fs::exists(w / "U.json"));
  check_error(w.run("eval --table T.json --input X.csv --frobnicate 3"), "unknown option --frobnicate");
  check_error(w.run("transmogrify"), "unknown verb 'transmogrify'");
  w.write("badp.json", R"({"KA_N_per_mm": 40, "KM_N_per_mm": 150, "dtr_max_mm": 2.95, "C_N_per_degC": 5.7,
    "Mf0_degC": 12.7, "Ms0_degC": 17.9, "As0_degC": 17.9, "Af0_degC": 21.5, "T_degC": 15})");
  check_error(w.run("eval --model simplified --params badp.json --input X.csv"), "T_degC");
  check_error(w.run("calibrate --data X.csv -o P.json"), "--temperature");
  w.write("Fbig.csv", "force_N\n1e6\n");
  check_error(w.run("invert --table T.json --input Fbig.csv"), "line 2: force 1e+06 N cannot be reached");
  w.write("few.csv", "displacement_mm,force_N\n0,0\n1,1\n");
  check_error(w.run("fit --data few.csv --subdivisions 8 -o F.json"), "too few");
  w.write("fot.csv", "alpha_mm,beta_mm,force_alpha_N,force_alpha_beta_N\n1,0,10,0\n2,0,20,0\n2,1,20,15\n3,0,30,0\n");
  check_error(w.run("identify --fot fot.csv -o F.json"), "missing node (alpha 3 mm, beta 1 mm)");
}

TEST_CASE("cli: the daemon's records, read from its file with no daemon running") {
  Workdir w;
  // Never a database by accident: --db must name hystlabd's file.
  check_error(w.run("campaign list --db d.db"), "no database at 'd.db'");
  CHECK_FALSE(std::filesystem::exists(w / "d.db"));
  {
    hystlab::db::Store daemons((w / "d.db").string());
    const auto rig = daemons.upsert_rig("sim frame", "{}", "2026-01-01T00:00:00Z");
    (void)daemons.create_campaign(rig, hystlab::domain::CampaignKind::waveform, R"({"kind": "waveform", "points_mm": [0, 2.5, 1, 3, 0]})",
                                  "2026-01-01T00:00:01Z");
  }
  const Result list = w.run("campaign list --db d.db");
  CHECK(list.out.find("queued") != std::string::npos);
  const Result show = w.run("campaign show 1 --db d.db");
  CHECK(show.out.find("campaign 1: waveform on sim frame, queued") != std::string::npos);  // readable lines
  const Result shown = w.run("campaign show 1 --json --db d.db");
  const auto j = nlohmann::json::parse(shown.out);
  CHECK(j["plan"]["points_mm"] == nlohmann::json::parse("[0,2.5,1,3,0]"));
  CHECK(w.run("tables list --db d.db").out.find("held-out RMS (N)") != std::string::npos);
  check_error(w.run("tables export 1 --format xls --db d.db"), "--format: 'xls'");
  CHECK(w.run("--version").out.rfind("hystlab ", 0) == 0);
  check_error(w.run("campaign show 99 --db d.db"), "no campaign 99");
  check_error(w.run("campaign show x --db d.db"), "campaign ID must be a positive whole number");
  check_error(w.run("campaign frobnicate 1"), "unknown campaign verb 'frobnicate'");
  check_error(w.run("tables export 5 --db d.db"), "no table 5");
  check_error(w.run("runs export 3 --db d.db"), "no samples for run 3");
}

TEST_CASE("cli: a validation run re-scored against a stored table, as the campaign scored it; held-out figures listed") {
  Workdir w;
  SimplifiedSmaModel sma(table1_parameters());
  const EverettTable table = identify_virtual(sma, Grid::make(0, 4, 8));
  const auto vx = ramp_through({0.0, 3.1, 0.7, 2.6, 1.2, 3.9, 0.0}, 0.01);
  std::vector<double> vf(vx.size());
  sma.reset();
  sma.evaluate(vx, vf);
  nlohmann::json acc = accuracy_json(score_table(table, vx, vf));  // what the campaign stores beside it
  acc = {{"overall", acc["overall"]}, {"held_out", acc}, {"recommended", true}};
  {
    hystlab::db::Store s((w / "d.db").string());
    const auto rig = s.upsert_rig("sim frame", "{}", "t");
    const auto c = s.create_campaign(rig, hystlab::domain::CampaignKind::fot, R"({"kind": "fot"})", "t");
    const auto [run, vrun] = s.add_runs(c, "t", 0, 0, true);
    std::vector<hystlab::db::SampleRow> rows;
    for (std::size_t k = 0; k < vx.size(); ++k) rows.push_back({vrun, static_cast<std::int64_t>(k), 0.01 * static_cast<double>(k), vx[k], vx[k], vf[k], 0});
    hystlab::db::Transaction tx(s.database());
    s.insert_samples(rows);
    (void)s.add_table(c, run, "fot", 8, 0, 4, "t", acc.dump(), table_to_json(table, {"test", "fot", "t", "", {}}).dump());
    tx.commit();
  }
  const Result list = w.run("tables list --db d.db");
  CAPTURE(list.out);
  char rms[32];
  std::snprintf(rms, sizeof rms, "%.4g", acc["held_out"]["overall"]["rms_N"].get<double>());
  CHECK(list.out.find(std::string(" ") + rms + "  ") != std::string::npos);
  CHECK(list.out.find("  *  ") != std::string::npos);  // recommended, and said so below the table
  CHECK(list.out.find("*: the table its campaign recommends") != std::string::npos);
  const Result cmp = w.run("compare --table-id 1 --run 2 --db d.db");
  REQUIRE(cmp.code == 0);
  CAPTURE(cmp.out);
  CHECK(cmp.out.find("data: run 2 (validation)") != std::string::npos);
  char line[64];
  std::snprintf(line, sizeof line, "%12.6g", acc["held_out"]["overall"]["rms_N"].get<double>());
  CHECK(cmp.out.find(std::string("overall")) != std::string::npos);
  CHECK(cmp.out.find(line) != std::string::npos);  // the same figure as stored, to its printed digits
  check_error(w.run("compare --table-id 1 --run 9 --db d.db"), "--run: no run 9");
  check_error(w.run("compare --table-id 7 --run 2 --db d.db"), "--table-id: no table 7");
  check_error(w.run("compare --table-id 1 --db d.db"), "give one of --data X.csv or --run RUN");
}

// A loopback port nothing listens on: bound to learn a free one, then closed.
int closed_port() {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  REQUIRE(s >= 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  REQUIRE(bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  REQUIRE(getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) == 0);
  close(s);
  return ntohs(a.sin_port);
}

// Until pred() holds for the CLI's answer to args, at most `seconds`; returns the last answer.
Result run_until(const Workdir& w, const std::string& args, const std::function<bool(const Result&)>& pred, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  Result r = w.run(args);
  while (!pred(r) && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    r = w.run(args);
  }
  return r;
}

TEST_CASE("cli: submit, preview and the commands go to the running hystlabd over HTTP, with its checks and its token") {
  Workdir w;
  w.write("plan.json", R"({"kind": "waveform", "points_csv": "path.csv", "ramp_rate_mm_s": 0.05})");
  w.write("path.csv", "displacement_mm\n0\n2.5\n1\n3\n0\n");
  w.write("bad.json", R"({"kind": "fot", "range_mm": [0, 4], "subdivisions": 0})");
  w.write("climb.json", R"({"kind": "waveform", "points_csv": "../path.csv", "ramp_rate_mm_s": 0.5})");
  // Refused before any connection: a file the plan may not reach, an address that is not one, --db.
  check_error(w.run("campaign submit --plan climb.json"), "must be a file beside the plan");
  check_error(w.run("campaign submit --plan plan.json --daemon localhost:8080"), "--daemon: 'localhost:8080' is not the daemon's address");
  check_error(w.run("campaign pause 1 --db d.db"), "--db: 'campaign pause' is sent to the running hystlabd");
  check_error(w.run("rig estop 'sim frame' --db d.db"), "--db: 'rig estop' is sent to the running hystlabd");
  // No daemon at the address: a port the kernel just gave out and took back.
  const std::string closed = "http://127.0.0.1:" + std::to_string(closed_port());
  check_error(w.run("campaign pause 1 --daemon " + closed), "no hystlabd answers at " + closed + " (nothing accepts a connection there)");

  const std::string token = "cli-test-token-0123456789";
  hystlab::test_support::DaemonProcess d(R"({"rigs": [{"name": "sim frame", "simulate": {"time_scale": 10}}], "http": {"token": ")" + token + R"("}})");
  const std::string at = " --daemon http://127.0.0.1:" + std::to_string(d.port());
  const std::string auth = at + " --token " + token;
  CAPTURE(d.log());
  check_error(w.run("campaign submit --plan plan.json" + at), "needs its token");
  // The daemon's own checks, in its words: the plan's field, the rig's name.
  check_error(w.run("campaign submit --plan bad.json" + auth), "plan: subdivisions must be an integer");
  check_error(w.run("campaign submit --plan plan.json --rig 'frame B'" + auth), "no rig named 'frame B'");
  const Result preview = w.run("campaign preview --plan plan.json" + auth);
  CAPTURE(preview.err);
  REQUIRE(preview.code == 0);
  CHECK(preview.out.find("waveform on 'sim frame'") != std::string::npos);
  CHECK(preview.out.find("peak speed 0.05 mm/s") != std::string::npos);
  const Result none = run_until(
      w, "campaign list --db " + d.db_path(), [](const Result& r) { return r.code == 0; }, 10);
  CHECK(none.code == 0);
  CHECK(none.out.find("waveform") == std::string::npos);  // a preview queues nothing

  // $HYSTLAB_DAEMON and $HYSTLAB_TOKEN stand for the options.
  const std::string env = "env HYSTLAB_DAEMON=http://127.0.0.1:" + std::to_string(d.port()) + " HYSTLAB_TOKEN=" + token + " '" + HYSTLAB_CLI + "' ";
  const Result queued = w.run_raw(env + "campaign submit --plan plan.json");
  CAPTURE(queued.err);
  REQUIRE(queued.code == 0);
  CHECK(queued.out.find("campaign 1 queued (waveform on 'sim frame'") != std::string::npos);
  const Result shown = w.run("campaign show 1 --json --db " + d.db_path());
  CHECK(nlohmann::json::parse(shown.out)["plan"]["points_mm"] == nlohmann::json::parse("[0.0,2.5,1.0,3.0,0.0]"));  // the CSV, inlined

  // Commands: abort ends it (the daemon drives the rig to its safe position); a second abort no
  // longer applies, in the API's words.
  const Result running = run_until(
      w, "campaign show 1 --db " + d.db_path(), [](const Result& r) { return r.out.find(", running") != std::string::npos; }, 60);
  CAPTURE(running.out);
  REQUIRE(running.out.find(", running") != std::string::npos);
  CHECK(w.run("campaign pause 1" + auth).out.find("pause sent: campaign 1 (running: taken by the running campaign)") != std::string::npos);
  CHECK(w.run("campaign abort 1" + auth).out.find("abort sent: campaign 1") != std::string::npos);
  const Result aborted = run_until(
      w, "campaign show 1 --db " + d.db_path(), [](const Result& r) { return r.out.find(", aborted") != std::string::npos; }, 60);
  CAPTURE(aborted.out);
  REQUIRE(aborted.out.find(", aborted") != std::string::npos);
  check_error(w.run("campaign abort 1" + auth), "campaign 1 is aborted: 'abort' does not apply");
  check_error(w.run("campaign pause 7" + auth), "campaign 7");

  // The rig's e-stop latches in the daemon: a submission is refused until the operator's reset.
  const Result estop = w.run("rig estop 'sim frame'" + auth);
  CAPTURE(estop.err);
  CHECK(estop.out.find("estop done: rig 'sim frame' is estopped (latched: the rig reports its e-stop)") != std::string::npos);  // confirmed before the answer
  check_error(w.run("campaign submit --plan plan.json" + auth), "reset it first");                                              // at once, never a moment later
  CHECK(w.run("rig reset 'sim frame'" + auth).code == 0);
  const Result again = run_until(
      w, "campaign submit --plan plan.json" + auth, [](const Result& r) { return r.code == 0; }, 30);
  CAPTURE(again.err);
  CHECK(again.out.find("campaign 2 queued") != std::string::npos);
  check_error(w.run("rig estop 'frame B'" + auth), "frame B");
}

TEST_CASE("cli: simulate sdof: time history, sweep up and down with the linear comparison, and its refusals") {
  Workdir w;
  const Result h = w.run(
      "simulate sdof --mass 1 --springs 2 --linear 5 --damping 0.02 --preload-mm 2 --amplitude-mm 0.05 "
      "--frequency-hz 10 --duration-s 0.5 --every 10 -o H.csv");
  REQUIRE(h.code == 0);
  const std::string hist = slurp(w / "H.csv");
  CHECK(hist.rfind("t_s,base_mm,mass_mm,compression_mm,force_N,input_work_Nmm", 0) == 0);
  CHECK(column(hist, 0).size() == 501);
  const Result s = w.run(
      "simulate sdof --mass 1 --springs 2 --linear 5 --preload-mm 2 --amplitude-mm 0.05 --sweep "
      "--frequencies 8,16,30 --settle-cycles 30 --zetas 0.1 -o S.csv --svg S.svg");
  REQUIRE(s.code == 0);
  const std::string sweep = slurp(w / "S.csv");
  CHECK(sweep.rfind("frequency_hz,up,down,up_p2p,down_p2p,linear_zeta_0.1", 0) == 0);
  const auto zeta01 = column(sweep, 5), f = column(sweep, 0);
  REQUIRE(zeta01.size() == 3);
  // The matched linear system is this one with ζ = 0.1: f_n = 100/2π Hz.
  for (std::size_t k = 0; k < 3; ++k) {
    const double r = f[k] / (100.0 / (2 * 3.141592653589793)), a = 0.2 * r;
    CHECK(zeta01[k] == doctest::Approx(std::sqrt((1 + a * a) / ((1 - r * r) * (1 - r * r) + a * a))).epsilon(0.02));
  }
  CHECK(slurp(w / "S.svg").find("<svg") != std::string::npos);
  const Result sma = w.run(
      "simulate sdof --mass 2 --springs 2 --model simplified --preload-mm 3 --amplitude-mm 0.5 --sweep "
      "--from-hz 20 --to-hz 40 --steps 5 --settle-cycles 30 -o M.csv");
  REQUIRE(sma.code == 0);
  CHECK(column(slurp(w / "M.csv"), 1).size() == 5);
  check_error(w.run("simulate sdof --mass 1 --linear 5 --amplitude-mm 0.1 --frequency-hz 5 --duration-s 1 --dt 0.05"), "unstable");
  check_error(w.run("simulate sdof --mass -1 --linear 5 --amplitude-mm 0.1 --frequency-hz 5 --duration-s 1"), "mass_kg");
  check_error(w.run("simulate sdof --mass 1 --linear -5 --amplitude-mm 0.1 --frequency-hz 5 --duration-s 1"), "--linear");
  check_error(w.run("simulate sdof --mass 1 --linear 5 --amplitude-mm 0.1 --sweep --frequencies 5,x"), "'x' is not a number");
  // One calibrated table per spring.
  REQUIRE(w.run("identify --model simplified --range 0,5 --subdivisions 6 -o A.json").code == 0);
  REQUIRE(w.run("identify --model simplified --range 0,5 --subdivisions 10 -o B.json").code == 0);
  const Result two = w.run(
      "simulate sdof --mass 2 --tables A.json,B.json --preload-mm 3 --amplitude-mm 0.3 --frequency-hz 20 "
      "--duration-s 0.2 -o two.csv");
  CAPTURE(two.err);
  REQUIRE(two.code == 0);
  CHECK(column(slurp(w / "two.csv"), 4).front() > 0);  // the two tables carry the weight
  check_error(w.run("simulate sdof --mass 2 --tables A.json,B.json --springs 3 --amplitude-mm 0.3 --frequency-hz 20 --duration-s 0.2"), "--tables");
  check_error(w.run("simulate pendulum --mass 1"), "unknown simulation");
  w.write("bad.json", R"({"format": "hystlab-everett-table", "version": 9})");
  check_error(w.run("simulate sdof --mass 1 --table bad.json --amplitude-mm 0.1 --frequency-hz 5 --duration-s 1"), "version");
}
