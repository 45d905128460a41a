#!/usr/bin/env bash
# The README's test command: install dependencies, build, run every test tier.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
cd build
ctest --output-on-failure --timeout 1800
