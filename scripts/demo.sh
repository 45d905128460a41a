#!/usr/bin/env bash
# The README's demo command: install dependencies, build, and run riner's main job on its
# built-in default scan: a Shepp-Logan fan-beam scan with ring artifacts, reconstructed with
# FBP and with Riner. Outputs (comparison.png, images, detector response, metrics) go to
# ./demo_out.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
build/apps/riner devices
build/apps/riner demo --out demo_out
