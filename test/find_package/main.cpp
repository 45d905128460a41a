// The library example of docs/guide/library.md, built against the installed package by CI:
// simulate a small ring scan, reconstruct it with FBP and with Riner, save the image and the
// detector response.
#include <cmath>
#include <cstdio>

#include "riner/riner.hpp"  // the whole library; the single headers work too

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  const std::filesystem::path out = argv[1];
  try {
    // A scan: here simulated; from files it is riner::load_scan("sino.npy", "geometry.json").
    riner::Geometry g = riner::Geometry::from_json(R"({"type": "parallel2d",
        "detector": {"count": 64, "pitch_mm": 1.0},
        "angles": {"count": 90, "start_rad": 0.0, "range_rad": 3.141592653589793},
        "volume": {"shape": [48, 48], "voxel_mm": 1.0}})");
    const riner::Phantom phantom = riner::shepp_logan(g);
    riner::RingModel rings;  // 75% of elements off by up to 25%, two dead, 1e7 photons
    const riner::Array alpha_true = riner::draw_responses(g, rings);
    riner::Scan scan{
        riner::corrupt_measurement(riner::exact_projections(phantom, g), alpha_true, rings), g, 0};

    riner::Device device = riner::Device::open();  // or Device::from_handles(context, queue)
    riner::FbpOptions fbp_options;
    fbp_options.device = device;
    const riner::Array fbp = riner::fbp(scan, fbp_options);

    riner::RinerConfig config;  // the defaults; or config.update_from_json(text)
    config.training.steps = 300;
    riner::Reconstructor reconstructor(scan, config, device);
    reconstructor.run(
        [](const riner::TrainingProgress& p) {
          std::printf("step %d/%d loss %.4f\n", p.step, p.total, p.loss);
          return true;  // false stops early
        },
        100);
    const riner::Array image = reconstructor.image();  // mu in 1/mm on the grid
    riner::write_array(out / "image.nii", image);
    riner::write_array(out / "alpha.npy", reconstructor.alpha());
    riner::write_array(out / "beta.npy", reconstructor.beta());

    const riner::Array truth = riner::rasterize(phantom, g, 4);
    std::printf("riner %s on %s: FBP %.2f dB, Riner %.2f dB\n", RINER_VERSION,
                device.info().name.c_str(), riner::psnr(fbp, truth), riner::psnr(image, truth));
    for (float v : image.data) {
      if (!std::isfinite(v)) return 1;
    }
    return 0;
  } catch (const riner::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
