#include "report_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace hystlab::web::report {

std::string num(double v, int digits) {
  if (!std::isfinite(v)) return "–";
  char b[48];
  const double a = std::fabs(v);
  if (a < 1e-9) return "0";  // a float's zero that a sum left at 1e-20
  if (a >= 1e6 || a < 1e-3)
    std::snprintf(b, sizeof b, "%.*e", std::max(digits - 2, 0), v);
  else if (a >= std::pow(10.0, digits - 1))
    std::snprintf(b, sizeof b, "%.0f", v);
  else
    std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string esc(const std::string& s) {
  std::string o;
  o.reserve(s.size());
  for (const char c : s) {
    if (c == '&')
      o += "&amp;";
    else if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '"')
      o += "&quot;";
    else
      o += c;
  }
  return o;
}

namespace {

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  [[nodiscard]] bool ok() const { return lo <= hi; }
};

// Round ticks: 1, 2 or 5 times a power of ten, about five of them (a log axis: the decades, and
// 2 and 5 within them when it spans less than two).
std::vector<double> ticks(double lo, double hi, bool log) {
  std::vector<double> t;
  if (log) {
    const int a = static_cast<int>(std::floor(std::log10(lo))), b = static_cast<int>(std::ceil(std::log10(hi)));
    for (int e = a; e <= b; ++e)
      for (const double m : b - a <= 3 ? std::vector<double>{1, 2, 5} : std::vector<double>{1}) {
        const double v = m * std::pow(10.0, e);
        if (v >= lo * 0.999 && v <= hi * 1.001) t.push_back(v);
      }
    return t;
  }
  const double raw = (hi - lo) / 5, p = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw / p < 1.5 ? p : raw / p < 3.5 ? 2 * p : raw / p < 7.5 ? 5 * p : 10 * p;
  for (double v = std::ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) t.push_back(std::fabs(v) < step * 1e-9 ? 0.0 : v);
  return t;
}

// The range an axis shows: the data's with a little room, or the decades around it on a log axis.
Range axis_range(Range r, bool log) {
  if (log) {
    r.lo = std::pow(10.0, std::floor(std::log10(r.lo) * 4) / 4), r.hi = std::pow(10.0, std::ceil(std::log10(r.hi) * 4) / 4);
    return r;
  }
  if (r.hi - r.lo < 1e-12) r.lo -= 1, r.hi += 1;
  const double pad = 0.03 * (r.hi - r.lo);
  return {r.lo - pad, r.hi + pad};
}

}  // namespace

std::string svg_xy(const std::vector<Series>& series, const Axis& x, const Axis& y, int width, int height) {
  Range rx, ry;
  for (const Series& s : series)
    for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k)
      if ((!x.log || s.x[k] > 0) && (!y.log || s.y[k] > 0)) rx.add(s.x[k]), ry.add(s.y[k]);
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" << width << "\" height=\"" << height << "\" viewBox=\"0 0 " << width << ' ' << height
    << "\" font-family=\"sans-serif\" font-size=\"11\">";
  if (!rx.ok() || !ry.ok()) return o.str() + "<text x=\"10\" y=\"20\">no data</text></svg>";
  rx = axis_range(rx, x.log), ry = axis_range(ry, y.log);
  const double L = 62, R = width - 12.0, T = 12, B = height - 40.0;
  auto px = [&](double v) {
    return x.log ? L + (std::log10(v) - std::log10(rx.lo)) / (std::log10(rx.hi) - std::log10(rx.lo)) * (R - L) : L + (v - rx.lo) / (rx.hi - rx.lo) * (R - L);
  };
  auto py = [&](double v) {
    return y.log ? B - (std::log10(v) - std::log10(ry.lo)) / (std::log10(ry.hi) - std::log10(ry.lo)) * (B - T) : B - (v - ry.lo) / (ry.hi - ry.lo) * (B - T);
  };
  char b[96];
  for (const double t : ticks(rx.lo, rx.hi, x.log)) {
    std::snprintf(b, sizeof b, "%.1f", px(t));
    o << "<line x1=\"" << b << "\" x2=\"" << b << "\" y1=\"" << T << "\" y2=\"" << B << "\" stroke=\"#e0e0e0\"/><text x=\"" << b << "\" y=\"" << B + 14
      << "\" text-anchor=\"middle\">" << num(t, 3) << "</text>";
  }
  for (const double t : ticks(ry.lo, ry.hi, y.log)) {
    std::snprintf(b, sizeof b, "%.1f", py(t));
    o << "<line x1=\"" << L << "\" x2=\"" << R << "\" y1=\"" << b << "\" y2=\"" << b << "\" stroke=\"#e0e0e0\"/><text x=\"" << L - 4 << "\" y=\"" << b
      << "\" dy=\"4\" text-anchor=\"end\">" << num(t, 3) << "</text>";
  }
  o << "<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << R - L << "\" height=\"" << B - T << "\" fill=\"none\" stroke=\"#555\"/>";
  o << "<text x=\"" << (L + R) / 2 << "\" y=\"" << height - 6 << "\" text-anchor=\"middle\">" << esc(x.label) << "</text>";
  o << "<text transform=\"translate(14," << (T + B) / 2 << ") rotate(-90)\" text-anchor=\"middle\">" << esc(y.label) << "</text>";
  int legend = 0;
  for (const Series& s : series) {
    std::string path;
    for (std::size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
      if (!std::isfinite(s.x[k]) || !std::isfinite(s.y[k]) || (x.log && s.x[k] <= 0) || (y.log && s.y[k] <= 0)) continue;
      std::snprintf(b, sizeof b, "%s%.1f,%.1f", path.empty() ? "M" : " L", px(s.x[k]), py(s.y[k]));
      path += b;
      if (s.markers) {
        std::snprintf(b, sizeof b, "%.1f\" cy=\"%.1f", px(s.x[k]), py(s.y[k]));
        o << "<circle cx=\"" << b << "\" r=\"2.5\" fill=\"" << s.color << "\"/>";
      }
    }
    if (!s.markers || s.x.size() > 1)
      o << "<path d=\"" << path << "\" fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"1.2\"" << (s.dashed ? " stroke-dasharray=\"5 3\"" : "")
        << "/>";
    if (!s.label.empty() && series.size() > 1) {
      const double ly = T + 14 + 14.0 * legend++;
      o << "<line x1=\"" << L + 10 << "\" x2=\"" << L + 30 << "\" y1=\"" << ly - 4 << "\" y2=\"" << ly - 4 << "\" stroke=\"" << s.color
        << "\" stroke-width=\"2\"" << (s.dashed ? " stroke-dasharray=\"5 3\"" : "") << "/><text x=\"" << L + 34 << "\" y=\"" << ly << "\">" << esc(s.label)
        << "</text>";
    }
  }
  return o.str() + "</svg>";
}

