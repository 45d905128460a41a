#!/usr/bin/env python3
"""A drifting beam as the main defect (issue 32, item 3): a clean detector, the paper's fan beam
and Shepp-Logan (riner.simulate, seed 4, noise-free line integrals), raw counts under a beam of
2e4 photons with a parabolic profile that loses light over the scan, four flat frames before
and four after. FBP and riner at the defaults with the flats before only (as a scanner's single
flat series is used) and with both series (each view's flat interpolated).

  drifting_beam.py [--loss smooth|elements]

smooth: 0-20% lost by the end, varying smoothly across the detector (a decaying, moving beam);
elements: 0-20% drawn element by element (gains that drift, each pixel on its own).
Prints one line per case: PSNR / SSIM against the truth, the ring index, the drift check.
"""
import argparse
import time

import numpy as np
import riner


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--loss", choices=("smooth", "elements"), default="elements")
    args = parser.parse_args()
    sim = riner.simulate(None, "fan2d-paper", seed=4, nonideal_fraction=0.0, dead=0, photons=0)
    lines = sim["clean"].astype(np.float64)
    truth = sim["ground_truth"]
    views, elements = lines.shape
    e = np.arange(elements)
    beam = 2e4 * (1 - 0.3 * ((e - (elements - 1) / 2) / (elements / 2)) ** 2)
    if args.loss == "smooth":
        loss = 0.10 + 0.10 * np.sin(2 * np.pi * 1.5 * e / elements)
    else:
        loss = 0.10 + 0.10 * np.random.default_rng(7).uniform(-1, 1, elements)
    when = (np.arange(views)[:, None] + 0.5) / views
    rng = np.random.default_rng(0)
    raw = rng.poisson(beam * (1 - loss * when) * np.exp(-lines)).astype(np.float32)
    before = rng.poisson(np.tile(beam, (4, 1))).astype(np.float32)
    after = rng.poisson(np.tile(beam * (1 - loss), (4, 1))).astype(np.float32)
    print(f"loss {args.loss}: case | FBP dB / SSIM | riner dB / SSIM | ring index FBP -> riner | "
          "drift check | seconds")
    for name, flats in (("flats before only", dict(flat=before)),
                        ("flats before and after", dict(flat=before, flat_after=after))):
        _, report = riner.flat_field(raw, **flats)
        fbp = riner.compare(riner.fbp(raw, "fan2d-paper", **flats), truth)
        start = time.time()
        r = riner.reconstruct(raw, "fan2d-paper", **flats)
        m = riner.compare(r.image, truth)
        q = r.summary["quality"]
        check = (f"drifts, {report['air_drift_sigmas']:.0f} sigmas" if report["air_drifts"]
                 else "no drift")
        print(f"{name} | {fbp['psnr']:.2f} / {fbp['ssim']:.3f} | {m['psnr']:.2f} / "
              f"{m['ssim']:.3f} | {q['fbp_ring_index']:.4f} -> {q['ring_index']:.4f} | {check} | "
              f"{time.time() - start:.0f}")


if __name__ == "__main__":
    main()
