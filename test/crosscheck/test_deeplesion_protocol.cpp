// The paper protocol on the real DeepLesion slices (when ../shared is present): FBP of the
// clean simulation must reach 30 dB; FBP of the ring-corrupted one sits near the paper's
// 13.81 dB FBP row.
#include <doctest/doctest.h>

#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/simulate.hpp"
#include "support/fixture.hpp"

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
      riner::Array truth =
          riner::read_array(
              riner::test::shared_data("deeplesion/slice_" + std::to_string(slice) + ".nii"))
              .array;
      for (float& v : truth.data) v *= 0.1f;  // cm^-1 -> mm^-1 (METHOD.md §4)
      riner::RingModel model;
      model.seed = static_cast<std::uint64_t>(slice);
      const riner::SimulatedScan sim = riner::simulate(truth, projector, model);
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
}