namespace {
// A perceptual-ish ramp from pale yellow to dark blue (viridis' ends, reversed), t in [0, 1].
std::string ramp(double t) {
  t = std::clamp(t, 0.0, 1.0);
  const double r0 = 253, g0 = 231, b0 = 37, r1 = 68, g1 = 1, b1 = 84;  // viridis: yellow -> purple
  const double m = t < 0.5 ? t * 2 : (t - 0.5) * 2;
  const double rm = 33, gm = 145, bm = 140;  // viridis' middle, teal
  char b[16];
  if (t < 0.5)
    std::snprintf(b, sizeof b, "#%02x%02x%02x", static_cast<int>(r0 + (rm - r0) * m), static_cast<int>(g0 + (gm - g0) * m),
                  static_cast<int>(b0 + (bm - b0) * m));
  else
    std::snprintf(b, sizeof b, "#%02x%02x%02x", static_cast<int>(rm + (r1 - rm) * m), static_cast<int>(gm + (g1 - gm) * m),
                  static_cast<int>(bm + (b1 - bm) * m));
  return b;
}
}  // namespace

std::string svg_heatmap(const std::vector<HeatCell>& cells, double lo_mm, double hi_mm, int n, int size) {
  Range r;
  for (const HeatCell& c : cells) r.add(c.value);
  std::ostringstream o;
  const int legend = 90, w = size + legend;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" << w << "\" height=\"" << size + 40 << "\" viewBox=\"0 0 " << w << ' ' << size + 40
    << "\" font-family=\"sans-serif\" font-size=\"11\">";
  if (!r.ok() || n < 1 || !(hi_mm > lo_mm)) return o.str() + "<text x=\"10\" y=\"20\">no nodes</text></svg>";
  const double L = 50, T = 10, S = size - 60.0, cell = S / n, step = (hi_mm - lo_mm) / n;
  // α runs right, β up; a node (α_i, β_j) is the cell whose upper-left corner it is.
  for (const HeatCell& c : cells) {
    const double i = std::round((c.alpha - lo_mm) / step), j = std::round((c.beta - lo_mm) / step);
    const double t = r.hi > r.lo ? (c.value - r.lo) / (r.hi - r.lo) : 0.5;
    char b[160];
    std::snprintf(b, sizeof b, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"%s\"><title>", L + (i - 1) * cell, T + (n - 1 - j) * cell,
                  cell, cell, ramp(t).c_str());
    o << b << "α " << num(c.alpha) << " mm, β " << num(c.beta) << " mm: F " << num(c.value) << " N</title></rect>";
  }
  o << "<path d=\"M" << L << ',' << T + S << " L" << L + S << ',' << T + S << " L" << L + S << ',' << T << " Z\" fill=\"none\" stroke=\"#555\"/>";
  for (int k = 0; k <= n; k += std::max(1, n / 4)) {
    const double v = lo_mm + k * step;
    o << "<text x=\"" << L + (k - 1) * cell + cell << "\" y=\"" << T + S + 14 << "\" text-anchor=\"middle\">" << num(v) << "</text>";
    o << "<text x=\"" << L - 4 << "\" y=\"" << T + S - k * cell << "\" dy=\"4\" text-anchor=\"end\">" << num(v) << "</text>";
  }
  o << "<text x=\"" << L + S / 2 << "\" y=\"" << T + S + 30 << "\" text-anchor=\"middle\">α (mm), the input's last maximum</text>";
  o << "<text transform=\"translate(12," << T + S / 2 << ") rotate(-90)\" text-anchor=\"middle\">β (mm), its last minimum</text>";
  // The colour scale: the measured range of F, in N.
  const double lx = L + S + 24, lh = S * 0.8;
  for (int k = 0; k < 40; ++k)
    o << "<rect x=\"" << lx << "\" y=\"" << T + lh - (k + 1) * lh / 40 << "\" width=\"14\" height=\"" << lh / 40 + 0.5 << "\" fill=\"" << ramp((k + 0.5) / 40)
      << "\"/>";
  for (const double t : ticks(r.lo, r.hi, false))
    o << "<text x=\"" << lx + 18 << "\" y=\"" << T + lh - (t - r.lo) / (r.hi - r.lo) * lh << "\" dy=\"4\">" << num(t) << "</text>";
  o << "<text x=\"" << lx << "\" y=\"" << T + lh + 18 << "\">F (N)</text>";
  return o.str() + "</svg>";
}

}  // namespace hystlab::web::report
