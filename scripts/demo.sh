#!/usr/bin/env bash
# The README's demo command: install dependencies, build, and run riner's main job on its
# built-in default scan (a Shepp-Logan fan-beam scan with ring artifacts). Outputs go to
# ./demo_out.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
riner=build/apps/riner
$riner devices
$riner simulate --phantom shepp-logan --geometry fan2d-paper --seed 1 --out demo_out
$riner fbp demo_out/sino.npy --out demo_out/fbp.nii --png
$riner compare demo_out/fbp.nii demo_out/ground_truth.nii
