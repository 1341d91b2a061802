// The CLI's help and the files it reads (issue 23): `hystlab --help` lists every verb with its
// sub-commands and every export format the code accepts; a JSON file (a table, parameters, a
// plan) that is not JSON, or not the document it should be, is one error naming the file.
#include <doctest/doctest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_workdir.hpp"
#include "hystlab/fmu/element_export.hpp"

using hystlab::test::check_error;
using hystlab::test::Result;
using hystlab::test::Workdir;

namespace {
// The lines of the top-level help that start with "  <what>".
std::vector<std::string> help_lines(const std::string& help, const std::string& what) {
  std::vector<std::string> out;
  std::istringstream in(help);
  for (std::string l; std::getline(in, l);)
    if (l.rfind("  " + what, 0) == 0) out.push_back(l);
  return out;
}

// The words of "a|b|c" that follows `after` in text (up to a blank or ']'): a help's choices.
std::vector<std::string> choices(const std::string& text, const std::string& after) {
  std::vector<std::string> out;
  const auto at = text.find(after);
  if (at == std::string::npos) return out;
  const std::string list = text.substr(at + after.size(), text.find_first_of(" ]\n", at + after.size()) - at - after.size());
  std::istringstream in(list);
  for (std::string w; std::getline(in, w, '|');) out.push_back(w);
  return out;
}

bool has(const std::vector<std::string>& v, const std::string& w) { return std::find(v.begin(), v.end(), w) != v.end(); }
}  // namespace

TEST_CASE("cli: --help lists every verb, each sub-command and every export format the code accepts") {
  Workdir w;
  const Result top = w.run("--help");
  REQUIRE(top.code == 0);
  CAPTURE(top.out);
  // Every export format is one the exports accept, and each help names it where a format is chosen.
  const std::string export_help = w.run("export --help").out, tables_help = w.run("tables --help").out;
  for (const std::string_view f : hystlab::fmu::kExportFormatList) {
    const std::string format(f);
    CAPTURE(format);
    CHECK(hystlab::fmu::is_export_format(f));
    CHECK(has(choices(top.out, "  export --format "), format));
    CHECK(has(choices(top.out, "  tables list|export --format "), format));
    CHECK(has(choices(export_help, "--format "), format));
    CHECK(has(choices(tables_help, "--format "), format));
  }
  CHECK(choices(top.out, "  export --format ").size() == hystlab::fmu::kExportFormatList.size());
  CHECK_FALSE(hystlab::fmu::is_export_format("xlsx"));
  // The runs' formats: the ones `runs export` names when it refuses another.
  const Result runs = w.run("runs export 1 --format h6 --db none.db");
  REQUIRE(runs.err.find("is not csv or h5") != std::string::npos);
  CHECK(choices(top.out, "  runs export --format ") == std::vector<std::string>{"csv", "h5"});
  // Every verb has a line of the top-level help and its own help; each sub-command is named on
  // its verb's line(s) and in the verb's own help.
  const std::pair<const char*, std::vector<const char*>> verbs[] = {{"eval", {}},
                                                                    {"identify", {}},
                                                                    {"fit", {}},
                                                                    {"design", {}},
                                                                    {"calibrate", {}},
                                                                    {"invert", {}},
                                                                    {"check", {}},
                                                                    {"compare", {}},
                                                                    {"loops", {}},
                                                                    {"demo", {}},
                                                                    {"simulate", {"sdof"}},
                                                                    {"export", {}},
                                                                    {"campaign", {"submit", "preview", "pause", "resume", "abort", "estop", "list", "show"}},
                                                                    {"rig", {"estop", "reset", "recover"}},
                                                                    {"tables", {"list", "export"}},
                                                                    {"runs", {"export"}},
                                                                    {"report", {}}};
  for (const auto& [v, subs] : verbs) {
    const std::string verb = v;
    CAPTURE(verb);
    const auto lines = help_lines(top.out, verb + " ");
    CHECK_FALSE(lines.empty());
    const Result own = w.run(verb + " --help");
    CHECK(own.code == 0);
    CHECK(own.out.rfind("usage: hystlab " + verb, 0) == 0);
    CHECK(own.out.find("usage: ", 1) == std::string::npos);  // printed once
    std::vector<std::string> listed;
    for (const std::string& l : lines)
      for (const std::string& sub : choices(l, verb + " ")) listed.push_back(sub);
    std::vector<std::string> usage;  // what the verb's own "usage: hystlab VERB a|b ..." lines name
    std::istringstream own_lines(own.out);
    for (std::string l; std::getline(own_lines, l);)
      for (const std::string& sub : choices(l, "hystlab " + verb + " ")) usage.push_back(sub);
    for (const char* sub : subs) {
      CAPTURE(sub);
      CHECK(has(listed, sub));
      CHECK(has(usage, sub));
    }
  }
}

