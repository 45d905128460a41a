// The no-reference quality measures (riner/quality.hpp): noise, specks and the centre's broad
// deviation from the FBP, on images with known noise, spikes and discs.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "riner/error.hpp"
#include "riner/quality.hpp"

namespace {

// A smooth ramp plus white noise of the given sigma.
riner::Array noisy(std::size_t n, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  riner::Array a({n, n});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < n; ++k)
      a(i, k) = static_cast<float>(0.02 + 1e-5 * static_cast<double>(i + k) + g(rng));
  return a;
}

// A square sample of mu in air, plus white noise, on an n x n grid; `cut` zeroes its top-left
// corner triangle of that many pixels per side.
riner::Array square_sample(std::size_t n, double mu, double sigma, unsigned seed, std::size_t cut) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  riner::Array a({n, n});
  const std::size_t lo = n / 4, hi = 3 * n / 4;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < n; ++k) {
      const bool inside = i >= lo && i < hi && k >= lo && k < hi && (i - lo) + (k - lo) >= cut;
      a(i, k) = static_cast<float>((inside ? mu : 0.0) + g(rng));
    }
  }
  return a;
}

// A disc of radius 40 px and the given contrast, its edge a partial-volume ramp one pixel wide
// whose position wavers by up to +-waver px from pixel to pixel (a real edge's roughness), plus
// white noise, on a 128 x 128 grid.
riner::Array wavering_disc(double contrast, double waver, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::uniform_real_distribution<double> u(-waver, waver);
  const std::size_t n = 128;
  const double c = 0.5 * (n - 1.0);
  riner::Array a({n, n});
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < n; ++k) {
      const double inside = std::clamp(40.5 - std::hypot(i - c, k - c) + u(rng), 0.0, 1.0);
      a(i, k) = static_cast<float>(contrast * inside + g(rng));
    }
  }
  return a;
}

}  // namespace

