#!/usr/bin/env bash
# Installs everything riner's build, tests, benchmarks and demo need, from Debian's packages.
set -euo pipefail
packages=(
  cmake g++ make pkg-config git
  ocl-icd-opencl-dev opencl-headers pocl-opencl-icd clinfo
  libclblast-dev libeigen3-dev doctest-dev nlohmann-json3-dev
  libtiff-dev libpng-dev libhdf5-dev
  openmpi-bin libopenmpi-dev
  oclgrind valgrind
  python3-dev pybind11-dev python3-numpy python3-pytest python3-skimage
)
if [ "$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update
$sudo apt-get install -y --no-install-recommends "${packages[@]}"
