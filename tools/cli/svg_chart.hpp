#pragma once
// A minimal line chart written as standalone SVG, so the learning-curve plots
// open in any browser without a plotting package.

#include <string>
#include <vector>

namespace cdcr::cli {

struct ChartSeries {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
  std::string colour;
  bool dashed = false;  // reference lines (initial error, noise floor)
  bool markers = true;
};

struct Chart {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<ChartSeries> series;
};

std::string render_svg(const Chart& chart);

}  // namespace cdcr::cli
