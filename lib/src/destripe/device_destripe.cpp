#include "destripe/device_destripe.hpp"

#include <algorithm>
#include <cmath>

#include "destripe/wavelets.hpp"
#include "riner/error.hpp"

namespace riner::stripes {

namespace {

bool sorts(DestripeMethod method) {
  return method == DestripeMethod::kSorting || method == DestripeMethod::kFiltering ||
         method == DestripeMethod::kLarge || method == DestripeMethod::kAll;
}

std::vector<float> to_float(const std::vector<double>& v) { return {v.begin(), v.end()}; }

}  // namespace

bool DeviceDestripe::supported(const cl::Context& context, DestripeMethod method,
                               std::size_t views, const StripeSettings& settings) {
  return !sorts(method) || (ops::StripeSortingOp::supported(context, views, settings.size) &&
                            ops::StripeSortingOp::supported(context, views, settings.large_size));
}

DeviceDestripe::DeviceDestripe(cl::Context& context, DestripeMethod method,
                               const StripeSettings& settings, std::size_t views,
                               std::size_t columns)
    : context_(context),
      method_(method),
      settings_(settings),
      views_(views),
      columns_(columns),
      steps_(context),
      values_(context, views * columns),
      work_(context, views * columns),
      column_a_(context, columns),
      column_b_(context, columns) {
  if (sorts(method)) sorting_ = std::make_unique<ops::StripeSortingOp>(context, views, columns);
  if (method == DestripeMethod::kFiltering) {
    pad_ = filtering_pad(views);
    const PaddedLine line = filtering_line(views);
    wide_views_ = line.length;
    const std::size_t n = wide_views_;
    padded_ = cl::Buffer<float>(context, n * columns);
    padded2_ = cl::Buffer<float>(context, n * columns);
    work2_ = cl::Buffer<float>(context, views * columns);
    const double sigma = settings.sigma * line.bins_scale;
    filter_ = std::make_unique<ops::LineFilterOp>(
        context, n, ops::circular_filter_taps(line_gains(n, [&](double k) { return low_pass_gain(k, sigma); })));
  } else if (method == DestripeMethod::kFitting) {
    const std::vector<double> basis = polynomial_basis(views, settings.fit_order);
    terms_ = basis.size() / views;
    basis_ = cl::Buffer<float>(context, std::span<const float>(to_float(basis)));
    coefficients_ = cl::Buffer<float>(context, terms_ * columns);
    const PaddedLine line = fitting_line(columns);
    wide_columns_ = line.length;
    padded_ = cl::Buffer<float>(context, views * wide_columns_);
    padded2_ = cl::Buffer<float>(context, views * wide_columns_);
    const double sigma = settings.sigma * line.bins_scale;
    filter_ = std::make_unique<ops::LineFilterOp>(
        context, wide_columns_,
        ops::circular_filter_taps(line_gains(wide_columns_, [&](double k) { return low_pass_gain(k, sigma); })));
  } else if (method == DestripeMethod::kWavelet) {
    const PaddedLine along_views = wavelet_line(views, settings.levels);
    wide_views_ = along_views.length;
    wide_columns_ = wavelet_line(columns, settings.levels).length;
    padded_ = cl::Buffer<float>(context, wide_views_ * wide_columns_);
    padded2_ = cl::Buffer<float>(context, wide_views_ * wide_columns_);
    const std::vector<double> h = daubechies_filter(settings.wavelet_order);
    low_pass_ = cl::Buffer<float>(context, std::span<const float>(to_float(h)));
    high_pass_ = cl::Buffer<float>(context, std::span<const float>(to_float(wavelet_high_pass(h))));
    const double sigma = settings.sigma * along_views.bins_scale;  // the band's lines run along the views
    for (int l = 0; l < settings.levels; ++l) {
      const std::size_t band_rows = (wide_views_ >> l) / 2;
      band_filters_.push_back(std::make_unique<ops::LineFilterOp>(
          context, band_rows,
          ops::circular_filter_taps(line_gains(band_rows, [&](double k) { return high_pass_gain(k, sigma); }))));
    }
  }
}

void DeviceDestripe::run(std::vector<float>& values, std::vector<bool>& dead,
                         std::vector<bool>& large) {
  if (values.size() != views_ * columns_) throw Error("device destripe: size mismatch");
  values_.write(std::span<const float>(values));
  switch (method_) {
    case DestripeMethod::kNormalise: normalise(); break;
    case DestripeMethod::kSorting:
      sorting_->apply(values_, values_, settings_.size, settings_.rank_window);
      break;
    case DestripeMethod::kFiltering: filtering(); break;
    case DestripeMethod::kFitting: fitting(); break;
    case DestripeMethod::kWavelet: wavelet(); break;
    case DestripeMethod::kLarge: large = large_stripes(); break;
    case DestripeMethod::kDead: dead = dead_stripes(); break;
    case DestripeMethod::kAll:
      dead = dead_stripes();
      large = large_stripes();
      sorting_->apply(values_, values_, settings_.size, settings_.rank_window);
      break;
  }
  values_.read(std::span<float>(values));
}

std::vector<double> DeviceDestripe::read_columns(const cl::Buffer<float>& buffer) {
  const std::vector<float> values = buffer.read();
  // The decisions sort these: a NaN would break the ordering (repair_non_finite's bound on the
  // readings keeps the sums finite).
  for (std::size_t c = 0; c < columns_; ++c) {
    if (!std::isfinite(values[c])) throw Error("device destripe: a column's summary is not finite");
  }
  return {values.begin(), values.begin() + static_cast<long>(columns_)};
}

void DeviceDestripe::write_columns(cl::Buffer<float>& buffer, const std::vector<double>& values) {
  buffer.write(std::span<const float>(to_float(values)));
}

void DeviceDestripe::normalise() {
  steps_.column_means(views_, columns_, 0, views_, values_, column_a_);
  write_columns(column_b_, normalise_offsets(read_columns(column_a_), settings_.size));
  steps_.subtract_column_offsets(columns_, column_b_, values_);
}

void DeviceDestripe::filtering() {
  steps_.reflect_pad_views(views_, columns_, pad_, wide_views_, values_, padded_);
  filter_->run(padded_, padded2_, ops::LineLayout{columns_, 0, 1, columns_});
  steps_.copy_block(views_, columns_, padded2_, pad_ * columns_, columns_, work_, 0, columns_);
  sorting_->apply(work_, work2_, settings_.size, settings_.rank_window);
  steps_.add_difference(views_, columns_, work2_, 0, columns_, work_, 0, columns_, values_);
}

void DeviceDestripe::fitting() {
  steps_.polynomial_trend(views_, columns_, terms_, basis_, values_, coefficients_, work_);
  steps_.periodic_extension(views_, columns_, views_, wide_columns_, work_, padded_);
  filter_->run(padded_, padded2_, ops::LineLayout{views_, 0, wide_columns_, 1});
  steps_.add_difference(views_, columns_, padded2_, 0, wide_columns_, work_, 0, columns_, values_);
}

void DeviceDestripe::wavelet() {
  const std::size_t width = wide_columns_;
  steps_.periodic_extension(views_, columns_, wide_views_, width, values_, padded_);
  const int levels = settings_.levels;
  for (int l = 0; l < levels; ++l) {
    const std::size_t rows_l = wide_views_ >> l, columns_l = width >> l;
    steps_.wavelet_analyse(ops::LineLayout{rows_l, 0, width, 1}, columns_l, low_pass_, high_pass_,
                           padded_, padded2_);
    steps_.wavelet_analyse(ops::LineLayout{columns_l, 0, 1, width}, rows_l, low_pass_, high_pass_,
                           padded2_, padded_);
    // The band of details across columns, high-passed along the views.
    const std::size_t band_rows = rows_l / 2, first = columns_l / 2, lines = columns_l - first;
    band_filters_[static_cast<std::size_t>(l)]->run(padded_, padded2_,
                                                     ops::LineLayout{lines, first, 1, width});
    steps_.copy_block(band_rows, lines, padded2_, first, width, padded_, first, width);
  }
  for (int l = levels - 1; l >= 0; --l) {
    const std::size_t rows_l = wide_views_ >> l, columns_l = width >> l;
    steps_.wavelet_synthesise(ops::LineLayout{columns_l, 0, 1, width}, rows_l, low_pass_,
                              high_pass_, padded_, padded2_);
    steps_.wavelet_synthesise(ops::LineLayout{rows_l, 0, width, 1}, columns_l, low_pass_,
                              high_pass_, padded2_, padded_);
  }
  steps_.copy_block(views_, columns_, padded_, 0, width, values_, 0, columns_);
}

std::vector<bool> DeviceDestripe::large_stripes() {
  const std::size_t drop = large_stripe_drop(views_, settings_.drop_ratio);
  sorting_->sort(values_);
  sorting_->median(settings_.large_size);
  steps_.column_means(views_, columns_, drop, views_ - drop, sorting_->sorted(), column_a_);
  steps_.column_means(views_, columns_, drop, views_ - drop, sorting_->filtered(), column_b_);
  const std::vector<double> level = read_columns(column_a_), smooth_level = read_columns(column_b_);
  std::vector<std::vector<double>> quarters;
  for (int q = 0; q < 4; ++q) {
    const auto [first, last] = rank_quarter(views_, drop, q);
    steps_.column_means(views_, columns_, first, last, sorting_->sorted(), column_a_);
    steps_.column_means(views_, columns_, first, last, sorting_->filtered(), column_b_);
    const std::vector<double> a = read_columns(column_a_), b = read_columns(column_b_);
    quarters.emplace_back(a.size());
    for (std::size_t c = 0; c < a.size(); ++c) quarters.back()[c] = a[c] - b[c];
  }
  const LargeStripes found =
      large_stripe_offsets(level, smooth_level, settings_.snr, quarters, settings_.large_size);
  write_columns(column_a_, found.offset);
  steps_.subtract_column_offsets(columns_, column_a_, values_);
  if (std::find(found.mask.begin(), found.mask.end(), true) == found.mask.end()) return found.mask;
  // The smoothed sorted values back in the views of their ranks (a column less its offset
  // ranks its views as before).
  sorting_->unsort(work_);
  std::vector<cl_uchar> mask(columns_);
  for (std::size_t c = 0; c < columns_; ++c) mask[c] = found.mask[c] ? 1 : 0;
  const cl::Buffer<cl_uchar> mask_buffer(context_, std::span<const cl_uchar>(mask));
  steps_.replace_masked_columns(columns_, mask_buffer, work_, values_);
  return found.mask;
}

static_assert(kNeighbourSpan <= ops::kFluctuationSpanMax, "column_fluctuation's ring is too short");

std::vector<bool> DeviceDestripe::dead_stripes() {
  steps_.view_deviations(views_, columns_, kFluctuationWindow / 2, values_, work_);
  steps_.column_fluctuation(views_, columns_, kNeighbourNear, kNeighbourFar, kNeighbourSpan, work_,
                            column_a_, column_b_);
  const std::vector<bool> mask =
      dead_columns(ColumnFluctuation{read_columns(column_a_), read_columns(column_b_)},
                   settings_.large_size, settings_.snr);
  if (std::find(mask.begin(), mask.end(), true) == mask.end()) return mask;
  const ColumnInterpolation plan = interpolation_plan(mask);
  const std::vector<cl_uint> left(plan.left.begin(), plan.left.end());
  const std::vector<cl_uint> right(plan.right.begin(), plan.right.end());
  const cl::Buffer<cl_uint> left_buffer(context_, std::span<const cl_uint>(left));
  const cl::Buffer<cl_uint> right_buffer(context_, std::span<const cl_uint>(right));
  const cl::Buffer<float> weight_buffer(context_, std::span<const float>(to_float(plan.weight)));
  steps_.interpolate_columns(columns_, left_buffer, right_buffer, weight_buffer, values_);
  return mask;
}

}  // namespace riner::stripes
