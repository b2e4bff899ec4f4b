#!/usr/bin/env bash
# Set up, build, and run a paper scenario headless: Thompson & Yoon's Fig. 7 with both the
# paper's planner (lspb_mtt) and the naive baseline (stop_and_go). Says what it is doing at each
# step, shows the build's progress, then prints the summary and where the metrics and images went.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${DEPOTWIN_BUILD_DIR:-$root/build}"
out="${1:-$root/results/thompson_fig7}"
started=$SECONDS

echo "demo: [1/3] checking the Debian packages (installs any that are missing)"
"$root/scripts/setup.sh"

if [[ -x "$build_dir/depotwin" ]]; then
  echo "demo: [2/3] building into $build_dir (rebuilds only what changed: seconds to minutes)"
else
  echo "demo: [2/3] building into $build_dir: a first build takes about 15 min on 2 cores" \
    "(the library, the CLI and the tests); progress below"
fi
# the build's percentage lines, errors and warnings; the build's own status decides
set +e
"$root/scripts/build.sh" 2>&1 | grep --line-buffered -E '^\[ *[0-9]+%\]|[Ee]rror|[Ww]arning'
build_status=${PIPESTATUS[0]}
set -e
[[ $build_status -eq 0 ]] || { echo "demo: the build failed (status $build_status)" >&2; exit 1; }
[[ -x "$build_dir/depotwin" ]] || { echo "demo: the build produced no $build_dir/depotwin" >&2; exit 1; }

echo "demo: [3/3] Thompson & Yoon Fig. 7 on the XY aerosol stage: lspb_mtt against stop_and_go," \
  "each planned, simulated in MuJoCo, deposited, scored and rendered (about 10 s)"
cd "$root"
"$build_dir/depotwin" compare scenarios/thompson_fig7.yaml --out "$out"
echo "demo: done in $((SECONDS - started)) s. Open $out/comparison.md, or the images under $out/."
echo "demo: the CLI is $build_dir/depotwin (\`$build_dir/depotwin --help\`;" \
  "\`cmake --install $build_dir --prefix DIR\` puts it in DIR/bin)"