TEST_SUITE("quality: lost object") {
  TEST_CASE(
      "object the FBP sees and the image sets to air is counted; noise and agreement are not") {
    const std::size_t n = 200;
    // Per pixel the sample is 2 noise sigmas, blurred by the measure 14.
    const riner::Array fbp = square_sample(n, 2e-3, 1e-3, 5, 0);
    // The same sample, clean: nothing lost.
    CHECK(riner::lost_object(square_sample(n, 2e-3, 0.0, 6, 0), fbp).pixels == 0);
    // Its corner set to air over a triangle of 20 pixels a side (210 pixels; the blur of the
    // measure takes a pixel or so off the edges).
    const riner::LostObject lost = riner::lost_object(square_sample(n, 2e-3, 0.0, 6, 20), fbp);
    CHECK(lost.pixels > 120);
    CHECK(lost.pixels < 260);
    const double disc = M_PI * 99.0 * 99.0;
    CHECK(lost.share == doctest::Approx(static_cast<double>(lost.pixels) / disc).epsilon(0.05));
    // The blurred FBP's noise: white noise of 1e-3 blurred by 2 px is 1e-3 / (2 sqrt(pi) 2).
    CHECK(lost.fbp_noise == doctest::Approx(1e-3 / (4.0 * std::sqrt(M_PI))).epsilon(0.2));
    // A faint sample (below 5 sigma of the blurred noise) is not claimed either way.
    CHECK(riner::lost_object(square_sample(n, 0.0, 0.0, 7, 0), square_sample(n, 2e-5, 1e-3, 8, 0))
              .pixels == 0);
    // An image at half the FBP's level still shows the object.
    CHECK(riner::lost_object(square_sample(n, 1e-3, 0.0, 9, 0), fbp).pixels == 0);
  }

  TEST_CASE("small faint blobs are FBP's streaks, not object; a small bright feature is") {
    const std::size_t n = 200;
    // A nearly noiseless FBP: blurred, its noise is about 1.4e-5. In the air beside the sample,
    // blobs of 3 x 3 pixels at 3.5e-4 (about 6 sigmas after the measure's blur), as streaks
    // off a dense edge leave them, and one of 3 x 3 at 2e-3 (a grain the image dropped).
    riner::Array fbp = square_sample(n, 2e-3, 1e-4, 5, 0);
    const auto blob = [&](std::size_t row, std::size_t column, float value) {
      for (std::size_t i = row; i < row + 3; ++i)
        for (std::size_t k = column; k < column + 3; ++k) fbp(i, k) += value;
    };
    for (std::size_t b = 0; b < 6; ++b) blob(30 + 25 * b, 25, 3.5e-4f);
    const riner::Array image = square_sample(n, 2e-3, 0.0, 6, 0);
    const riner::LostObject streaks = riner::lost_object(image, fbp);
    CHECK(streaks.pixels == 0);
    blob(100, 170, 2e-2f);
    CHECK(riner::lost_object(image, fbp).pixels > 10);
  }

  TEST_CASE("a thin arc about the axis the FBP shows and the image has not: counted apart") {
    // A ring of one element in the FBP (1 px wide at 80 px from the axis, over a third of the
    // turn), in the air beside the sample: the built-in demo's rings were called lost object.
    const std::size_t n = 200;
    riner::Array fbp = square_sample(n, 2e-3, 1e-3, 5, 0);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < n; ++k) {
        const double y = i - 0.5 * (n - 1.0), x = k - 0.5 * (n - 1.0);
        const double angle = std::atan2(y, x);
        if (std::fabs(std::hypot(x, y) - 80.0) < 0.5 && angle > 0.0 && angle < 2.1)
          fbp(i, k) += 1e-2f;
      }
    }
    const riner::LostObject arcs = riner::lost_object(square_sample(n, 2e-3, 0.0, 6, 0), fbp);
    CHECK(arcs.pixels == 0);
    CHECK(arcs.arc_pixels > 100);
    CHECK(arcs.arc_share > 0.0);
    // A corner cut off the sample is no arc (it is compact, not thin along a circle).
    const riner::LostObject cut = riner::lost_object(square_sample(n, 2e-3, 0.0, 6, 20), fbp);
    CHECK(cut.pixels > 120);
    CHECK(cut.arc_pixels > 100);
    // A ring ten times brighter touching that corner (54 px from the axis, the corner at 56-70):
    // the corner is judged apart from the arc it touches (it was all taken for the arc: 0 lost).
    riner::Array crossed = square_sample(n, 2e-3, 1e-3, 5, 0);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < n; ++k) {
        const double y = i - 0.5 * (n - 1.0), x = k - 0.5 * (n - 1.0);
        const double angle = std::atan2(y, x);
        if (std::fabs(std::hypot(x, y) - 54.0) < 0.5 && angle > -3.0 && angle < -1.2)
          crossed(i, k) += 1e-1f;
      }
    }
    const riner::LostObject both = riner::lost_object(square_sample(n, 2e-3, 0.0, 6, 20), crossed);
    MESSAGE("a corner a bright ring touches: " << both.pixels << " lost, " << both.arc_pixels
                                               << " in arcs");
    CHECK(both.pixels > 60);
    CHECK(both.arc_pixels > 100);
    CHECK(riner::lost_object(square_sample(n, 2e-3, 0.0, 6, 0), crossed).pixels == 0);
  }

  TEST_CASE("the FBP's bright rim at the field's edge is not object") {
    const std::size_t n = 200;
    riner::Array fbp = square_sample(n, 2e-3, 1e-3, 5, 0);
    // A rim 3 px wide just outside the field (radius 92 px), as FBP draws it there.
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < n; ++k) {
        const double r = std::hypot(i - 0.5 * (n - 1.0), k - 0.5 * (n - 1.0));
        if (std::fabs(r - 93.5) < 1.5) fbp(i, k) += 5e-3f;
      }
    }
    const riner::Array image = square_sample(n, 2e-3, 0.0, 6, 0);
    CHECK(riner::lost_object(image, fbp).pixels > 500);
    CHECK(riner::lost_object(image, fbp, 92.0).pixels == 0);
    // The field comes from the geometry: the detector's nearer end (the axis 1 element left of
    // its middle: 91.5 elements of 0.5 mm), in voxels of 0.5 mm.
    riner::Geometry g;
    g.n_u = 185;
    g.pitch_u = 0.5;
    g.offset_u = -1.0;
    g.voxel_mm = 0.5;
    CHECK(riner::field_radius_px(g) == doctest::Approx(91.5));
    // Fan beam: the ray to the detector's nearer end passes the axis at SOD sin(atan(u / SDD)).
    g.type = riner::GeometryType::kFan2d;
    g.source_origin_mm = 370.0;
    g.origin_detector_mm = 370.0;
    const double u = 91.5 * 0.5;
    CHECK(riner::field_of_view(g).radius_mm ==
          doctest::Approx(370.0 * std::sin(std::atan(u / 740.0))));
    // Half acquisition: the axis 32.5 elements from one end (offset -60). Over a full turn
    // every line is seen from one side or the other, so the field reaches the farther end
    // (152.5 elements, 76.25 mm); over a half turn only the nearer one (16.25 mm).
    g.type = riner::GeometryType::kParallel2d;
    g.offset_u = -60.0;
    g.angles = riner::uniform_angles({360, 0.0, 2.0 * M_PI});
    CHECK(riner::is_half_acquisition(g));
    CHECK(riner::field_radius_px(g) == doctest::Approx(152.5));
    g.angles = riner::uniform_angles({180, 0.0, M_PI});
    CHECK_FALSE(riner::is_half_acquisition(g));
    CHECK(riner::field_radius_px(g) == doctest::Approx(32.5));
  }
}

