#!/usr/bin/env bash
# Configures and builds riner (Release) into ./build. Extra arguments go to cmake's configure.
# Then makes `import riner` work for this user's python3: a riner.pth in the user
# site-packages names build/python (what `pip install --user -e` would do; the last build
# registered wins). RINER_NO_PTH=1 skips that; PYTHONPATH=build/python works without it.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build -j "$(nproc)"

if [ -d build/python/riner ] && [ -z "${RINER_NO_PTH:-}" ]; then
  built_for=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' build/CMakeCache.txt)
  tag=$("$built_for" -c 'import sys; print(sys.implementation.cache_tag)')
  # The python the module was built for, and the python3 on PATH when it is the same version.
  for py in "$built_for" python3; do
    command -v "$py" >/dev/null || continue
    [ "$("$py" -c 'import sys; print(sys.implementation.cache_tag)')" = "$tag" ] || continue
    site=$("$py" -m site --user-site)
    mkdir -p "$site"
    echo "$PWD/build/python" > "$site/riner.pth"
  done
  echo "riner's Python module: build/python (registered in $site/riner.pth)"
fi
