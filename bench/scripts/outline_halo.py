#!/usr/bin/env python3
"""The halo at an object's outline (issue 29): a round object's mean profile across its edge,
by distance from its own centre (found from the FBP above a threshold), for the scan's FBP and
for images replayed with two ring-correction chains, and a zoom on the edge. For the HTC disc:

  riner fbp ../shared/data/htc2022_disc/sino.npy --output fbp.nii
  OLD_BINARY/riner_bench --case=ring_chain_replay --replay=DIR --images=OLD
  build/bench/riner_bench --case=ring_chain_replay --replay=DIR --images=NEW
  outline_halo.py fbp.nii OLD/htc2022_disc_magrg.npy NEW/htc2022_disc_magrg.npy \
      --names "zeroed at the end" "zeroed after each step" --png bench/figures/htc_outline_halo.png
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import riner


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("fbp")
    p.add_argument("images", nargs="+")
    p.add_argument("--names", nargs="+")
    p.add_argument("--threshold", type=float, default=0.02, help="object above this (1/mm)")
    p.add_argument("--png")
    a = p.parse_args()
    fbp = np.asarray(riner.read_array(a.fbp), dtype=np.float64).squeeze()
    images = [np.load(f).astype(np.float64).squeeze() for f in a.images]
    names = a.names or a.images
    y, x = np.mgrid[0:fbp.shape[0], 0:fbp.shape[1]]
    inside = fbp > a.threshold
    cy, cx = y[inside].mean(), x[inside].mean()
    radius = np.sqrt(inside.sum() / np.pi)
    r = np.hypot(y - cy, x - cx)
    print(f"object centre ({cy:.1f}, {cx:.1f}) px, radius {radius:.1f} px")
    band = (r > radius + 1.5) & (r < radius + 5)
    print(f"air 1.5-5 px outside the edge, mean minus the FBP's ({fbp[band].mean():.5f}/mm):")
    for name, im in zip(names, images):
        print(f"  {name}: {im[band].mean() - fbp[band].mean():+.5f}/mm")
    if not a.png:
        return
    d = np.arange(-6, 8, 0.5)
    fig = plt.figure(figsize=(3 * (len(images) + 1), 6.5))
    panels = len(images) + 1
    ax = [plt.subplot2grid((2, panels), (0, 0), colspan=panels)]
    ax += [plt.subplot2grid((2, panels), (1, k)) for k in range(panels)]
    ax[0].plot(d, [fbp[(r >= radius + t) & (r < radius + t + 0.5)].mean() for t in d], "k", label="FBP")
    for name, im in zip(names, images):
        ax[0].plot(d, [im[(r >= radius + t) & (r < radius + t + 0.5)].mean() for t in d], label=name)
    ax[0].set_xlabel("distance from the object's edge (px)")
    ax[0].set_ylabel("mean (1/mm)")
    ax[0].set_ylim(-0.002, 0.012)
    ax[0].legend(fontsize=8)
    # The part of the edge farthest to the left.
    row = int(round(cy))
    col = int(round(cx - radius))
    crop = (slice(row - 12, row + 12), slice(max(col - 8, 0), col + 16))
    for axis, (name, im) in zip(ax[1:], [("FBP", fbp)] + list(zip(names, images))):
        axis.imshow(im[crop], cmap="gray", vmin=-0.005, vmax=0.015, interpolation="nearest")
        axis.set_title(name, fontsize=9)
        axis.set_xticks([])
        axis.set_yticks([])
    fig.tight_layout()
    fig.savefig(a.png, dpi=80)
    print(f"wrote {a.png}")


if __name__ == "__main__":
    main()
