// The FMU's state (get, set, serialize: a rolled-back step gives the same output), two instances
// at once, the input's derivatives within a step, the parameters, and every refusal with its reason.
#include <doctest/doctest.h>

#include "fmu_workspace.hpp"

using namespace hystlab::test;

namespace {
bool logged(const LogBook& b, const std::string& what) {
  for (const auto& m : b.messages)
    if (m.find(what) != std::string::npos) return true;
  return false;
}
}  // namespace

TEST_CASE("fmu: a state got, set and serialized rolls a simulation back to the same outputs") {
  Workspace w;
  Fmu f(w.fmu("T.json", "T.fmu"), w.dir / "T");
  const std::vector<double> x = random_input(11, 0.0, 4.0, 1600);
  LogBook book;
  const auto cb = callbacks(book);
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const std::size_t cut = 100 + std::mt19937_64(seed)() % 1200;
    CAPTURE(cut);
    fmi2Component c = started(f, cb);
    const std::vector<double> head(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(cut));
    (void)run_fmu(f, c, head);
    fmi2FMUstate s = nullptr;
    REQUIRE(f.fmi2GetFMUstate(c, &s) == fmi2OK);
    const std::vector<double> first = run_fmu(f, c, x, cut, 1.0);
    REQUIRE(f.fmi2SetFMUstate(c, s) == fmi2OK);  // roll back
    CHECK(exact_matches(run_fmu(f, c, x, cut, 1.0), first) == static_cast<int>(first.size()));
    const std::vector<fmi2Byte> bytes = serialized(f, c, s);
    const std::size_t size = bytes.size();
    fmi2Component other = started(f, cb);  // a second instance takes the serialized state
    (void)run_fmu(f, other, {0.0});
    CHECK(f.fmi2SetFMUstate(other, s) == fmi2Error);  // a handle is its instance's own
    CHECK(logged(book, "not got from this instance"));
    fmi2FMUstate back = reinterpret_cast<fmi2FMUstate>(0x1);  // output only: never read
    REQUIRE(f.fmi2DeSerializeFMUstate(other, bytes.data(), size, &back) == fmi2OK);
    REQUIRE(f.fmi2SetFMUstate(other, back) == fmi2OK);
    CHECK(exact_matches(run_fmu(f, other, x, cut, 1.0), first) == static_cast<int>(first.size()));
    REQUIRE(f.fmi2GetFMUstate(c, &s) == fmi2OK);  // overwritten in place
    CHECK(f.fmi2FreeFMUstate(c, &s) == fmi2OK);
    CHECK(s == nullptr);
    fmi2FMUstate left = nullptr;
    REQUIRE(f.fmi2GetFMUstate(other, &left) == fmi2OK);  // left for fmi2FreeInstance (the leak checker watches)
    (void)left;
    f.fmi2FreeInstance(other);
    f.fmi2FreeInstance(c);
  }
}

