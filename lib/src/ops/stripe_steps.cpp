#include "ops/stripe_steps.hpp"

#include "riner/error.hpp"

namespace riner::ops {

namespace {

cl_uint u32(std::size_t n) { return static_cast<cl_uint>(n); }

template <typename T>
void need(const cl::Buffer<T>& buffer, std::size_t count, const char* step) {
  if (buffer.size() < count) throw Error(std::string("stripe step ") + step + ": a buffer is too small");
}

// The last index a layout of lines of n values reaches, plus one.
std::size_t extent(const LineLayout& lines, std::size_t n) {
  return lines.lines == 0 ? 0 : lines.first + (lines.lines - 1) * lines.line_step + (n - 1) * lines.stride + 1;
}

}  // namespace

const std::vector<std::string>& stripe_program_sources() {
  static const std::vector<std::string> sources{"common", "stripe_columns", "wavelet",
                                                "stripe_sorting"};
  return sources;
}

StripeStepsOp::StripeStepsOp(cl::Context& context)
    : context_(context),
      program_(context.program(stripe_program_sources())),
      column_means_(*program_, "column_means"),
      subtract_offsets_(*program_, "subtract_column_offsets"),
      deviations_(*program_, "view_deviations"),
      fluctuation_(*program_, "column_fluctuation"),
      interpolate_(*program_, "interpolate_columns"),
      replace_masked_(*program_, "replace_masked_columns"),
      add_difference_(*program_, "add_difference"),
      coefficients_(*program_, "polynomial_coefficients"),
      values_(*program_, "polynomial_values"),
      reflect_pad_(*program_, "reflect_pad_views"),
      periodic_(*program_, "periodic_extension"),
      copy_block_(*program_, "copy_block"),
      analyse_(*program_, "wavelet_analyse"),
      synthesise_(*program_, "wavelet_synthesise") {}

void StripeStepsOp::column_means(std::size_t views, std::size_t columns, std::size_t from,
                                 std::size_t to, const cl::Buffer<float>& in,
                                 cl::Buffer<float>& means) {
  need(in, views * columns, "column_means");
  need(means, columns, "column_means");
  if (from > to || to > views) throw Error("stripe step column_means: views out of range");
  column_means_.set_args(u32(views), u32(columns), u32(from), u32(to), in, means);
  context_.launch(column_means_, columns);
}

void StripeStepsOp::subtract_column_offsets(std::size_t columns, const cl::Buffer<float>& offsets,
                                            cl::Buffer<float>& values) {
  need(offsets, columns, "subtract_column_offsets");
  const std::size_t n = values.size() / columns * columns;
  subtract_offsets_.set_args(u32(n), u32(columns), offsets, values);
  context_.launch(subtract_offsets_, n);
}

void StripeStepsOp::view_deviations(std::size_t views, std::size_t columns, std::size_t half,
                                    const cl::Buffer<float>& in, cl::Buffer<float>& deviation) {
  need(in, views * columns, "view_deviations");
  need(deviation, views * columns, "view_deviations");
  deviations_.set_args(u32(views), u32(columns), static_cast<cl_int>(half), in, deviation);
  context_.launch(deviations_, views * columns);
}

void StripeStepsOp::column_fluctuation(std::size_t views, std::size_t columns, std::size_t near,
                                       std::size_t far, std::size_t span,
                                       const cl::Buffer<float>& deviation, cl::Buffer<float>& total,
                                       cl::Buffer<float>& own) {
  need(deviation, views * columns, "column_fluctuation");
  need(total, columns, "column_fluctuation");
  need(own, columns, "column_fluctuation");
  if (span > kFluctuationSpanMax || near > far) {
    throw Error("stripe step column_fluctuation: span or neighbours out of range");
  }
  fluctuation_.set_args(u32(views), u32(columns), static_cast<cl_int>(near),
                        static_cast<cl_int>(far), static_cast<cl_int>(span), deviation, total, own);
  context_.launch(fluctuation_, columns);
}

void StripeStepsOp::interpolate_columns(std::size_t columns, const cl::Buffer<cl_uint>& left,
                                        const cl::Buffer<cl_uint>& right,
                                        const cl::Buffer<float>& weight,
                                        cl::Buffer<float>& values) {
  need(left, columns, "interpolate_columns");
  need(right, columns, "interpolate_columns");
  need(weight, columns, "interpolate_columns");
  const std::size_t n = values.size() / columns * columns;
  interpolate_.set_args(u32(n), u32(columns), left, right, weight, values);
  context_.launch(interpolate_, n);
}

void StripeStepsOp::replace_masked_columns(std::size_t columns, const cl::Buffer<cl_uchar>& mask,
                                           const cl::Buffer<float>& source,
                                           cl::Buffer<float>& values) {
  need(mask, columns, "replace_masked_columns");
  const std::size_t n = values.size() / columns * columns;
  need(source, n, "replace_masked_columns");
  replace_masked_.set_args(u32(n), u32(columns), mask, source, values);
  context_.launch(replace_masked_, n);
}

void StripeStepsOp::add_difference(std::size_t views, std::size_t columns,
                                   const cl::Buffer<float>& plus, std::size_t plus_first,
                                   std::size_t plus_stride, const cl::Buffer<float>& minus,
                                   std::size_t minus_first, std::size_t minus_stride,
                                   cl::Buffer<float>& values) {
  need(values, views * columns, "add_difference");
  need(plus, plus_first + (views - 1) * plus_stride + columns, "add_difference");
  need(minus, minus_first + (views - 1) * minus_stride + columns, "add_difference");
  add_difference_.set_args(u32(views), u32(columns), plus, u32(plus_first), u32(plus_stride), minus,
                           u32(minus_first), u32(minus_stride), values);
  context_.launch(add_difference_, views * columns);
}

void StripeStepsOp::polynomial_trend(std::size_t views, std::size_t columns, std::size_t terms,
                                     const cl::Buffer<float>& basis, const cl::Buffer<float>& in,
                                     cl::Buffer<float>& coefficients, cl::Buffer<float>& trend) {
  need(basis, views * terms, "polynomial_trend");
  need(in, views * columns, "polynomial_trend");
  need(coefficients, terms * columns, "polynomial_trend");
  need(trend, views * columns, "polynomial_trend");
  coefficients_.set_args(u32(views), u32(columns), u32(terms), basis, in, coefficients);
  context_.launch(coefficients_, terms * columns);
  values_.set_args(u32(views), u32(columns), u32(terms), basis, coefficients, trend);
  context_.launch(values_, views * columns);
}

void StripeStepsOp::reflect_pad_views(std::size_t views, std::size_t columns, std::size_t pad,
                                      std::size_t out_views, const cl::Buffer<float>& in,
                                      cl::Buffer<float>& out) {
  need(in, views * columns, "reflect_pad_views");
  need(out, out_views * columns, "reflect_pad_views");
  if (pad >= views || out_views < views + pad) {
    throw Error("stripe step reflect_pad_views: the pad is not shorter than the views");
  }
  reflect_pad_.set_args(u32(views), u32(columns), u32(pad), u32(out_views), in, out);
  context_.launch(reflect_pad_, out_views * columns);
}

void StripeStepsOp::periodic_extension(std::size_t views, std::size_t columns,
                                       std::size_t out_views, std::size_t out_columns,
                                       const cl::Buffer<float>& in, cl::Buffer<float>& out) {
  need(in, views * columns, "periodic_extension");
  need(out, out_views * out_columns, "periodic_extension");
  if (out_views < views || out_columns < columns) {
    throw Error("stripe step periodic_extension: the extension is smaller than the sinogram");
  }
  periodic_.set_args(u32(views), u32(columns), u32(out_views), u32(out_columns), in, out);
  context_.launch(periodic_, out_views * out_columns);
}

void StripeStepsOp::copy_block(std::size_t rows, std::size_t columns, const cl::Buffer<float>& src,
                               std::size_t src_first, std::size_t src_stride,
                               cl::Buffer<float>& dst, std::size_t dst_first,
                               std::size_t dst_stride) {
  if (rows == 0 || columns == 0) return;
  need(src, src_first + (rows - 1) * src_stride + columns, "copy_block");
  need(dst, dst_first + (rows - 1) * dst_stride + columns, "copy_block");
  copy_block_.set_args(u32(rows), u32(columns), src, u32(src_first), u32(src_stride), dst,
                       u32(dst_first), u32(dst_stride));
  context_.launch(copy_block_, rows * columns);
}

void StripeStepsOp::wavelet_analyse(const LineLayout& lines, std::size_t n,
                                    const cl::Buffer<float>& h, const cl::Buffer<float>& g,
                                    const cl::Buffer<float>& in, cl::Buffer<float>& out) {
  if (n % 2 != 0 || h.size() != g.size()) throw Error("stripe step wavelet_analyse: an odd line");
  need(in, extent(lines, n), "wavelet_analyse");
  need(out, extent(lines, n), "wavelet_analyse");
  const std::size_t n_out = lines.lines * n / 2;
  analyse_.set_args(u32(n_out), u32(n), u32(lines.first), u32(lines.line_step), u32(lines.stride),
                    u32(h.size()), h, g, in, out);
  context_.launch(analyse_, n_out);
}

void StripeStepsOp::wavelet_synthesise(const LineLayout& lines, std::size_t n,
                                       const cl::Buffer<float>& h, const cl::Buffer<float>& g,
                                       const cl::Buffer<float>& in, cl::Buffer<float>& out) {
  if (n % 2 != 0 || h.size() != g.size()) throw Error("stripe step wavelet_synthesise: an odd line");
  need(in, extent(lines, n), "wavelet_synthesise");
  need(out, extent(lines, n), "wavelet_synthesise");
  const std::size_t n_out = lines.lines * n;
  synthesise_.set_args(u32(n_out), u32(n), u32(lines.first), u32(lines.line_step),
                       u32(lines.stride), u32(h.size()), h, g, in, out);
  context_.launch(synthesise_, n_out);
}

}  // namespace riner::ops
