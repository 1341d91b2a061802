// The CLI's exports as the tools that read them do: the C header compiled (its values exactly the
// CSV's) and evaluated through the C API against `hystlab eval` to the last digit, the parameter
// exports, and the refusals.
#include <doctest/doctest.h>

#include <cctype>
#include <cstdlib>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "../support/build_paths.hpp"
#include "cli_workdir.hpp"

using namespace hystlab::test;

namespace {
// The C header's arrays given to the C API (hystlab_model_from_table) in a C program: on a path
// with reversals, the CLI's forces to the last digit (%.17g reads back to the same double).
void check_header_forces(const Workdir& w, const std::string& table, const std::string& name) {
  CAPTURE(table);
  REQUIRE(w.run("export --table " + table + " --format h --name " + name + " -o " + name + ".h").code == 0);
  std::string upper = name;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const bool refined = slurp(w / (name + ".h")).find(upper + "_NODES_MM") != std::string::npos;
  std::vector<double> xs;
  const double path[] = {0, 3.5, 1, 3, 1.5, 4, 2, 2.5, 0.5, 3.9, 0};
  for (std::size_t k = 0; k + 1 < std::size(path); ++k)
    for (int s = 0; s < 25; ++s) xs.push_back(path[k] + (path[k + 1] - path[k]) * s / 25.0);
  std::ostringstream xcsv;
  xcsv.precision(17);  // reads back to the same doubles, in the CLI and in C's fscanf
  xcsv << "displacement_mm\n";
  for (const double x : xs) xcsv << x << "\n";
  w.write("X.csv", xcsv.str());
  w.write(name + "_main.c", "#include <stdio.h>\n#include <hystlab/hystlab.h>\n#include \"" + name +
                                ".h\"\nint main(void) {\n"
                                "  hystlab_model* m = NULL; double x, f;\n"
                                "  if (hystlab_model_from_table(" +
                                upper + "_N, " + upper + "_LO_MM, " + upper + "_HI_MM, " + (refined ? upper + "_NODES_MM" : "NULL") + ", " + upper +
                                "_VALUES_N, " + upper +
                                "_FORCE_OFFSET_N, &m) != HYSTLAB_OK) { fprintf(stderr, \"%s\\n\", hystlab_last_error()); return 1; }\n"
                                "  FILE* in = fopen(\"X.csv\", \"r\"); char head[64]; if (!in || !fgets(head, sizeof head, in)) return 1;\n"
                                "  while (fscanf(in, \"%lf\", &x) == 1) { hystlab_model_step(m, x, &f); printf(\"%.17g\\n\", f); }\n"
                                "  hystlab_model_free(m); return 0;\n}\n");
  const std::string cc = "cd '" + (w / "").string() + "' && cc -std=c99 -Wall -Werror " HYSTLAB_C_FLAGS " -I'" + HYSTLAB_CAPI_INCLUDE + "' " + name +
                         "_main.c '" + HYSTLAB_CAPI_LIB + "' -Wl,-rpath,'" + std::filesystem::path(HYSTLAB_CAPI_LIB).parent_path().string() + "' -o " + name +
                         "_main && ./" + name + "_main > " + name + "_forces.txt";
  REQUIRE(std::system(cc.c_str()) == 0);
  const Result eval = w.run("eval --table " + table + " --input X.csv");
  REQUIRE(eval.code == 0);
  std::istringstream cli(eval.out), c(slurp(w / (name + "_forces.txt")));
  std::string line;
  std::getline(cli, line);
  int same = 0, count = 0;
  for (std::string a, b; std::getline(cli, a) && std::getline(c, b); ++count)
    same += std::stod(a.substr(a.find(',') + 1)) == std::strtod(b.c_str(), nullptr) ? 1 : 0;
  CHECK(count == static_cast<int>(xs.size()));
  CHECK(same == count);
}

}  // namespace