TEST_CASE("fmu: F follows x and the parameters in initialization mode, before the memory takes it") {
  Workspace w;
  Fmu f(w.fmu("T.json", "T.fmu"), w.dir / "T");
  LogBook book;
  const auto cb = callbacks(book);
  fmi2Component c = started(f, cb), ref = started(f, cb);
  const double offset = 2.0, zero = 0.0;
  REQUIRE(f.fmi2SetReal(c, &kXOffset, 1, &offset) == fmi2OK);
  REQUIRE(f.fmi2SetReal(c, &kX, 1, &zero) == fmi2OK);
  double in_init = -1, after = -2;
  REQUIRE(f.fmi2GetReal(c, &kF, 1, &in_init) == fmi2OK);
  REQUIRE(f.fmi2ExitInitializationMode(c) == fmi2OK);
  REQUIRE(f.fmi2GetReal(c, &kF, 1, &after) == fmi2OK);
  CHECK(in_init == after);
  CHECK(after > 0.0);  // 2 mm into the table, not the rest force
  (void)run_fmu(f, ref, {2.0});
  double at2 = 0;
  REQUIRE(f.fmi2GetReal(ref, &kF, 1, &at2) == fmi2OK);
  CHECK(after == at2);
  // A refused step (an input beyond a finite number in mm) leaves the instance as it was.
  const double huge = 1e308;
  fmi2Component m = started(f, cb);
  const double big_scale = 1e10;
  REQUIRE(f.fmi2SetReal(m, &kXScale, 1, &big_scale) == fmi2OK);
  (void)run_fmu(f, m, {0.0});
  REQUIRE(f.fmi2SetReal(m, &kX, 1, &huge) == fmi2OK);
  CHECK(f.fmi2DoStep(m, 0.0, 1.0, fmi2True) == fmi2Error);
  CHECK(logged(book, "beyond a finite number"));
  REQUIRE(f.fmi2SetReal(m, &kX, 1, &zero) == fmi2OK);
  double back = -1;
  REQUIRE(f.fmi2GetReal(m, &kF, 1, &back) == fmi2OK);
  CHECK(back == 0.0);  // at rest still
  for (fmi2Component k : {c, ref, m}) f.fmi2FreeInstance(k);
}

TEST_CASE("fmu: a state from another table, or bytes that are no state, are refused by name") {
  Workspace w;
  Fmu a(w.fmu("T.json", "T.fmu"), w.dir / "A"), b(w.fmu("T2.json", "T2.fmu"), w.dir / "B");
  CHECK(a.guid != b.guid);
  LogBook book;
  const auto cb = callbacks(book);
  fmi2Component ca = started(a, cb), cbi = started(b, cb);
  (void)run_fmu(a, ca, {0.0, 2.0, 1.0});
  (void)run_fmu(b, cbi, {0.0});
  fmi2FMUstate s = nullptr;
  REQUIRE(a.fmi2GetFMUstate(ca, &s) == fmi2OK);
  std::vector<fmi2Byte> bytes = serialized(a, ca, s);
  const std::size_t size = bytes.size();
  fmi2FMUstate into = nullptr;
  CHECK(b.fmi2DeSerializeFMUstate(cbi, bytes.data(), size, &into) == fmi2Error);
  CHECK(into == nullptr);
  CHECK(logged(book, "saved by another FMU"));
  bytes.resize(size / 2);
  CHECK(a.fmi2DeSerializeFMUstate(ca, bytes.data(), bytes.size(), &into) == fmi2Error);
  CHECK(logged(book, "bytes for"));
  const std::string junk = "not a state at all";
  CHECK(a.fmi2DeSerializeFMUstate(ca, junk.data(), junk.size(), &into) == fmi2Error);
  CHECK(logged(book, "not a serialized hystlab FMU state"));
  std::vector<fmi2Byte> small(8);
  CHECK(a.fmi2SerializeFMUstate(ca, s, small.data(), small.size()) == fmi2Error);
  CHECK(logged(book, "the buffer holds 8 bytes"));
  // After every refusal the instance still steps as before.
  double F = 0, want = 0;
  CHECK(a.fmi2SetFMUstate(ca, s) == fmi2OK);
  CHECK(a.fmi2GetReal(ca, &kF, 1, &want) == fmi2OK);
  CHECK(a.fmi2DoStep(ca, 1.0, 1e-3, fmi2True) == fmi2OK);
  CHECK(a.fmi2GetReal(ca, &kF, 1, &F) == fmi2OK);
  CHECK(F == want);  // the input held: the same force
  a.fmi2FreeFMUstate(ca, &s);
  a.fmi2FreeInstance(ca);
  b.fmi2FreeInstance(cbi);
}

