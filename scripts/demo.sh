#!/usr/bin/env bash
# The README's demo command: install dependencies, build, and run riner's main job on its
# built-in default scan. Outputs go to ./demo_out.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
build/apps/riner devices
