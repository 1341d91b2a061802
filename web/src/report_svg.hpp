#pragma once
// The campaign report's figures as inline SVG (vector graphics that print sharp and need no
// script): x-y plots with linear or logarithmic axes and round ticks, and the Everett table as a
// heatmap with its colour scale. Pure: numbers in, SVG text out.
#include <string>
#include <vector>

namespace hystlab::web::report {

// A number for people: about `digits` significant figures, no exponent for ordinary magnitudes.
[[nodiscard]] std::string num(double v, int digits = 3);
// Text safe inside HTML or SVG.
[[nodiscard]] std::string esc(const std::string& s);

struct Series {
  std::vector<double> x, y;
  std::string label, color = "#1565c0";
  bool dashed = false, markers = false;
};
struct Axis {
  std::string label;
  bool log = false;
};

// An x-y plot of the series (a legend when more than one has a label); width and height in px.
[[nodiscard]] std::string svg_xy(const std::vector<Series>& series, const Axis& x, const Axis& y, int width = 640, int height = 360);

// The identified Everett table F(α, β) on its triangle (α > β): one cell per node, coloured on a
// scale from the smallest to the largest F measured (shown beside it, in N).
struct HeatCell {
  double alpha = 0, beta = 0, value = 0;
};
[[nodiscard]] std::string svg_heatmap(const std::vector<HeatCell>& cells, double lo_mm, double hi_mm, int n, int size = 360);

}  // namespace hystlab::web::report