TEST_CASE("fmu: two instances at once keep their own memory") {
  Workspace w;
  Fmu f(w.fmu("T.json", "T.fmu"), w.dir / "T");
  const std::vector<double> x1 = random_input(3, 0.0, 4.0, 800), x2 = random_input(4, 0.0, 4.0, 800);
  const std::vector<double> want1 = cli_forces(w, "--table T.json", x1), want2 = cli_forces(w, "--table T.json", x2);
  LogBook book;
  const auto cb = callbacks(book);
  fmi2Component a = started(f, cb), b = started(f, cb);
  std::vector<double> got1, got2;
  for (std::size_t k = 0; k < x1.size(); ++k) {  // interleaved, step by step
    got1.push_back(run_fmu(f, a, std::vector<double>(x1.begin(), x1.begin() + static_cast<std::ptrdiff_t>(k + 1)), k, 0.0)[0]);
    got2.push_back(run_fmu(f, b, std::vector<double>(x2.begin(), x2.begin() + static_cast<std::ptrdiff_t>(k + 1)), k, 0.0)[0]);
  }
  CHECK(exact_matches(got1, want1) == static_cast<int>(x1.size()));
  CHECK(exact_matches(got2, want2) == static_cast<int>(x2.size()));
  f.fmi2FreeInstance(a);
  f.fmi2FreeInstance(b);
}

TEST_CASE("fmu: an input turning inside a step (second derivative) is followed through its turning point") {
  Workspace w;
  Fmu f(w.fmu("T.json", "T.fmu"), w.dir / "T");
  LogBook book;
  const auto cb = callbacks(book);
  fmi2Component c = started(f, cb), ref = started(f, cb);
  (void)run_fmu(f, c, {0.0, 3.0, 1.0});
  (void)run_fmu(f, ref, {0.0, 3.0, 1.0, 0.5, 1.0});  // the same path with its turning point at 0.5 mm
  // x(τ) = 1 − 2τ + 2τ² over h = 1 s: down to 0.5 mm at τ = 0.5 s, back up to 1 mm.
  const fmi2Integer orders[2] = {1, 2};
  const fmi2ValueReference refs[2] = {kX, kX};
  const double ders[2] = {-2.0, 4.0};
  REQUIRE(f.fmi2SetRealInputDerivatives(c, refs, 2, orders, ders) == fmi2OK);
  REQUIRE(f.fmi2DoStep(c, 1.0, 1.0, fmi2True) == fmi2OK);
  double F = 0, Fref = 1;
  CHECK(f.fmi2GetReal(c, &kF, 1, &F) == fmi2OK);
  CHECK(f.fmi2GetReal(ref, &kF, 1, &Fref) == fmi2OK);
  CHECK(F == Fref);
  double held = 0;  // a held input over the same step: no turning point, another force
  fmi2Component plain = started(f, cb);
  (void)run_fmu(f, plain, {0.0, 3.0, 1.0, 1.0});
  CHECK(f.fmi2GetReal(plain, &kF, 1, &held) == fmi2OK);
  CHECK(held != F);
  const fmi2Integer third = 3;
  CHECK(f.fmi2SetRealInputDerivatives(c, refs, 1, &third, ders) == fmi2Error);
  CHECK(logged(book, "order 3"));
  for (fmi2Component k : {c, ref, plain}) f.fmi2FreeInstance(k);
}

