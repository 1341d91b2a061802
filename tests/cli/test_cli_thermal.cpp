// Issue 42: `hystlab eval` with temperature as an input, run as a user runs it: tables identified
// at several temperatures (by `hystlab identify` on the simplified model at each), joined at
// evaluation; the simplified model at another temperature; the refusals, each naming its option.
#include <doctest/doctest.h>

#include <sstream>
#include <string>
#include <vector>

#include "cli_workdir.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/thermal_table.hpp"

using namespace hystlab::models;
using hystlab::test::check_error;
using hystlab::test::slurp;
using hystlab::test::Workdir;

using hystlab::test::csv_column;

TEST_CASE("cli: eval at a temperature: tables identified at three joined, the simplified model moved, refusals named") {
  Workdir w;
  std::vector<EverettTable> tables;
  for (int T : {22, 26, 30}) {
    SmaParameters p = table1_parameters();
    p.T = T;
    w.write("p" + std::to_string(T) + ".json", params_to_json(p, "test").dump());
    const std::string t = "t" + std::to_string(T) + ".json";
    REQUIRE(w.run("identify --model simplified --params p" + std::to_string(T) + ".json --range 0,4 --subdivisions 12 -o " + t).code == 0);
    tables.push_back(table_from_json(slurp(w / t)).table);
  }
  const ThermalTable tt = make_thermal_table({22, 26, 30}, tables);
  // A path with reversals, and a temperature rising along it.
  std::ostringstream x, xt;
  x.precision(17);
  xt.precision(17);
  x << "displacement_mm\n";
  xt << "displacement_mm,temperature_C\n";
  std::vector<double> path, temp;
  double at = 0;
  for (double target : {4.0, 1.0, 3.5, 0.5, 3.0})
    for (int k = 1; k <= 50; ++k) path.push_back(at + (target - at) * k / 50), at = k == 50 ? target : at;
  for (std::size_t k = 0; k < path.size(); ++k) {
    temp.push_back(22 + 8.0 * static_cast<double>(k) / static_cast<double>(path.size()));
    x << path[k] << "\n";
    xt << path[k] << "," << temp[k] << "\n";
  }
  w.write("X.csv", x.str());
  w.write("XT.csv", xt.str());

  const auto at27 = w.run("eval --table t22.json,t26.json,t30.json --identified-at 22,26,30 --temperature 27 --input X.csv");
  CAPTURE(at27.err);
  REQUIRE(at27.code == 0);
  ThermalPreisachModel lib(tt, 27);
  const std::vector<double> f27 = csv_column(at27.out, 1);
  REQUIRE(f27.size() == path.size());
  for (std::size_t k = 0; k < path.size(); ++k) CHECK(f27[k] == lib.step(path[k]));  // exact: shortest round-trip formatting

  const auto ramp = w.run("eval --table t22.json,t26.json,t30.json --identified-at 22,26,30 --input XT.csv");
  REQUIRE(ramp.code == 0);
  CHECK(ramp.out.rfind("displacement_mm,temperature_C,force_N\n", 0) == 0);
  ThermalPreisachModel ramped(tt, temp[0]);
  const std::vector<double> fr = csv_column(ramp.out, 2);
  REQUIRE(fr.size() == path.size());
  for (std::size_t k = 0; k < path.size(); ++k) {
    ramped.set_temperature(temp[k]);
    CHECK(fr[k] == ramped.step(path[k]));
  }

  const auto sma = w.run("eval --model simplified --temperature 27 --input X.csv");
  REQUIRE(sma.code == 0);
  SmaParameters p27 = table1_parameters();
  p27.T = 27;
  SimplifiedSmaModel truth(p27);
  const std::vector<double> fs = csv_column(sma.out, 1);
  for (std::size_t k = 0; k < path.size(); ++k) CHECK(fs[k] == truth.step(path[k]));

  check_error(w.run("eval --table t22.json,t26.json --identified-at 22,26 --temperature 31 --input X.csv"),
              "--temperature: temperature 31 °C is outside the identified 22..26 °C (--clamp clamps and counts)");
  check_error(w.run("eval --table t22.json,t26.json --identified-at 26,22 --temperature 24 --input X.csv"),
              "--table/--identified-at: thermal table: the temperatures must increase: 22 °C follows 26 °C");
  check_error(w.run("eval --table t22.json --identified-at 22,26 --temperature 24 --input X.csv"), "--identified-at: 2 temperatures for 1 tables in --table");
  check_error(w.run("eval --table t22.json,t26.json --identified-at 22,26 --input X.csv"),
              "tables at several temperatures need --temperature T or a temperature_C column in X.csv");
  check_error(w.run("eval --table t22.json --temperature 22 --input X.csv"), "--temperature: a table is identified at one temperature");
  check_error(w.run("eval --model simplified --temperature 45 --input X.csv"),
              "--temperature 45: the simplified model with these parameters holds from Af0 = 21.5 °C to 40.9 °C (parameters: ");
  // Without --identified-at: each table's own temperature (identify wrote the parameters' T), in any order.
  const auto own = w.run("eval --table t30.json,t22.json,t26.json --temperature 27 --input X.csv");
  REQUIRE(own.code == 0);
  CHECK(own.out == at27.out);
  CHECK(nlohmann::json::parse(slurp(w / "t26.json"))["provenance"]["temperature_C"] == 26);
  w.write("t_anon.json", [&] {
    auto j = nlohmann::json::parse(slurp(w / "t26.json"));
    j["provenance"].erase("temperature_C");
    return j.dump();
  }());
  w.write("t_warm.json", [&] {
    auto j = nlohmann::json::parse(slurp(w / "t26.json"));
    j["provenance"]["temperature_C"] = "warm";
    return j.dump();
  }());
  check_error(w.run("eval --table t22.json,t_warm.json --input XT.csv"), "'provenance.temperature_C' must be a number");
  check_error(w.run("eval --table t22.json,t_anon.json --input XT.csv"),
              "t_anon.json: the table does not say the temperature it was identified at (provenance.temperature_C): give --identified-at");
  check_error(w.run("eval --table t22.json,t26.json --identified-at 22,26 --model simplified --input XT.csv"), "without --model or --params");
  check_error(w.run("eval --table t22.json,t26.json --identified-at 22,26 --temperature 24 --input XT.csv"), "has a temperature_C column too");
  w.write("XT3.csv", "displacement_mm,temperature_C\n0,22\n1,warm\n");
  check_error(w.run("eval --table t22.json,t26.json --identified-at 22,26 --input XT3.csv"), "XT3.csv: line 3, column 'temperature_C': 'warm' is not a number");
  REQUIRE(w.run("identify --model simplified --params p26.json --range 0,4 --subdivisions 8 -o t26_8.json").code == 0);
  check_error(w.run("eval --table t22.json,t26_8.json --identified-at 22,26 --temperature 24 --input X.csv"),
              "the table at 26 °C is not on the nodes of the table at 22 °C");
  w.write("XT2.csv", "displacement_mm,temperature_C\n0,22\n1,40\n");
  check_error(w.run("eval --table t22.json,t26.json --identified-at 22,26 --input XT2.csv"),
              "XT2.csv: line 3: temperature 40 °C is outside the identified 22..26 °C");
  const auto clamped = w.run("eval --table t22.json,t26.json --identified-at 22,26 --input XT2.csv --clamp");
  CHECK(clamped.code == 0);
  CHECK(clamped.err.find("1 temperature(s) outside 22..26 °C were clamped") != std::string::npos);
  CHECK(csv_column(clamped.out, 1) == std::vector<double>{22, 26});  // the temperature used, clamped
}
