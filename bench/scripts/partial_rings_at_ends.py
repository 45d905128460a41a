#!/usr/bin/env python3
"""Partial rings near the scan's ends (issue 32): the partial-rings bench's scans (the ten
DeepLesion slices in bench/partial_rings_geometry.json's 180-degree parallel beam, the paper's
responses and 10^7 photons), with 12 elements per slice whose response changes by 15-30% (in
log) at a view drawn within views / 12 of either end, where riner_bench --case=partial_rings
draws none. Prints, per slice, the changes and how many the detection found at their view,
elsewhere, and on unchanged elements; with --train, also riner at the defaults with
training.partial_responses on and off on the first N slices (PSNR / SSIM against the truth).

  partial_rings_at_ends.py [--data ../shared/data/deeplesion] [--train N]
"""
import argparse
import os

import numpy as np
import riner

GEOMETRY = os.path.join(os.path.dirname(__file__), "..", "partial_rings_geometry.json")


def scan_with_changes_at_the_ends(data, i):
    """Slice i's scan (seed i), its truth, and {element: [view of the change]}."""
    img = riner.read_array(f"{data}/slice_{i}.nii")
    sim = riner.simulate(img, GEOMETRY, seed=i, mu_unit="cm", photons=0)
    lines = sim["clean"].astype(np.float64)
    base = np.asarray(sim["alpha"], np.float64)
    views, elements = lines.shape
    rng = np.random.default_rng(100 + i)
    alpha = np.tile(base, (views, 1))
    live = np.flatnonzero(base > 0)
    live = live[(live > 2) & (live < elements - 3)]
    truth = {}
    for k, e in enumerate(rng.choice(live, 12, replace=False)):
        near_end = int(rng.integers(10, views // 12))
        v = near_end if k % 2 == 0 else views - near_end
        alpha[v:, e] *= np.exp(rng.choice([-1, 1]) * rng.uniform(0.15, 0.3))
        truth[int(e)] = [v]
    counts = rng.poisson(alpha * 1e7 * np.exp(-lines))
    with np.errstate(divide="ignore"):
        sino = (-np.log(counts / 1e7)).astype(np.float32)
    return sino, sim["ground_truth"], truth, base


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--data", default="../shared/data/deeplesion")
    parser.add_argument("--train", type=int, default=0)
    args = parser.parse_args()
    total = np.zeros(4, int)
    print("slice | changes | found at their view | elsewhere | unchanged elements found")
    for i in range(10):
        sino, image, truth, base = scan_with_changes_at_the_ends(args.data, i)
        r = riner.reconstruct(sino, GEOMETRY, steps=1, quality=False)
        found = {c["element"]: [s["first_view"] for s in c["segments"]][1:]
                 for c in r.summary["changing_elements"]}
        row = np.array([len(truth), sum(truth.get(e) == v for e, v in found.items()),
                        sum(e in truth and truth[e] != v for e, v in found.items()),
                        sum(e not in truth and base[e] > 0 for e in found)])
        total += row
        print(i, *row, sep=" | ", flush=True)
        if i < args.train:
            for on in (True, False):
                m = riner.compare(riner.reconstruct(sino, GEOMETRY, partial_responses=on,
                                                    quality=False).image, image)
                print(f"  partial_responses {'on' if on else 'off'}: {m['psnr']:.2f} dB / "
                      f"{m['ssim']:.4f}", flush=True)
    print("total", *total, sep=" | ")


if __name__ == "__main__":
    main()
