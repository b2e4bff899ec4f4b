#!/usr/bin/env bash
# Set up, build, and run a paper scenario headless: Thompson & Yoon's Fig. 7 with both the
# paper's planner (lspb_mtt) and the naive baseline (stop_and_go). Prints the summary and
# where the metrics and images went.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh" >/dev/null
build_dir="${DEPOTWIN_BUILD_DIR:-$root/build}"
out="${1:-$root/results/thompson_fig7}"
cd "$root"
"$build_dir/depotwin" compare scenarios/thompson_fig7.yaml --out "$out"
