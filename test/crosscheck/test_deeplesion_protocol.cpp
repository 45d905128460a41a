// The paper protocol on the real DeepLesion slices (when ../shared is present): FBP of the
// clean simulation must reach 30 dB; FBP of the ring-corrupted one sits near the paper's
// 13.81 dB FBP row; the classical filters reach the paper's rows for them.
#include <doctest/doctest.h>

#include <string>

#include "riner/destripe.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/simulate.hpp"
#include "support/fixture.hpp"

namespace {

struct PaperSlice {
  riner::Array truth;  // mm^-1
  riner::SimulatedScan sim;
};

// Slice `index` of the shared DeepLesion slices through the paper's simulation (seed: index).
PaperSlice paper_slice(int index, const riner::Projector& projector) {
  PaperSlice out;
  out.truth = riner::test::deeplesion_slice_mm(index);
  riner::RingModel model;
  model.seed = static_cast<std::uint64_t>(index);
  out.sim = riner::simulate(out.truth, projector, model);
  return out;
}

}  // namespace

TEST_SUITE("deeplesion_protocol") {
  TEST_CASE("FBP on fan2d-paper simulations of the ten slices") {
    if (riner::test::shared_data("deeplesion/slice_0.nii").empty()) {
      MESSAGE("../shared/data/deeplesion not found: skipped");
      return;
    }
    const riner::Geometry g = riner::preset_geometry("fan2d-paper");
    const riner::Projector projector(g, riner::Engine::kOpenCL, riner::test::device());
    riner::FbpOptions options;
    options.device = riner::test::device();
    double clean_psnr = 0.0, ring_psnr = 0.0, clean_ssim = 0.0, ring_ssim = 0.0;
    for (int slice = 0; slice < 10; ++slice) {
      CAPTURE(slice);
      const auto [truth, sim] = paper_slice(slice, projector);
      const riner::ImageMetrics clean =
          riner::compare_images(riner::fbp(riner::Scan{sim.clean, g, 0}, options), truth);
      const riner::ImageMetrics rings = riner::compare_images(riner::fbp(sim.scan, options), truth);
      CHECK(clean.psnr >= 30.0);
      clean_psnr += clean.psnr / 10;
      clean_ssim += clean.ssim / 10;
      ring_psnr += rings.psnr / 10;
      ring_ssim += rings.ssim / 10;
    }
    MESSAGE("clean FBP: mean PSNR " << clean_psnr << " dB, SSIM " << clean_ssim);
    MESSAGE("ring-corrupted FBP: mean PSNR " << ring_psnr << " dB, SSIM " << ring_ssim);
    CHECK(ring_psnr < 25.0);  // rings must be there
    CHECK(ring_psnr > 8.0);   // and not absurd
  }

  TEST_CASE("the classical combination and normalisation reach the paper's Super and Norm") {
    // The paper's Table 1: Norm 24.37 dB, Super (Vo's combination) 29.11, on these slices.
    // The combination's sorting step at the literature's window of 21 reads 29.0 here: it
    // flattens detail narrower than 10 columns that its large step has already freed of
    // offsets, so riner's combination sorts with 5 (30.3).
    if (riner::test::shared_data("deeplesion/slice_0.nii").empty()) {
      MESSAGE("../shared/data/deeplesion not found: skipped");
      return;
    }
    const riner::Geometry g = riner::preset_geometry("fan2d-paper");
    const riner::Projector projector(g, riner::Engine::kOpenCL, riner::test::device());
    riner::FbpOptions fbp_options;
    fbp_options.device = riner::test::device();
    const auto filtered_psnr = [&](const PaperSlice& slice, riner::DestripeMethod method,
                                   std::size_t size) {
      riner::DestripeOptions options;
      options.method = method;
      options.size = size;
      options.device = riner::test::device();
      const riner::Array clean = riner::destripe(slice.sim.scan.measurement, g, options);
      return riner::compare_images(riner::fbp(riner::Scan{clean, g, 0}, fbp_options), slice.truth)
          .psnr;
    };
    double all = 0.0, all_21 = 0.0, normalise = 0.0;
    for (int index = 0; index < 10; ++index) {
      const PaperSlice slice = paper_slice(index, projector);
      all += filtered_psnr(slice, riner::DestripeMethod::kAll, 0) / 10;
      all_21 += filtered_psnr(slice, riner::DestripeMethod::kAll, 21) / 10;
      normalise += filtered_psnr(slice, riner::DestripeMethod::kNormalise, 0) / 10;
    }
    MESSAGE("mean PSNR: all " << all << " dB (window 21: " << all_21 << "), normalise "
                               << normalise);
    CHECK(all >= 29.11);
    CHECK(all > all_21 + 0.5);
    CHECK(normalise >= 24.37);
  }
}
