#include "riner/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "riner/error.hpp"
#include "riner/io.hpp"

namespace riner {

namespace {

// 5x7 glyphs, one byte per row (low 5 bits, MSB left), for the characters plots need.
struct Glyph {
  char c;
  unsigned char rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {14, 17, 19, 21, 25, 17, 14}}, {'1', {4, 12, 4, 4, 4, 4, 14}},
    {'2', {14, 17, 1, 2, 4, 8, 31}},     {'3', {30, 1, 1, 14, 1, 1, 30}},
    {'4', {2, 6, 10, 18, 31, 2, 2}},     {'5', {31, 16, 30, 1, 1, 17, 14}},
    {'6', {6, 8, 16, 30, 17, 17, 14}},   {'7', {31, 1, 2, 4, 8, 8, 8}},
    {'8', {14, 17, 17, 14, 17, 17, 14}}, {'9', {14, 17, 17, 15, 1, 2, 12}},
    {'.', {0, 0, 0, 0, 0, 12, 12}},      {'-', {0, 0, 0, 31, 0, 0, 0}},
    {'+', {0, 4, 4, 31, 4, 4, 0}},       {'/', {1, 1, 2, 4, 8, 16, 16}},
    {'(', {2, 4, 8, 8, 8, 4, 2}},        {')', {8, 4, 2, 2, 2, 4, 8}},
    {':', {0, 12, 12, 0, 12, 12, 0}},    {'=', {0, 0, 31, 0, 31, 0, 0}},
    {'%', {24, 25, 2, 4, 8, 19, 3}},     {',', {0, 0, 0, 0, 12, 4, 8}},
    {'<', {2, 4, 8, 16, 8, 4, 2}},       {'>', {8, 4, 2, 1, 2, 4, 8}},
    {'_', {0, 0, 0, 0, 0, 0, 31}},       {'a', {0, 0, 14, 1, 15, 17, 15}},
    {'b', {16, 16, 30, 17, 17, 17, 30}}, {'c', {0, 0, 14, 16, 16, 17, 14}},
    {'d', {1, 1, 15, 17, 17, 17, 15}},   {'e', {0, 0, 14, 17, 31, 16, 14}},
    {'f', {6, 9, 8, 28, 8, 8, 8}},       {'g', {0, 15, 17, 17, 15, 1, 14}},
    {'h', {16, 16, 22, 25, 17, 17, 17}}, {'i', {4, 0, 12, 4, 4, 4, 14}},
    {'j', {2, 0, 6, 2, 2, 18, 12}},      {'k', {16, 16, 18, 20, 24, 20, 18}},
    {'l', {12, 4, 4, 4, 4, 4, 14}},      {'m', {0, 0, 26, 21, 21, 17, 17}},
    {'n', {0, 0, 22, 25, 17, 17, 17}},   {'o', {0, 0, 14, 17, 17, 17, 14}},
    {'p', {0, 0, 30, 17, 30, 16, 16}},   {'q', {0, 0, 13, 19, 15, 1, 1}},
    {'r', {0, 0, 22, 25, 16, 16, 16}},   {'s', {0, 0, 14, 16, 14, 1, 30}},
    {'t', {8, 8, 28, 8, 8, 9, 6}},       {'u', {0, 0, 17, 17, 17, 19, 13}},
    {'v', {0, 0, 17, 17, 17, 10, 4}},    {'w', {0, 0, 17, 17, 21, 21, 10}},
    {'x', {0, 0, 17, 10, 4, 10, 17}},    {'y', {0, 0, 17, 17, 15, 1, 14}},
    {'z', {0, 0, 31, 2, 4, 8, 31}},
};

class Canvas {
 public:
  Canvas(int w, int h) : w_(w), h_(h), rgb_(static_cast<std::size_t>(w) * h * 3, 255) {}

  void pixel(int x, int y, std::array<unsigned char, 3> c) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
    std::memcpy(&rgb_[(static_cast<std::size_t>(y) * w_ + x) * 3], c.data(), 3);
  }

  void line(double x0, double y0, double x1, double y1, std::array<unsigned char, 3> c,
            bool dashed = false) {
    const int steps = static_cast<int>(std::max(std::fabs(x1 - x0), std::fabs(y1 - y0))) + 1;
    for (int i = 0; i <= steps; ++i) {
      if (dashed && (i / 4) % 2) continue;
      const double t = static_cast<double>(i) / steps;
      const int x = static_cast<int>(std::lround(x0 + t * (x1 - x0)));
      const int y = static_cast<int>(std::lround(y0 + t * (y1 - y0)));
      pixel(x, y, c);
      pixel(x, y + 1, c);  // two pixels thick reads better
    }
  }

  // Text at (x, y) = top-left; upper-case letters are drawn in lower case.
  void text(int x, int y, const std::string& s, std::array<unsigned char, 3> c) {
    for (char ch : s) {
      if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
      for (const Glyph& g : kFont) {
        if (g.c != ch) continue;
        for (int row = 0; row < 7; ++row) {
          for (int col = 0; col < 5; ++col) {
            if (g.rows[row] & (16 >> col)) pixel(x + col, y + row, c);
          }
        }
      }
      x += 6;
    }
  }

