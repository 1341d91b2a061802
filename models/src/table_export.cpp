#include "hystlab/models/table_export.hpp"

#include "hystlab/models/text_forms.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <sstream>
#include <tuple>
#include <vector>

namespace hystlab::models {
namespace {
std::string num(double v) { return exact_text(v); }

int version_of(const Grid& g) { return g.uniform() ? kTableVersion : kTableVersionNodes; }

// Provenance as comment text: one line, no line breaks smuggled in from a source name.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

const char* kMatlabFunctions = R"(
function f = hystlab_eval(T, x)
  % Force series for the displacement series x (mm), from rest at delta_min (MODELS.md section 1).
  % Memory: minima m = [m0 m1 ...] (m0 = delta_min) and maxima M = [M1 M2 ...]; rising when
  % numel(m) == numel(M) + 1. Wiping-out removes a pair when the input passes it.
  f = zeros(size(x));
  m = T.lo; M = []; xp = T.lo;
  for k = 1:numel(x)
    u = min(max(x(k), T.lo), T.hi);
    if u <= T.lo
      m = T.lo; M = []; xp = T.lo; f(k) = T.force_offset;
      continue;
    end
    rising = numel(m) == numel(M) + 1;
    if rising && u < xp
      M(end + 1) = xp; rising = false;
    elseif ~rising && u > xp
      m(end + 1) = xp; rising = true;
    end
    if rising
      while ~isempty(M) && u >= M(end)
        M(end) = []; m(end) = [];
      end
    else
      while numel(m) >= 2 && u <= m(end)
        m(end) = []; M(end) = [];
      end
    end
    N = numel(M); s = 0;
    if rising
      for q = 1:N
        s = s + hystlab_everett(T, M(q), m(q)) - hystlab_everett(T, M(q), m(q + 1));
      end
      s = s + hystlab_everett(T, u, m(end));
    else
      for q = 1:N - 1
        s = s + hystlab_everett(T, M(q), m(q)) - hystlab_everett(T, M(q), m(q + 1));
      end
      s = s + hystlab_everett(T, M(N), m(N)) - hystlab_everett(T, M(N), u);
    end
    f(k) = s + T.force_offset;
    xp = u;
  end
end

function v = hystlab_everett(T, a, b)
  % F(a, b): bilinear on rectangles (Eq. 8), linear on the diagonal triangles (Eq. 9).
  a = min(max(a, T.lo), T.hi); b = min(max(b, T.lo), a);
  if isfield(T, 'nodes')  % a grid of its own (format version 2): the cells by search
    i = min(max(sum(T.nodes(2:end) <= a) + 1, 1), T.n); j = min(max(sum(T.nodes(2:end) <= b) + 1, 1), i);
    s = (a - T.nodes(i)) / (T.nodes(i + 1) - T.nodes(i)); t = (b - T.nodes(j)) / (T.nodes(j + 1) - T.nodes(j));
    if j == i, t = min(t, s); end
  else
    r = 1 / ((T.hi - T.lo) / T.n);  % as the library: times the reciprocal step, to the last digit
    u = (a - T.lo) * r; w = (b - T.lo) * r;
    i = min(floor(u) + 1, T.n); j = min(floor(w) + 1, i);
    s = u - (i - 1); t = w - (j - 1);
  end
  F = T.F;
  if j < i
    v = (1 - s) * ((1 - t) * F(i, j) + t * F(i, j + 1)) + s * ((1 - t) * F(i + 1, j) + t * F(i + 1, j + 1));
  else
    v = F(i, i) + (F(i + 1, i) - F(i, i)) * s + (F(i + 1, i + 1) - F(i + 1, i)) * min(t, s);
  end
end
)";
void check_identifier(const std::string& name) {
  bool ok = !name.empty() && name.size() <= 64 && !std::isdigit(static_cast<unsigned char>(name[0]));
  for (char c : name) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_');
  if (!ok) throw FormatError("export: '" + name + "' is not a C identifier (letters, digits, _; not starting with a digit)");
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// The parameters in the order of docs/FORMATS.md, with their units.
std::vector<std::tuple<const char*, double, const char*>> params_of(const SmaParameters& p) {
  return {{"KA", p.KA, "N/mm"},   {"KM", p.KM, "N/mm"},   {"dtr_max", p.dtr_max, "mm"}, {"C", p.C, "N/degC"}, {"Mf0", p.Mf0, "degC"},
          {"Ms0", p.Ms0, "degC"}, {"As0", p.As0, "degC"}, {"Af0", p.Af0, "degC"},       {"T", p.T, "degC"}};
}
}  // namespace

std::string table_to_c_header(const EverettTable& table, const TableProvenance& p, const std::string& name) {
  check_identifier(name);
  const std::string N = upper(name);
  const Grid& g = table.grid();
  std::ostringstream o;
  o << "/* hystlab Everett table (" << kTableFormat << " v" << version_of(g) << "), " << one_line(p.method) << ", " << one_line(p.source) << ", created "
    << one_line(p.created) << ".\n"
    << " * F(delta_i, delta_j) in N for 0 <= j <= i <= n at " << N << "_VALUES_N[i*(i+1)/2 + j];\n"
    << (g.uniform() ? " * delta_i = lo + (hi - lo) * i / n in mm." : " * delta_i = " + N + "_NODES_MM[i] in mm (a grid of its own).")
    << " Evaluate with the memory-stack rule of hystlab's docs. */\n"
    << "#ifndef " << N << "_H\n#define " << N << "_H\n\n"
    << "#define " << N << "_N " << g.n << "\n"
    << "#define " << N << "_NODE_COUNT " << Grid::node_count(g.n) << "\n"
    << "static const double " << N << "_LO_MM = " << num(g.lo) << ";\n"
    << "static const double " << N << "_HI_MM = " << num(g.hi) << ";\n"
    << "static const double " << N << "_FORCE_OFFSET_N = " << num(table.force_offset()) << ";\n";
  if (!g.uniform()) {
    o << "static const double " << N << "_NODES_MM[" << N << "_N + 1] = {";
    for (int i = 0; i <= g.n; ++i) o << (i ? ", " : "") << num(g.node(i));
    o << "};\n";
  }
  o << "static const double " << N << "_VALUES_N[" << N << "_NODE_COUNT] = {\n";
  for (int i = 0; i <= g.n; ++i) {
    o << "   ";
    for (int j = 0; j <= i; ++j) o << " " << num(table.node_value(i, j)) << ",";
    o << "\n";
  }
  o << "};\n\n#endif\n";
  return o.str();
}

std::string params_to_csv(const SmaParameters& p) {
  std::ostringstream o;
  o << "# " << kParamsModel << "\nname,value,unit\n";
  for (const auto& [n, v, u] : params_of(p)) o << n << "," << num(v) << "," << u << "\n";
  return o.str();
}

std::string params_to_matlab(const SmaParameters& p) {
  std::ostringstream o;
  o << "% hystlab " << kParamsModel << " parameters (N, mm, degC).\nP = struct();\n";
  for (const auto& [n, v, u] : params_of(p)) o << "P." << n << " = " << num(v) << ";  % " << u << "\n";
  return o.str();
}

std::string params_to_c_header(const SmaParameters& p, const std::string& name) {
  check_identifier(name);
  const std::string N = upper(name);
  std::ostringstream o;
  o << "/* hystlab " << kParamsModel << " parameters (N, mm, degC). */\n#ifndef " << N << "_H\n#define " << N << "_H\n";
  for (const auto& [n, v, u] : params_of(p)) o << "static const double " << N << "_" << upper(n) << " = " << num(v) << "; /* " << u << " */\n";
  o << "#endif\n";
  return o.str();
}

std::string table_to_csv(const EverettTable& table, const TableProvenance& p) {
  const Grid& g = table.grid();
  std::ostringstream o;
  o << "# " << kTableFormat << " v" << version_of(g) << "\n";
  o << "# n=" << g.n << " lo_mm=" << num(g.lo) << " hi_mm=" << num(g.hi) << " force_offset_N=" << num(table.force_offset()) << "\n";
  o << "# source: " << one_line(p.source) << "; method: " << one_line(p.method) << "; created: " << one_line(p.created) << "\n";
  o << "i,j,alpha_mm,beta_mm,F_N\n";
  for (int i = 0; i <= g.n; ++i)
    for (int j = 0; j <= i; ++j) o << i << "," << j << "," << num(g.node(i)) << "," << num(g.node(j)) << "," << num(table.node_value(i, j)) << "\n";
  return o.str();
}

std::string table_to_matlab(const EverettTable& table, const TableProvenance& p) {
  const Grid& g = table.grid();
  std::ostringstream o;
  o << "% hystlab Everett table (" << kTableFormat << " v" << version_of(g) << "), " << one_line(p.method) << ", " << one_line(p.source) << ", created "
    << one_line(p.created) << ".\n"
    << "% Run this script, then: f = hystlab_eval(T, x) for displacements x in mm (force in N).\n"
    << "T = struct();\nT.lo = " << num(g.lo) << ";\nT.hi = " << num(g.hi) << ";\nT.n = " << g.n << ";\nT.force_offset = " << num(table.force_offset()) << ";\n";
  if (!g.uniform()) {
    o << "T.nodes = [";
    for (int i = 0; i <= g.n; ++i) o << (i ? " " : "") << num(g.node(i));
    o << "];  % the grid's own nodes (mm)\n";
  }
  o << "% T.F(i+1, j+1) = F(delta_i, delta_j) in N for j <= i; NaN above the diagonal.\nT.F = [\n";
  for (int i = 0; i <= g.n; ++i) {
    o << " ";
    for (int j = 0; j <= g.n; ++j) o << " " << (j <= i ? num(table.node_value(i, j)) : std::string("NaN"));
    o << "\n";
  }
  o << "];\n" << kMatlabFunctions;
  return o.str();
}

}  // namespace hystlab::models
