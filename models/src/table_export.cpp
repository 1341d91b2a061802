#include "hystlab/models/table_export.hpp"

#include <cstdio>
#include <sstream>

namespace hystlab::models {
namespace {
// Round-trip precision: what was identified is what the other tool gets.
std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

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
  h = (T.hi - T.lo) / T.n;
  u = (a - T.lo) / h; w = (b - T.lo) / h;
  i = min(floor(u) + 1, T.n); j = min(floor(w) + 1, i);
  s = u - (i - 1); t = w - (j - 1);
  F = T.F;
  if j < i
    v = (1 - s) * ((1 - t) * F(i, j) + t * F(i, j + 1)) + s * ((1 - t) * F(i + 1, j) + t * F(i + 1, j + 1));
  else
    v = F(i, i) + (F(i + 1, i) - F(i, i)) * s + (F(i + 1, i + 1) - F(i + 1, i)) * min(t, s);
  end
end
)";
}  // namespace

std::string table_to_csv(const EverettTable& table, const TableProvenance& p) {
  const Grid& g = table.grid();
  std::ostringstream o;
  o << "# " << kTableFormat << " v" << kTableVersion << "\n";
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
  o << "% hystlab Everett table (" << kTableFormat << " v" << kTableVersion << "), " << one_line(p.method) << ", "
    << one_line(p.source) << ", created " << one_line(p.created) << ".\n"
    << "% Run this script, then: f = hystlab_eval(T, x) for displacements x in mm (force in N).\n"
    << "T = struct();\nT.lo = " << num(g.lo) << ";\nT.hi = " << num(g.hi) << ";\nT.n = " << g.n
    << ";\nT.force_offset = " << num(table.force_offset()) << ";\n"
    << "% T.F(i+1, j+1) = F(delta_i, delta_j) in N for j <= i; NaN above the diagonal.\nT.F = [\n";
  for (int i = 0; i <= g.n; ++i) {
    o << " ";
    for (int j = 0; j <= g.n; ++j) o << " " << (j <= i ? num(table.node_value(i, j)) : std::string("NaN"));
    o << "\n";
  }
  o << "];\n" << kMatlabFunctions;
  return o.str();
}

}  // namespace hystlab::models