  const std::vector<unsigned char>& rgb() const { return rgb_; }

 private:
  int w_;
  int h_;
  std::vector<unsigned char> rgb_;
};

std::string tick_label(double v, double step) {
  char buf[32];
  const int decimals =
      step >= 1.0 ? 0 : std::min(6, static_cast<int>(std::ceil(-std::log10(step))));
  // A tick a rounding error off 0 would print as "-0.0".
  if (std::fabs(v) < 1e-9 * step) v = 0.0;
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

double nice_step(double range, int target) {
  const double raw = range / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * magnitude >= raw) return m * magnitude;
  }
  return 10.0 * magnitude;
}

}  // namespace

namespace {

struct Bounds {
  double x_lo, x_hi, y_lo, y_hi;
};

// The axes' ranges: the finite data and the horizontal lines (or plot.y_min/y_max), y padded.
Bounds data_bounds(const LinePlot& plot) {
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  for (const PlotSeries& s : plot.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, s.y[i]);
      y_hi = std::max(y_hi, s.y[i]);
    }
  }
  for (const auto& [y, label] : plot.horizontal_lines) {
    y_lo = std::min(y_lo, y);
    y_hi = std::max(y_hi, y);
  }
  if (!std::isfinite(x_lo)) x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;
  if (plot.y_min != 0.0 || plot.y_max != 0.0) y_lo = plot.y_min, y_hi = plot.y_max;
  if (!(x_hi > x_lo)) x_hi = x_lo + 1.0;
  if (!(y_hi > y_lo)) y_hi = y_lo + 1.0;
  const double pad = 0.04 * (y_hi - y_lo);
  return {x_lo, x_hi, y_lo - pad, y_hi + pad};
}

}  // namespace

void write_plot_png(const std::filesystem::path& path, const LinePlot& plot) {
  if (plot.width < 200 || plot.height < 150) throw InputError("plot too small");
  const auto [x_lo, x_hi, y_lo, y_hi] = data_bounds(plot);

  Canvas canvas(plot.width, plot.height);
  const int left = 70, right = plot.width - 20, top = 30, bottom = plot.height - 45;
  auto px = [&](double x) { return left + (x - x_lo) / (x_hi - x_lo) * (right - left); };
  auto py = [&](double y) { return bottom - (y - y_lo) / (y_hi - y_lo) * (bottom - top); };
  const std::array<unsigned char, 3> black{0, 0, 0}, grey{200, 200, 200}, dark{90, 90, 90};

  const double y_step = nice_step(y_hi - y_lo, 6);
  for (double y = std::ceil(y_lo / y_step) * y_step; y <= y_hi; y += y_step) {
    canvas.line(left, py(y), right, py(y), grey);
    const std::string label = tick_label(y, y_step);
    canvas.text(left - 6 - 6 * static_cast<int>(label.size()), static_cast<int>(py(y)) - 3, label,
                black);
  }
  const double x_step = nice_step(x_hi - x_lo, 8);
  for (double x = std::ceil(x_lo / x_step) * x_step; x <= x_hi; x += x_step) {
    canvas.line(px(x), bottom, px(x), bottom + 4, black);
    const std::string label = tick_label(x, x_step);
    canvas.text(static_cast<int>(px(x)) - 3 * static_cast<int>(label.size()), bottom + 8, label,
                black);
  }
  canvas.line(left, top, left, bottom, black);
  canvas.line(left, bottom, right, bottom, black);
  for (const auto& [y, label] : plot.horizontal_lines) {
    canvas.line(left, py(y), right, py(y), dark, true);
    canvas.text(right - 6 * static_cast<int>(label.size()) - 2, static_cast<int>(py(y)) - 10, label,
                dark);
  }
  for (const PlotSeries& s : plot.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      const double y = std::clamp(s.y[i], y_lo, y_hi);
      if (s.points) {
        for (int dx = -2; dx <= 2; ++dx) {
          for (int dy = -2; dy <= 2; ++dy) {
            canvas.pixel(static_cast<int>(px(s.x[i])) + dx, static_cast<int>(py(y)) + dy, s.color);
          }
        }
      } else if (i > 0 && std::isfinite(s.y[i - 1])) {
        canvas.line(px(s.x[i - 1]), py(std::clamp(s.y[i - 1], y_lo, y_hi)), px(s.x[i]), py(y),
                    s.color);
      }
    }
  }
  canvas.text(left, 10, plot.title, black);
  canvas.text((left + right) / 2 - 3 * static_cast<int>(plot.x_label.size()), plot.height - 16,
              plot.x_label, black);
  canvas.text(6, 10, plot.y_label, black);
  // Legend, top right.
  int legend_y = top + 6;
  for (const PlotSeries& s : plot.series) {
    if (s.label.empty()) continue;
    const int x = right - 10 - 6 * static_cast<int>(s.label.size()) - 20;
    canvas.line(x, legend_y + 3, x + 14, legend_y + 3, s.color);
    canvas.text(x + 18, legend_y, s.label, black);
    legend_y += 12;
  }
  write_png_rgb(path, canvas.rgb(), static_cast<std::size_t>(plot.height),
                static_cast<std::size_t>(plot.width));
}

}  // namespace riner