TEST_CASE("fmu: parameters scale the input and the force; refusals are named and leave the instance usable") {
  Workspace w;
  Fmu f(w.fmu("T.json", "T.fmu"), w.dir / "T");
  const std::vector<double> x = random_input(5, 0.0, 4.0, 500);
  const std::vector<double> want = cli_forces(w, "--table T.json", x);
  LogBook book;
  const auto cb = callbacks(book);
  fmi2Component c = started(f, cb);
  const double two = 2.0;
  const fmi2Integer minus = -1;
  REQUIRE(f.fmi2SetReal(c, &kForceScale, 1, &two) == fmi2OK);
  REQUIRE(f.fmi2SetInteger(c, &kSign, 1, &minus) == fmi2OK);
  const std::vector<double> got = run_fmu(f, c, x);
  int scaled = 0;
  for (std::size_t k = 0; k < x.size(); ++k) scaled += got[k] == -2.0 * want[k] ? 1 : 0;
  CHECK(scaled == static_cast<int>(x.size()));
  CHECK(f.fmi2SetReal(c, &kForceScale, 1, &two) == fmi2Error);  // fixed: not after initialization
  CHECK(logged(book, "force_scale: a fixed parameter"));
  const double nan = std::nan("");
  CHECK(f.fmi2SetReal(c, &kX, 1, &nan) == fmi2Error);
  CHECK(logged(book, "x: nan is not a finite number"));
  CHECK(f.fmi2SetReal(c, &kF, 1, &two) == fmi2Error);
  CHECK(logged(book, "F is an output"));
  CHECK(f.fmi2DoStep(c, 0.0, 0.0, fmi2True) == fmi2Error);
  CHECK(logged(book, "communicationStepSize 0"));
  double F = 0;
  CHECK(f.fmi2GetReal(c, &kF, 1, &F) == fmi2OK);
  CHECK(F == got.back());  // nothing refused was taken
  f.fmi2FreeInstance(c);

  fmi2Component m = started(f, cb);  // x in metres: the same forces
  const double thousand = 1000.0;
  REQUIRE(f.fmi2SetReal(m, &kXScale, 1, &thousand) == fmi2OK);
  std::vector<double> metres;
  for (const double v : x) metres.push_back(v / 1000.0);
  const std::vector<double> in_m = run_fmu(f, m, metres);
  double worst = 0;
  for (std::size_t k = 0; k < x.size(); ++k) worst = std::max(worst, std::abs(in_m[k] - want[k]));
  CHECK(worst < 1e-9);
  f.fmi2FreeInstance(m);
}

TEST_CASE("fmu: an instantiation that cannot work says why, and nothing else is touched") {
  Workspace w;
  Fmu f(w.fmu("T.json", "T.fmu"), w.dir / "T");
  LogBook book;
  const auto cb = callbacks(book);
  const std::string uri = f.resource_uri();
  CHECK(f.fmi2Instantiate("a", fmi2CoSimulation, "{wrong}", uri.c_str(), &cb, fmi2False, fmi2False) == nullptr);
  CHECK(logged(book, "does not match the FMU's resources"));
  CHECK(f.fmi2Instantiate("b", fmi2ModelExchange, f.guid.c_str(), uri.c_str(), &cb, fmi2False, fmi2False) == nullptr);
  CHECK(logged(book, "co-simulation only"));
  CHECK(f.fmi2Instantiate("c", fmi2CoSimulation, f.guid.c_str(), "file:///nowhere", &cb, fmi2False, fmi2False) == nullptr);
  CHECK(logged(book, "cannot read the FMU's resource"));
  CHECK(f.fmi2Instantiate("d", fmi2CoSimulation, f.guid.c_str(), "http://example.org/r", &cb, fmi2False, fmi2False) == nullptr);
  CHECK(logged(book, "is not a file: URI"));
  CHECK(f.fmi2DoStep(nullptr, 0.0, 1.0, fmi2True) == fmi2Error);
  fmi2Component c = f.instantiate(cb);
  REQUIRE(c != nullptr);
  CHECK(f.fmi2DoStep(c, 0.0, 1.0, fmi2True) == fmi2Error);  // before initialization
  CHECK(logged(book, "not initialized"));
  f.fmi2FreeInstance(c);
  // A table of an unknown version is refused by the exporter, naming the version.
  std::ofstream(w.dir / "bad.json") << R"({"format": "hystlab-everett-table", "version": 7})";
  int st = 0;
  const std::string out = w.run("export --table bad.json --format fmu -o bad.fmu", &st);
  CHECK(st == 2);
  CHECK(out.find("version") != std::string::npos);
  CHECK(!fs::exists(w.dir / "bad.fmu"));
}
