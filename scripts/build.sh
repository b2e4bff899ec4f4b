#!/usr/bin/env bash
# Configure and build DepoTwin (Release) into build/. Used by test.sh and demo.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${DEPOTWIN_BUILD_DIR:-$root/build}"
jobs="${DEPOTWIN_JOBS:-$(nproc)}"
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build_dir" -j "$jobs"
