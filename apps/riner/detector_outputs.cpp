#include "detector_outputs.hpp"

#include <algorithm>
#include <vector>

#include "riner/io.hpp"
#include "riner/plot.hpp"
#include "riner/reconstructor.hpp"

namespace riner::app {

void write_detector_outputs(const std::filesystem::path& dir, Array alpha, Array beta,
                            const std::vector<std::size_t>& dead, const Array& alpha_by_view) {
  mark_dead_elements(dead, alpha, beta);
  write_array(dir / "alpha.npy", alpha);
  write_array(dir / "beta.npy", beta);
  if (alpha_by_view.size() > 0) write_array(dir / "alpha_by_view.npy", alpha_by_view);
  if (alpha.rank() == 1) {
    LinePlot plot;
    plot.title = "estimated detector response alpha (blue) and mask beta (orange)";
    plot.x_label = "element";
    plot.y_label = "";
    PlotSeries a{"alpha", {}, {}, {31, 119, 180}, false};
    PlotSeries b{"beta", {}, {}, {255, 127, 14}, false};
    for (std::size_t e = 0; e < alpha.size(); ++e) {
      a.x.push_back(static_cast<double>(e));
      a.y.push_back(std::min(alpha.data[e], 3.0f));  // a wild alpha must not flatten the plot
      b.x.push_back(static_cast<double>(e));
      b.y.push_back(beta.data[e]);
    }
    // What the tool decided: a red mark at 0 for every element it takes for dead, whatever its
    // beta (an element with no finite reading is dead with beta wherever training left it).
    PlotSeries d{"dead", {}, {}, {214, 39, 40}, true};
    for (std::size_t e : dead) {
      d.x.push_back(static_cast<double>(e));
      d.y.push_back(0.0);
    }
    plot.title = "detector response alpha (blue), mask beta (orange), " +
                 std::to_string(dead.size()) + " dead (red, why: summary.json)";
    plot.series = {a, b, d};
    plot.horizontal_lines = {{Reconstructor::kDeadBelowBeta, "dead below 0.5"}};
    write_plot_png(dir / "detector.png", plot);
  } else {
    // 3D: the two maps side by side, each windowed on its own. A detector of few rows (a stack
    // of two slices: a 1284 x 2 strip) has each row drawn kRowsAtLeast / rows pixels tall.
    constexpr std::size_t kRowsAtLeast = 64;
    const std::size_t rows = alpha.shape[0];
    const std::size_t cols = alpha.shape[1];
    const std::size_t tall = std::max<std::size_t>(1, kRowsAtLeast / rows);
    Array both({rows * tall, 2 * cols + 4}, 0.0f);
    const Window wa = percentile_window(alpha);
    std::vector<char> is_dead(rows * cols, 0);
    for (std::size_t e : dead) is_dead[e] = 1;
    for (std::size_t r = 0; r < rows * tall; ++r) {
      for (std::size_t c = 0; c < cols; ++c) {
        const std::size_t e = (r / tall) * cols + c;
        both(r, c) = (alpha.data[e] - wa.lo) / (wa.hi - wa.lo);
        both(r, cols + 4 + c) = is_dead[e] ? 0.0f : beta.data[e];
      }
    }
    write_png(dir / "detector.png", both, Window{0.0f, 1.0f});
  }
}

}  // namespace riner::app
