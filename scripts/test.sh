#!/usr/bin/env bash
# Set up, build and run every test with ctest. The README's test command.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
build_dir="${DEPOTWIN_BUILD_DIR:-$root/build}"
cd "$build_dir"
ctest --output-on-failure -j "${DEPOTWIN_JOBS:-$(nproc)}" "$@"