TEST_SUITE("quality") {
  TEST_CASE("the noise estimate scales with the noise, specks count isolated outliers") {
    const riner::Array a = noisy(128, 1e-3, 1);
    const riner::Array b = noisy(128, 2e-3, 2);
    const double na = riner::residual_noise(a), nb = riner::residual_noise(b);
    CHECK(na > 0.5e-3);
    CHECK(na < 2e-3);
    CHECK(nb / na == doctest::Approx(2.0).epsilon(0.1));
    // White noise has (almost) no 6-sigma outliers; ten planted spikes of 20 sigma are ten.
    CHECK(riner::specks_per_10k(a, na) < 1.0);
    riner::Array spiky = a;
    for (std::size_t s = 0; s < 10; ++s)
      spiky(30 + 6 * s, 40 + 5 * s) += 20.0f * static_cast<float>(na);
    const double pixels = M_PI * 63.0 * 63.0;  // the inscribed disc, roughly
    CHECK(riner::specks_per_10k(spiky, na) == doctest::Approx(1e4 * 10 / pixels).epsilon(0.1));
  }

  TEST_CASE("an edge that wavers by a fraction of a pixel is not specks; a pixel beside it is") {
    // Without the extremum rule 43 of its edge pixels read as specks here.
    const double sigma = 1e-3;
    riner::Array disc = wavering_disc(40 * sigma, 0.3, sigma, 5);
    const double noise = riner::residual_noise(disc);
    CHECK(noise == doctest::Approx(sigma).epsilon(0.2));
    const double pixels = M_PI * 63.0 * 63.0;  // the inscribed disc, roughly
    const auto specks = [&] { return riner::specks_per_10k(disc, noise) * pixels / 1e4; };
    const double edge_specks = specks();
    CHECK(edge_specks <= 3.0);
    // Four dark pixels in the air two pixels outside the edge, and four bright ones inside it.
    const double c = 63.5;
    for (int s = 0; s < 4; ++s) {
      const double angle = 0.4 + 1.5 * s;
      const auto at = [&](double r) {
        return std::pair{static_cast<std::size_t>(std::lround(c + r * std::sin(angle))),
                         static_cast<std::size_t>(std::lround(c + r * std::cos(angle)))};
      };
      const auto [io, ko] = at(42.5);
      disc(io, ko) -= static_cast<float>(12 * sigma);
      const auto [ii, ki] = at(37.0);
      disc(ii, ki) += static_cast<float>(12 * sigma);
    }
    CHECK(specks() - edge_specks == doctest::Approx(8.0).epsilon(0.05));
  }

  TEST_CASE("a disc at the centre that the FBP lacks stands out; the FBP's own noise does not") {
    const std::size_t n = 160;
    const riner::Array fbp = noisy(n, 2e-3, 3);
    const double noise = riner::residual_noise(fbp);
    riner::Array clean = noisy(n, 0.0, 4);  // the same ramp, no noise
    const riner::CentreDeviation same = riner::centre_deviation(clean, fbp);
    CHECK(same.fbp_noise > 0.0);
    CHECK(same.sigmas < 2.0);
    riner::Array disc = clean;
    const double c = 0.5 * (n - 1.0);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < n; ++k)
        if (std::hypot(i - c, k - c) < 12.0) disc(i, k) += 3e-3f;
    const riner::CentreDeviation d = riner::centre_deviation(disc, fbp);
    CHECK(d.deviation == doctest::Approx(3e-3).epsilon(0.3));
    CHECK(d.at_px < 12.0);  // inside the disc
    CHECK(d.sigmas > 3.0);
    CHECK_THROWS_AS(riner::quality_against_fbp(riner::Array({8, 8}), riner::Array({8, 8})),
                    riner::InputError);
    // A volume: its slices' specks and noise, no centre.
    riner::Array volume({2, n, n}), fbp_volume({2, n, n});
    std::copy(disc.data.begin(), disc.data.end(), volume.data.begin());
    std::copy(clean.data.begin(), clean.data.end(), volume.data.begin() + n * n);
    std::copy(fbp.data.begin(), fbp.data.end(), fbp_volume.data.begin());
    std::copy(fbp.data.begin(), fbp.data.end(), fbp_volume.data.begin() + n * n);
    const riner::QualityReport q3 = riner::quality_against_fbp(volume, fbp_volume);
    CHECK(q3.noise == doctest::Approx(noise).epsilon(1e-6));
    CHECK(q3.fbp_specks_per_10k ==
          doctest::Approx(riner::specks_per_10k(fbp, noise)).epsilon(1e-6));
    CHECK(q3.centre.sigmas == 0.0);
    CHECK_THROWS_AS(riner::centre_deviation(disc, riner::Array({n, n + 1})), riner::InputError);
    const riner::QualityReport q = riner::quality_against_fbp(disc, fbp);
    CHECK(q.noise == noise);
    CHECK(q.specks_per_10k < q.fbp_specks_per_10k + 1.0);
  }

  TEST_CASE("edge strength: a blurred disc reads weaker than a sharp one; noise barely counts") {
    const std::size_t n = 160;
    const double c = 0.5 * (n - 1.0);
    // A disc of 0.02/mm over a ramp, its edge sharp, or blurred by averaging 7 x 7 pixels.
    riner::Array sharp = noisy(n, 0.0, 5);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < n; ++k)
        if (std::hypot(i - c, k - c) < 40.0) sharp(i, k) += 0.02f;
    riner::Array blurred = sharp;
    for (std::size_t i = 3; i + 3 < n; ++i) {
      for (std::size_t k = 3; k + 3 < n; ++k) {
        double sum = 0.0;
        for (int di = -3; di <= 3; ++di)
          for (int dk = -3; dk <= 3; ++dk) sum += sharp(i + di, k + dk);
        blurred(i, k) = static_cast<float>(sum / 49.0);
      }
    }
    const double e_sharp = riner::edge_strength(sharp);
    // A step of h after a Gaussian of 1 px has its steepest slope h / sqrt(2 pi) per pixel; the
    // edge covers ~3% of the disc's pixels, so the 99th percentile lies on it.
    CHECK(e_sharp > 0.4 * 0.02 / std::sqrt(2.0 * M_PI));
    CHECK(e_sharp < 1.1 * 0.02 / std::sqrt(2.0 * M_PI));
    CHECK(riner::edge_strength(blurred) < 0.6 * e_sharp);
    // White noise of 1/20 of the step moves it by less than 10%.
    const riner::Array ramp = noisy(n, 0.0, 6);
    riner::Array noisy_sharp = noisy(n, 1e-3, 6);  // the same ramp with noise
    for (std::size_t p = 0; p < noisy_sharp.size(); ++p)
      noisy_sharp.data[p] += sharp.data[p] - ramp.data[p];
    CHECK(riner::edge_strength(noisy_sharp) == doctest::Approx(e_sharp).epsilon(0.1));
    const riner::QualityReport q = riner::quality_against_fbp(blurred, sharp);
    CHECK(q.edge_scale_px == 1.0);  // the sharp disc's edges stand out at 1 px
    CHECK(q.edge_strength / q.fbp_edge_strength < riner::kSoftEdgeRatio);
    CHECK_THROWS_AS(riner::edge_strength(riner::Array({8, 8})), riner::InputError);
  }

  TEST_CASE("edge strength: an FBP whose noise hides its edges at 1 px is compared wider") {
    // A faint square (0.005/mm) in an FBP whose noise, high-pass like an FBP's (white noise
    // less the mean of its 4 neighbours), is larger than its step per pixel: at 1 px the FBP's
    // 99th percentile is the noise's, and the noise-free square, as sharp as the truth, would
    // read blurred.
    const std::size_t n = 200;
    riner::Array clean({n, n});
    for (std::size_t i = 50; i < 150; ++i)
      for (std::size_t k = 50; k < 150; ++k) clean(i, k) = 0.005f;
    std::mt19937 rng(7);
    std::normal_distribution<double> g(0.0, 0.02);
    riner::Array white({n, n});
    for (float& v : white.data) v = static_cast<float>(g(rng));
    riner::Array fbp = clean;
    for (std::size_t i = 1; i + 1 < n; ++i)
      for (std::size_t k = 1; k + 1 < n; ++k)
        fbp(i, k) += white(i, k) - 0.25f * (white(i - 1, k) + white(i + 1, k) + white(i, k - 1) +
                                            white(i, k + 1));
    CHECK(riner::edge_strength(clean) < 0.5 * riner::edge_strength(fbp));  // 1 px: misread
    CHECK(riner::edge_scale_px(fbp) > 1.0);
    CHECK(riner::edge_scale_px(fbp) < 8.0);
    CHECK(riner::edge_scale_px(clean) == 1.0);
    const riner::QualityReport q = riner::quality_against_fbp(clean, fbp);
    CHECK(q.edge_scale_px == riner::edge_scale_px(fbp));
    CHECK(q.edge_strength / q.fbp_edge_strength > riner::kSoftEdgeRatio);
    CHECK(q.edge_strength / q.fbp_edge_strength < 1.25);
    // The same square blurred by a Gaussian of about 5 px (12 passes of a 5 x 5 mean) still reads
    // blurred at that scale.
    riner::Array soft = clean;
    for (int pass = 0; pass < 12; ++pass) {
      riner::Array next = soft;
      for (std::size_t i = 2; i + 2 < n; ++i)
        for (std::size_t k = 2; k + 2 < n; ++k) {
          double sum = 0.0;
          for (int di = -2; di <= 2; ++di)
            for (int dk = -2; dk <= 2; ++dk) sum += soft(i + di, k + dk);
          next(i, k) = static_cast<float>(sum / 25.0);
        }
      soft = next;
    }
    const riner::QualityReport qs = riner::quality_against_fbp(soft, fbp);
    CHECK(qs.edge_strength / qs.fbp_edge_strength < riner::kSoftEdgeRatio);
  }
}
