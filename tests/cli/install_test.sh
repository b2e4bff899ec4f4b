#!/usr/bin/env bash
# `cmake --install` lays out a working CLI: DIR/bin/depotwin finds the models installed beside
# it (not the source tree it was built from) and runs a shipped scenario from any directory.
set -euo pipefail
build_dir="$1"
prefix="$(mktemp -d)"
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build_dir" --prefix "$prefix" >/dev/null
binary="$prefix/bin/depotwin"
[[ -x "$binary" ]] || { echo "FAIL: no $binary"; exit 1; }
# the models directory it reports is the installed one
version="$(env -u DEPOTWIN_MODELS_DIR "$binary" --version)"
expected="models: $(realpath "$prefix")/share/depotwin/models"
grep -qxF "$expected" <<<"$version" || { echo "FAIL: '$version' lacks '$expected'"; exit 1; }
[[ -f "$prefix/share/depotwin/models/xy_stage.xml" ]] || { echo "FAIL: models not installed"; exit 1; }
# a shipped scenario, simulated from an unrelated directory with the installed models
cd "$prefix"
env -u DEPOTWIN_MODELS_DIR "$binary" run share/depotwin/scenarios/thompson_fig7.yaml \
  --planner lspb_mtt --no-render --quiet --out "$prefix/out" >/dev/null
[[ -f "$prefix/out/lspb_mtt/metrics.json" ]] || { echo "FAIL: no metrics.json"; exit 1; }
echo "ok: installed CLI runs with $expected"
