#!/usr/bin/env bash
# Builds riner with clang, ASan, UBSan and libFuzzer's coverage instrumentation (the library
# too: without it the fuzzer sees only the harness), and runs every libFuzzer target for the
# given number of seconds each (default 600) from its seed corpus; findings land in
# build-fuzz/findings/.
# Not part of CI.   usage: scripts/fuzz.sh [seconds] [target ...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(npy nifti tiff raw geometry config)
if ! command -v clang++ >/dev/null; then
  if [ "$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi
  $sudo apt-get install -y --no-install-recommends clang libclang-rt-dev
fi
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DRINER_BUILD_FUZZERS=ON -DRINER_BUILD_PYTHON=OFF -DRINER_BUILD_TESTS=OFF -DRINER_BUILD_BENCH=OFF -DRINER_BUILD_APPS=OFF \
  -DRINER_SANITIZE=address,undefined,fuzzer-no-link
cmake --build build-fuzz -j "$(nproc)"
mkdir -p build-fuzz/findings
for t in "${targets[@]}"; do
  corpus=build-fuzz/corpus/$t
  mkdir -p "$corpus"
  cp -n test/fuzz/corpus/$t/* "$corpus"/ 2>/dev/null || true
  echo "== fuzz_$t for ${seconds}s"
  build-fuzz/test/fuzz/fuzz_$t -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=4096 \
    -artifact_prefix=build-fuzz/findings/$t- "$corpus"
done
