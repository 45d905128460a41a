"""The Python module against the CLI on DeepLesion slices at the defaults (issue 15 acceptance):
the same simulation (fan2d-paper, seed = slice), the same seed and settings, reconstructed once
through `riner reconstruct` and once through riner.reconstruct(); PSNR/SSIM of both against the
ground truth, the largest pixel difference, and the wall time of each.

    PYTHONPATH=build/python /usr/bin/python3 bench/scripts/python_vs_cli.py \
        --cli build/apps/riner --shared ../shared --slices 0 --json out.jsonl
"""
import argparse
import json
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import riner


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default="build/apps/riner")
    parser.add_argument("--shared", default="../shared")
    parser.add_argument("--slices", default="0")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--steps", type=int, default=0, help="0: the default")
    parser.add_argument("--json", default="")
    args = parser.parse_args()
    rows = []
    for s in [int(v) for v in args.slices.split(",")]:
        truth = riner.read_array(pathlib.Path(args.shared) / "data/deeplesion" / f"slice_{s}.nii")
        truth = truth * np.float32(0.1)  # 1/cm -> 1/mm
        sim = riner.simulate(truth, "fan2d-paper", seed=s)
        settings = {"seed": args.seed}
        flags = ["--seed", str(args.seed)]
        if args.steps:
            settings["steps"] = args.steps
            flags += ["--steps", str(args.steps)]
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            riner.write_array(tmp / "sino.npy", sim["sino"])
            (tmp / "geometry.json").write_text(json.dumps(sim["geometry"]))
            start = time.time()
            subprocess.run([args.cli, "reconstruct", str(tmp / "sino.npy"), "--format", "npy",
                            "--out", str(tmp / "cli"), "--quiet"] + flags, check=True)
            cli_seconds = time.time() - start
            cli_image = riner.read_array(tmp / "cli" / "image.npy")
        start = time.time()
        result = riner.reconstruct(sim["sino"], sim["geometry"], **settings)
        py_seconds = time.time() - start
        cli_m = riner.compare(cli_image, truth)
        py_m = riner.compare(result.image, truth)
        row = {"slice": s, "seed": args.seed, "steps": result.summary["steps"],
               "cli_psnr": cli_m["psnr"], "cli_ssim": cli_m["ssim"],
               "python_psnr": py_m["psnr"], "python_ssim": py_m["ssim"],
               "max_abs_difference": float(np.abs(result.image - cli_image).max()),
               "cli_seconds": cli_seconds, "python_seconds": py_seconds,
               "device": result.summary["device"]}
        print(json.dumps(row), flush=True)
        rows.append(row)
    if args.json:
        with open(args.json, "a", encoding="utf-8") as f:
            for row in rows:
                f.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