TEST_CASE("cli: export a table and parameters as JSON, CSV, MATLAB and a C header that compiles") {
  Workdir w;
  REQUIRE(w.run("identify --model simplified --range 0,4 --subdivisions 6 -o T.json").code == 0);
  REQUIRE(w.run("export --table T.json --format csv -o T.csv").code == 0);
  REQUIRE(w.run("export --table T.json --format h --name isolator -o isolator.h").code == 0);
  REQUIRE(w.run("export --table T.json --format m -o T.m").code == 0);
  REQUIRE(w.run("export --table T.json --format json -o T2.json").code == 0);
  CHECK(slurp(w / "T.m").find("function f = hystlab_eval(T, x)") != std::string::npos);
  CHECK(slurp(w / "T2.json").find("\"hystlab-everett-table\"") != std::string::npos);
  // The header, compiled by the C compiler, holds the CSV's node values exactly.
  w.write("main.c",
          "#include <stdio.h>\n#include \"isolator.h\"\nint main(void) {\n"
          "  for (int k = 0; k < ISOLATOR_NODE_COUNT; ++k) printf(\"%.17g\\n\", ISOLATOR_VALUES_N[k]);\n"
          "  printf(\"%d %.17g %.17g\\n\", ISOLATOR_N, ISOLATOR_LO_MM, ISOLATOR_HI_MM);\n  return 0;\n}\n");
  const std::string cc = "cd '" + (w / "").string() + "' && cc -std=c99 -Wall -Werror main.c -o main && ./main > values.txt";
  REQUIRE(std::system(cc.c_str()) == 0);
  std::istringstream csv(slurp(w / "T.csv")), values(slurp(w / "values.txt"));
  std::vector<double> from_csv, from_c;
  for (std::string line; std::getline(csv, line);)
    if (!line.empty() && line[0] != '#' && line[0] != 'i') from_csv.push_back(std::stod(line.substr(line.rfind(',') + 1)));
  for (std::string line; std::getline(values, line);) from_c.push_back(std::strtod(line.c_str(), nullptr));
  REQUIRE(from_csv.size() == 28);  // (n+1)(n+2)/2
  REQUIRE(from_c.size() == 29);
  for (std::size_t k = 0; k < 28; ++k) CHECK(from_c[k] == from_csv[k]);
  check_header_forces(w, "T.json", "isolator");
  REQUIRE(w.run("identify --model simplified --range 0,4 --subdivisions 9 --refine 2,1 -o R.json").code == 0);
  check_header_forces(w, "R.json", "refined");  // a grid of its own: NAME_NODES_MM
  w.write("P.json", R"({"model": "simplified-sma", "KA_N_per_mm": 40, "KM_N_per_mm": 150, "dtr_max_mm": 2.95, "C_N_per_degC": 5.7,
                        "Mf0_degC": 12.7, "Ms0_degC": 17.9, "As0_degC": 17.9, "Af0_degC": 21.5, "T_degC": 25})");
  const Result ph = w.run("export --params P.json --format h --name tube");
  REQUIRE(ph.code == 0);
  CHECK(ph.out.find("static const double TUBE_KM = 150;") != std::string::npos);
  CHECK(w.run("export --params P.json --format csv").out.find("dtr_max,2.95,mm") != std::string::npos);
  CHECK(w.run("export --params P.json --format m").out.find("P.Af0 = 21.5;") != std::string::npos);
  check_error(w.run("export --table T.json --format xlsx"), "xlsx");
  check_error(w.run("export --table T.json --params P.json --format h"), "one of");
  check_error(w.run("export --params T.json --format fmu -o T.fmu"), "parameter file 'T.json': missing field");  // the kind named is the kind read
  check_error(w.run("export --table P.json --format fmu"), "table file 'P.json': missing field 'format'");
  check_error(w.run("export --table T.json --format fmu"), "-o FILE.fmu");
  check_error(w.run("export --table T.json --format h --name 9lives"), "not a C identifier");
}