TEST_CASE("cli: a table, parameter or plan file that is not JSON: one error naming the file, the place and the fault") {
  Workdir w;
  w.write("notjson.txt", "hello\n");
  w.write("X.csv", "displacement_mm,force_N\n0,0\n1,2\n");
  w.write("F.csv", "force_N\n1\n");
  const std::string table = "table file 'notjson.txt' is not JSON: line 1, column 1: unexpected 'h'";
  // Every command that reads a table file.
  check_error(w.run("eval --table notjson.txt --input X.csv"), table);
  check_error(w.run("invert --table notjson.txt --input F.csv"), table);
  check_error(w.run("compare --table notjson.txt --data X.csv"), table);
  check_error(w.run("export --table notjson.txt --format csv"), table);
  check_error(w.run("simulate sdof --mass 1 --tables notjson.txt --amplitude-mm 0.1 --frequency-hz 5 --duration-s 1"), table);
  // Every command that reads a parameter file.
  const std::string params = "parameter file 'notjson.txt' is not JSON: line 1, column 1: unexpected 'h'";
  check_error(w.run("eval --model simplified --params notjson.txt --input X.csv"), params);
  check_error(w.run("export --params notjson.txt --format h"), params);
  check_error(w.run("calibrate --data X.csv --initial notjson.txt -o P.json"), params);
  check_error(w.run("demo --params notjson.txt --out d"), params);
  // A plan, refused before any connection to a daemon: the place in a file of several lines.
  w.write("plan.json", "{\"kind\": \"fot\",\n \"range_mm\": [0, 4],\n \"subdivisions\": 8,,\n}\n");
  check_error(w.run("campaign submit --plan plan.json --daemon http://127.0.0.1:9"), "plan file 'plan.json' is not JSON: line 3, column 20: unexpected ','");
  check_error(w.run("campaign preview --plan plan.json --daemon http://127.0.0.1:9"), "plan file 'plan.json' is not JSON: line 3");
  w.write("cut.json", "{\"format\": ");
  check_error(w.run("eval --table cut.json --input X.csv"), "table file 'cut.json' is not JSON: line 1, column 12: the file ends too early");
  w.write("empty.json", "");
  check_error(w.run("campaign submit --plan empty.json"), "plan file 'empty.json' is not JSON: line 1, column 1: the file is empty");
  // JSON, but not the document asked for: its fault, named by the file.
  w.write("obj.json", "{\"a\": 1}");
  check_error(w.run("eval --table obj.json --input X.csv"), "table file 'obj.json': missing field 'format'");
  check_error(w.run("eval --model simplified --params obj.json --input X.csv"), "parameter file 'obj.json': missing field 'KA_N_per_mm'");
  check_error(w.run("eval --table missing.json --input X.csv"), "cannot open 'missing.json'");
}

TEST_CASE("cli: design suggests a next campaign's rows on an identified table, within its budget, and names a bad option") {
  Workdir w;
  REQUIRE(w.run("identify --model simplified --range 0,4 --subdivisions 12 -o T.json").code == 0);
  const Result r = w.run("design --table T.json --budget-s 120 -o D.json");
  CAPTURE(r.err);
  CAPTURE(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("row 1: up to ") != std::string::npos);
  CHECK(r.out.find("stopped: ") != std::string::npos);
  const auto d = nlohmann::json::parse(hystlab::test::slurp(w / "D.json"));
  REQUIRE(!d["rows"].empty());
  CHECK(d["seconds"].get<double>() <= 120);
  CHECK(d["nodes"].size() == 13 + d["rows"].size());
  double before = d["rms_before_N"];
  for (const auto& row : d["rows"]) {  // each row lowers the estimated error, each inside the range
    CHECK(row["rms_after_N"].get<double>() < before);
    CHECK(row["alpha_mm"].get<double>() > 0);
    CHECK(row["alpha_mm"].get<double>() < 4);
    before = row["rms_after_N"];
  }
  check_error(w.run("design --table T.json --budget-s 1"), "option --budget-s");
  check_error(w.run("design --table T.json"), "--budget-s");
  check_error(w.run("design --table T.json --budget-s 100 --target-rms-n -2"), "option --target-rms-n");
}
