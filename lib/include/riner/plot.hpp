// Small line plots rendered straight to PNG (no plotting dependency): detector responses
// against element index, PSNR against time. A built-in 5x7 pixel font labels the axes.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace riner {

struct PlotSeries {
  std::string label;
  std::vector<double> x;
  std::vector<double> y;
  std::array<unsigned char, 3> color{31, 119, 180};
  bool points = false;  // markers instead of a line
};

struct LinePlot {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<PlotSeries> series;
  std::vector<std::pair<double, std::string>> horizontal_lines;  // y value, label (dashed grey)
  double y_min = 0.0;                                            // both 0: from the data
  double y_max = 0.0;
  int width = 900;
  int height = 420;
};

// Renders the plot to an RGB PNG (written atomically, like every output).
void write_plot_png(const std::filesystem::path& path, const LinePlot& plot);

}  // namespace riner
