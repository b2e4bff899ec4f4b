#!/usr/bin/env bash
# Bounded fuzz runs: builds the libFuzzer targets of tests/fuzz/ with clang, ASan and UBSan into
# build-fuzz/, then runs each from its committed corpus for a while. A crash, a sanitizer
# report, an exception other than InputError, a hang (one input over 60 s), an allocation over
# 1 GB or 2.5 GB in all fails the run; the input is kept in build-fuzz/artifacts/<target>/.
#   scripts/fuzz.sh [TARGET...]        scenario gcode stl move (default: all four)
#   DEPOTWIN_FUZZ_SECONDS=60           how long each target runs (the CI's setting)
#   DEPOTWIN_FUZZ_RUNS=N               run N inputs per target instead (a long run: 10000000)
#   DEPOTWIN_FUZZ_BUILD_DIR=DIR        where to build (default build-fuzz/)
# New inputs that reach new code stay in build-fuzz/corpus/<target>/ (not committed); the
# committed corpus is tests/fuzz/corpus/<target>/: small seeds, and a regression input for every
# crash found and fixed.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
build_dir="${DEPOTWIN_FUZZ_BUILD_DIR:-$root/build-fuzz}"
jobs="${DEPOTWIN_JOBS:-$(nproc)}"
seconds="${DEPOTWIN_FUZZ_SECONDS:-60}"
runs="${DEPOTWIN_FUZZ_RUNS:-}"
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then targets=(scenario gcode stl move); fi
for target in "${targets[@]}"; do
  if [ ! -d "$root/tests/fuzz/corpus/$target" ]; then
    echo "fuzz: unknown target '$target' (expected scenario, gcode, stl or move)" >&2
    exit 2
  fi
done
# the sanitizers' settings, without stack-use-after-return detection (half the speed of the
# STL reader's runs) and with a 16 MB quarantine for freed memory instead of 256 MB (refilling
# the large one cost the scenario loader's runs two thirds of their time in page faults)
ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:strict_init_order=1:check_initialization_order=1:halt_on_error=1:quarantine_size_mb=16}"
source "$root/tests/sanitizers/options.sh"

launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
echo "fuzz: configuring $build_dir (clang, libFuzzer, ASan + UBSan)"
cmake -S "$root" -B "$build_dir" -DCMAKE_CXX_COMPILER=clang++ -DDEPOTWIN_FUZZ=ON \
  -DDEPOTWIN_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1" "${launcher[@]}" >/dev/null
echo "fuzz: building ${targets[*]/#/fuzz_}"
cmake --build "$build_dir" -j "$jobs" --target "${targets[@]/#/fuzz_}"

# temporary files (fuzz_scenario's directory when /dev/shm is missing) under the build, one
# folder per run of this script, removed afterwards
mkdir -p "$build_dir/tmp"
TMPDIR="$(mktemp -d "$build_dir/tmp/run-XXXXXX")"
export TMPDIR
trap 'rm -rf "$TMPDIR"' EXIT
failed=()
for target in "${targets[@]}"; do
  corpus="$build_dir/corpus/$target"
  artifacts="$build_dir/artifacts/$target"
  mkdir -p "$corpus" "$artifacts"
  for seed in "$root/tests/fuzz/corpus/$target"/*; do
    [ -e "$corpus/$(basename "$seed")" ] || cp "$seed" "$corpus"/
  done
  # one process per part: the whole time, or the runs asked for. assimp leaks about 2.5 kB on
  # each malformed ASCII STL file (suppressed in lsan.supp), which nearly every input the
  # STL reader's run breeds is, so one process outgrows the 2.5 GB limit after about 0.8 M
  # inputs: its long runs go in parts of 0.5 M inputs, each from the corpus the last one grew
  parts=("")
  what="$seconds s"
  if [ -n "$runs" ]; then
    what="$runs runs"
    part_runs="$runs"
    if [ "$target" = stl ]; then part_runs=500000; fi
    parts=()
    for ((left = runs; left > 0; left -= part_runs)); do
      parts+=("$((left < part_runs ? left : part_runs))")
    done
  fi
  # assimp's leaks would also make a leak check after every such input cost three quarters of
  # the run, so the STL reader's are checked at exit only
  leaks=(-detect_leaks=1)
  if [ "$target" = stl ]; then leaks=(-detect_leaks=0); fi
  echo "fuzz: $target for $what (corpus $corpus${runs:+, ${#parts[@]} part(s)})"
  executed=0
  target_failed=0
  for ((part = 0; part < ${#parts[@]}; ++part)); do
    limit=(-max_total_time="$seconds")
    log="$build_dir/fuzz-$target.log"
    if [ -n "$runs" ]; then
      limit=(-runs="${parts[part]}")
      log="$build_dir/fuzz-$target-$runs-runs-part$((part + 1)).log"
    fi
    # -entropic_scale_per_exec_time: inputs that run long (a random_segments bed packed to its
    # last segment takes seconds) get less of the mutation budget, so the scenario loader runs
    # at about 1 300-1 600 inputs/s instead of 90 while still reaching the same code
    if ! "$build_dir/tests/fuzz/fuzz_$target" "${limit[@]}" "${leaks[@]}" -timeout=60 \
      -rss_limit_mb=2560 -malloc_limit_mb=1024 -entropic_scale_per_exec_time=1 \
      -dict="$root/tests/fuzz/$target.dict" -print_final_stats=1 -artifact_prefix="$artifacts/" \
      "$corpus" >"$log" 2>&1; then
      tail -n 60 "$log"
      echo "fuzz: $target FAILED: input kept in $artifacts/ (log: $log). Once fixed, commit it" \
        "as tests/fuzz/corpus/$target/regression-<what>."
      failed+=("$target")
      target_failed=1
      break
    fi
    # libFuzzer's final stats: executions, rate, peak memory
    grep -E "^stat::(number_of_executed_units|average_exec_per_sec|peak_rss_mb)" "$log" |
      sed "s/^/fuzz: $target${runs:+ part $((part + 1))}: /"
    executed=$((executed + $(sed -n 's/^stat::number_of_executed_units: *//p' "$log")))
  done
  if [ "$target_failed" = 0 ]; then echo "fuzz: $target: $executed inputs, no crash"; fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: failed: ${failed[*]}"
  exit 1
fi
echo "fuzz: ${targets[*]}: no crash"
