#include "svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace hystlab::cli {
namespace {
constexpr double kW = 720, kH = 480, kLeft = 70, kRight = 20, kTop = 40, kBottom = 55;

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else
      o += c;
  }
  return o;
}

std::string tick_label(double t, double step) {
  if (std::fabs(t) < step * 1e-9) t = 0.0;
  char b[32];
  std::snprintf(b, sizeof b, "%g", t);
  return b;
}

// "Nice" tick spacing: 1, 2 or 5 times a power of ten, about six ticks.
double tick_step(double span) {
  const double raw = span / 6.0, mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double r = raw / mag;
  return (r < 1.5 ? 1.0 : r < 3.5 ? 2.0 : r < 7.5 ? 5.0 : 10.0) * mag;
}
}  // namespace

std::string svg_plot(const std::string& title, const std::string& x_label, const std::string& y_label, const std::vector<PlotSeries>& series) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series)
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      x0 = std::min(x0, s.x[k]);
      x1 = std::max(x1, s.x[k]);
      y0 = std::min(y0, s.y[k]);
      y1 = std::max(y1, s.y[k]);
    }
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  const double xs = tick_step(x1 - x0), ys = tick_step(y1 - y0);
  x0 = std::floor(x0 / xs) * xs;
  x1 = std::ceil(x1 / xs) * xs;
  y0 = std::floor(y0 / ys) * ys;
  y1 = std::ceil(y1 / ys) * ys;
  const double pw = kW - kLeft - kRight, ph = kH - kTop - kBottom;
  auto px = [&](double x) { return kLeft + (x - x0) / (x1 - x0) * pw; };
  auto py = [&](double y) { return kTop + (1.0 - (y - y0) / (y1 - y0)) * ph; };
  std::string o = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(kW) + "\" height=\"" + num(kH) +
                  "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o += "<text x=\"" + num(kW / 2) + "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" + escape(title) + "</text>\n";
  for (double t = x0; t <= x1 + xs * 1e-6; t += xs) {
    o += "<line x1=\"" + num(px(t)) + "\" y1=\"" + num(kTop) + "\" x2=\"" + num(px(t)) + "\" y2=\"" + num(kTop + ph) + "\" stroke=\"#e5e5e5\"/>\n<text x=\"" +
         num(px(t)) + "\" y=\"" + num(kTop + ph + 16) + "\" text-anchor=\"middle\">" + tick_label(t, xs) + "</text>\n";
  }
  for (double t = y0; t <= y1 + ys * 1e-6; t += ys) {
    o += "<line x1=\"" + num(kLeft) + "\" y1=\"" + num(py(t)) + "\" x2=\"" + num(kLeft + pw) + "\" y2=\"" + num(py(t)) + "\" stroke=\"#e5e5e5\"/>\n<text x=\"" +
         num(kLeft - 6) + "\" y=\"" + num(py(t) + 4) + "\" text-anchor=\"end\">" + tick_label(t, ys) + "</text>\n";
  }
  o += "<rect x=\"" + num(kLeft) + "\" y=\"" + num(kTop) + "\" width=\"" + num(pw) + "\" height=\"" + num(ph) + "\" fill=\"none\" stroke=\"#333\"/>\n";
  o += "<text x=\"" + num(kLeft + pw / 2) + "\" y=\"" + num(kH - 12) + "\" text-anchor=\"middle\">" + escape(x_label) +
       "</text>\n<text transform=\"translate(18," + num(kTop + ph / 2) + ") rotate(-90)\" text-anchor=\"middle\">" + escape(y_label) + "</text>\n";
  for (std::size_t s = 0; s < series.size(); ++s) {
    const PlotSeries& ser = series[s];
    if (ser.markers) {
      for (std::size_t k = 0; k < ser.x.size(); ++k)
        o += "<circle cx=\"" + num(px(ser.x[k])) + "\" cy=\"" + num(py(ser.y[k])) + "\" r=\"2.5\" fill=\"" + ser.color + "\"/>\n";
    } else {
      o += "<polyline fill=\"none\" stroke=\"" + ser.color + "\" stroke-width=\"1.5\"" + (ser.dashed ? " stroke-dasharray=\"6 4\"" : "") + " points=\"";
      for (std::size_t k = 0; k < ser.x.size(); ++k) o += num(px(ser.x[k])) + "," + num(py(ser.y[k])) + " ";
      o += "\"/>\n";
    }
    const double ly = kTop + 14 + 16 * static_cast<double>(s);
    if (ser.markers)
      o += "<circle cx=\"" + num(kLeft + 22) + "\" cy=\"" + num(ly - 4) + "\" r=\"3\" fill=\"" + ser.color + "\"/>\n";
    else
      o += "<line x1=\"" + num(kLeft + 10) + "\" y1=\"" + num(ly - 4) + "\" x2=\"" + num(kLeft + 34) + "\" y2=\"" + num(ly - 4) + "\" stroke=\"" + ser.color +
           "\" stroke-width=\"2\"" + (ser.dashed ? " stroke-dasharray=\"6 4\"" : "") + "/>\n";
    o += "<text x=\"" + num(kLeft + 40) + "\" y=\"" + num(ly) + "\">" + escape(ser.name) + "</text>\n";
  }
  return o + "</svg>\n";
}

}  // namespace hystlab::cli
