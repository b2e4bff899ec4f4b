#!/usr/bin/env bash
# The whole test suite again, built with clang under AddressSanitizer + UndefinedBehaviorSanitizer
# (float-cast-overflow included), into build-sanitize/. Any finding aborts the test that made
# it, so the run fails. The second step of .ci/run, after scripts/test.sh. Arguments go to
# ctest (e.g. -R Gcode). MuJoCo and the other Debian libraries are not instrumented; leaks
# inside them are suppressed by tests/sanitizers/lsan.supp (libraries only, never ours).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
build_dir="${DEPOTWIN_SANITIZE_BUILD_DIR:-$root/build-sanitize}"
jobs="${DEPOTWIN_JOBS:-$(nproc)}"

# the sanitizers' settings, for the build (gtest_discover_tests runs the test programs) and ctest
source "$root/tests/sanitizers/options.sh"

# -O2 as the normal build (Eigen is slow unoptimised), line tables for the reports, and
# assertions left on (no NDEBUG: Eigen's bounds checks run too); no benchmark programs
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
echo "sanitize: configuring $build_dir (clang, ASan + UBSan)"
cmake -S "$root" -B "$build_dir" -DCMAKE_CXX_COMPILER=clang++ -DDEPOTWIN_SANITIZE=ON \
  -DDEPOTWIN_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1" "${launcher[@]}" >/dev/null
echo "sanitize: building"
cmake --build "$build_dir" -j "$jobs"
echo "sanitize: running every test"
cd "$build_dir"
ctest --output-on-failure -j "$jobs" "$@"
