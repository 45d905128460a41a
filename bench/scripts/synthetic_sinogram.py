#!/usr/bin/env python3
"""A synthetic parallel-beam sinogram for timing the stripe filters (riner destripe) at a
scanner's size: a shifted disc over 180 degrees, 30% of the elements offset by up to +-0.05 in
rho, Gaussian noise 0.005. Writes sino.npy and geometry.json into the folder given.

    python3 bench/scripts/synthetic_sinogram.py DIR [--views 720] [--columns 725]
"""
import argparse
import json
import os

import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--views", type=int, default=720)
    parser.add_argument("--columns", type=int, default=725)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    views, columns = args.views, args.columns
    angles = np.linspace(0.0, np.pi, views, endpoint=False)
    u = np.arange(columns) - columns / 2 + 0.5
    radius, cx, cy = 250.0 * columns / 725, 30.0, -20.0
    sino = np.zeros((views, columns), np.float32)
    for i, t in enumerate(angles):
        d = u - (cx * np.cos(t) + cy * np.sin(t))
        sino[i] = 0.008 * np.sqrt(np.clip(radius * radius - d * d, 0.0, None))
    offsets = np.zeros(columns, np.float32)
    chosen = rng.random(columns) < 0.3
    offsets[chosen] = rng.uniform(-0.05, 0.05, chosen.sum())
    sino += offsets[None, :] + rng.normal(0.0, 0.005, (views, columns)).astype(np.float32)
    os.makedirs(args.out, exist_ok=True)
    np.save(os.path.join(args.out, "sino.npy"), sino.astype(np.float32))
    geometry = {"type": "parallel2d",
                "detector": {"count": columns, "pitch_mm": 1.0},
                "angles": {"count": views, "start_rad": 0.0, "range_rad": np.pi},
                "volume": {"shape": [columns, columns], "voxel_mm": 1.0}}
    with open(os.path.join(args.out, "geometry.json"), "w") as f:
        json.dump(geometry, f)


if __name__ == "__main__":
    main()
