// The FMU as an importer sees it: exported by the CLI, unpacked, its model description checked
// (well formed, what FMI 2.0 requires), its binary loaded and stepped on a random input against
// `hystlab eval` to the last digit; state got, set and serialized; and every refusal named.
#include <doctest/doctest.h>

#include "fmu_workspace.hpp"

using namespace hystlab::test;

TEST_CASE("fmu: the archive holds what FMI 2.0 requires, well formed") {
  Workspace w;
  Fmu f(w.fmu("T.json", "T.fmu"), w.dir / "T");
  int st = 0;
  shell("xmllint --noout '" + (f.dir / "modelDescription.xml").string() + "' 2>&1", &st);
  CHECK(st == 0);
  CHECK(f.xpath("string(/fmiModelDescription/@fmiVersion)") == "2.0");
  CHECK(f.guid.size() == 38);
  CHECK(f.identifier == "hystlab_element");
  CHECK(f.xpath("count(/fmiModelDescription/ModelVariables/ScalarVariable)") == "7");
  CHECK(f.xpath("string(//ScalarVariable[@name=\"x\"]/@causality)") == "input");
  CHECK(f.xpath("string(//ScalarVariable[@name=\"F\"]/Real/@unit)") == "N");
  CHECK(f.xpath("count(/fmiModelDescription/ModelStructure/Outputs/Unknown)") == "2");
  CHECK(f.xpath("string(/fmiModelDescription/CoSimulation/@canGetAndSetFMUstate)") == "true");
  CHECK(fs::exists(f.dir / "resources" / "element.json"));
  CHECK(fs::exists(f.dir / "documentation" / "index.html"));
  CHECK(fs::exists(f.dir / "documentation" / "licenses" / "license.txt"));
  const std::string dyn = shell("readelf -d '" + (f.dir / "binaries/linux64/hystlab_element.so").string() + "'");
  CHECK(dyn.find("[$ORIGIN]") != std::string::npos);
  CHECK(dyn.find("SONAME") == std::string::npos);  // two FMUs stay two libraries
  CHECK(std::string(f.fmi2GetVersion()) == "2.0");
  CHECK(std::string(f.fmi2GetTypesPlatform()) == "default");
}

TEST_CASE("fmu: a random input gives the CLI's forces to the last digit (uniform and refined tables, parameters)") {
  Workspace w;
  const std::vector<std::pair<std::string, std::string>> elements{
      {"T.json", "--table T.json --clamp"}, {"T2.json", "--table T2.json --clamp"}, {"P.json", "--model simplified --params P.json"}};
  std::uint64_t seed = 7;
  for (const auto& [file, args] : elements) {
    const std::string& element = file;  // CAPTURE takes no binding (clang 14)
    CAPTURE(element);
    Fmu f(w.fmu(file, file + ".fmu"), w.dir / (file + "-fmu"));
    const std::vector<double> x = random_input(seed++, -0.3, 4.3, 3000);
    const std::vector<double> want = cli_forces(w, args, x);
    LogBook book;
    const auto cb = hystlab::test::callbacks(book);
    fmi2Component c = started(f, cb);
    const std::vector<double> got = run_fmu(f, c, x);
    REQUIRE(want.size() == x.size());
    CHECK(exact_matches(got, want) == static_cast<int>(x.size()));
    fmi2Integer sat = -1;
    CHECK(f.fmi2GetInteger(c, &kSaturations, 1, &sat) == fmi2OK);
    if (file[0] == 'T') {
      CHECK(sat > 0);  // the input left [0, 4]: clamped, counted, and said once
      CHECK(book.messages.size() == 1);
      CHECK(book.messages[0].find("outside the table's range") != std::string::npos);
    }
    CHECK(f.fmi2Terminate(c) == fmi2OK);
    f.fmi2FreeInstance(c);
  }
}
