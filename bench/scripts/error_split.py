#!/usr/bin/env python3
"""Where a reconstruction's error lies (issue 31's warm start against the cold defaults): each
slice's error image split into its rings (the angular means about the grid's centre, in rings
of half a pixel), the broad rest (a Gaussian of 2 px of what is left) and the fine rest, as mean
squared errors over the slices, in dB of the truth's range (the PSNR each part alone would give).

  build/bench/riner_bench --case=ring_corrections --first=0 --last=9 --images=COLD
  build/bench/riner_bench --case=ring_corrections --first=0 --last=9 \
      --config='{"training":{"warm_start":"wavelet"}}' --images=WARM
  error_split.py COLD WARM

Each folder holds slice_N_result.npy and slice_N_truth.npy (what --images writes).
"""
import argparse
import glob
import os
import re

import numpy as np


def parts(error):
    """Mean squares of the error's rings, broad rest and fine rest (they add up to its own)."""
    n = error.shape[0]
    centre = (n - 1) / 2
    y, x = np.mgrid[0:n, 0:n]
    ring = np.floor(np.hypot(x - centre, y - centre) / 0.5).astype(int)
    sums = np.bincount(ring.ravel(), error.ravel())
    counts = np.maximum(np.bincount(ring.ravel()), 1)
    rings = (sums / counts)[ring]
    rest = error - rings
    f = np.fft.fftfreq(n)
    fx, fy = np.meshgrid(f, f)
    gauss = np.exp(-2 * (np.pi * 2.0) ** 2 * (fx ** 2 + fy ** 2))  # sigma 2 px
    broad = np.real(np.fft.ifft2(np.fft.fft2(rest) * gauss))
    return np.array([np.mean(error ** 2), np.mean(rings ** 2), np.mean(broad ** 2),
                     np.mean((rest - broad) ** 2)])


def db(mean_square):
    return 10 * np.log10(1.0 / mean_square)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folders", nargs="+", help="folders written by ring_corrections --images")
    args = parser.parse_args()
    print("| folder | slices | PSNR (mean) | total | rings | broad rest | fine rest |")
    print("|---|---|---|---|---|---|---|")
    for folder in args.folders:
        results = sorted(glob.glob(os.path.join(folder, "slice_*_result.npy")),
                         key=lambda p: int(re.search(r"slice_(\d+)_", p).group(1)))
        if not results:
            raise SystemExit(f"{folder}: no slice_N_result.npy")
        total = np.zeros(4)
        psnr = []
        for path in results:
            truth = np.load(path.replace("_result.npy", "_truth.npy"))
            span = truth.max() - truth.min()
            p = parts(np.load(path) - truth) / span ** 2
            total += p
            psnr.append(db(p[0]))
        total /= len(results)
        shares = total[1:] / total[0]
        print(f"| {folder} | {len(results)} | {np.mean(psnr):.2f} | {db(total[0]):.2f} | "
              f"{db(total[1]):.2f} ({shares[0]:.0%}) | {db(total[2]):.2f} ({shares[1]:.0%}) | "
              f"{db(total[3]):.2f} ({shares[2]:.0%}) |")


if __name__ == "__main__":
    main()
