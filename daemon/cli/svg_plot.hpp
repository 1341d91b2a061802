#pragma once
// A small static SVG line plot for reports (not a chart engine: axes, ticks, lines, legend).
#include <string>
#include <vector>

namespace hystlab::cli {

struct PlotSeries {
  std::string name;
  std::string color;  // CSS colour
  std::vector<double> x, y;
  bool dashed = false;
  bool markers = false;  // points instead of a line
};

[[nodiscard]] std::string svg_plot(const std::string& title, const std::string& x_label, const std::string& y_label, const std::vector<PlotSeries>& series);

}  // namespace hystlab::cli
