#!/usr/bin/env bash
# Regenerate the example images under renders/ (or OUTDIR) from every scenario in scenarios/:
# `depotwin compare` into a temporary directory, then a curated copy into OUTDIR/<scenario>/:
# comparison.png, comparison.md and per run scene.png, thickness.png, path.png, axes.png,
# errors.png and thickness_profile.png (no CSVs, JSON or raw field data). Each scenario
# folder is emptied first, so the output is exactly what this run made; the output is
# byte-for-byte deterministic (running twice leaves `git status` clean).
#
# usage: scripts/render-examples.sh [OUTDIR]      (default: <repo>/renders)
# env:   DEPOTWIN_BUILD_DIR (default <repo>/build; built with scripts/build.sh when the
#        depotwin binary is missing)
#        DEPOTWIN_RENDER_SCENARIOS: scenario names to render (space-separated; default: all)
#        DEPOTWIN_RENDER_SWEEPS: parameter studies of scenarios/sweeps/ whose summary.png goes
#        to OUTDIR/sweeps/<name>/ (space-separated; default: corner_study; "none": none)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out_dir="${1:-$root/renders}"
build_dir="${DEPOTWIN_BUILD_DIR:-$root/build}"
depotwin="$build_dir/depotwin"

# the binary, built when missing
if [[ ! -x "$depotwin" ]]; then
  echo "render-examples: $depotwin missing, building" >&2
  DEPOTWIN_BUILD_DIR="$build_dir" "$root/scripts/build.sh" >&2
fi

# the images copied per run
run_images=(scene.png thickness.png path.png axes.png errors.png thickness_profile.png joints.png
  layers.png paths3d.png)
# images that show only the deposit, which is the same for every print order
deposit_images=(scene.png thickness.png thickness_profile.png)

work_dir="$(mktemp -d "${TMPDIR:-/tmp}/depotwin-renders.XXXXXX")"
trap 'rm -rf "$work_dir"' EXIT
mkdir -p "$out_dir"

shopt -s nullglob
scenario_files=("$root"/scenarios/*.yaml)
[[ ${#scenario_files[@]} -gt 0 ]] || { echo "render-examples: no scenarios in $root/scenarios" >&2; exit 2; }

for scenario_file in "${scenario_files[@]}"; do
  name="$(basename "$scenario_file" .yaml)"
  if [[ -n "${DEPOTWIN_RENDER_SCENARIOS:-}" && " $DEPOTWIN_RENDER_SCENARIOS " != *" $name "* ]]; then
    continue
  fi
  # per-scenario compare flags; an order comparison keeps the deposit images of one order
  # only (the orders print the same lines), which keeps renders/ under about 5 MB
  compare_flags=()
  deposit_run=""
  case "$name" in
    ganganath_n20)
      compare_flags=(--orders "as_given,nearest_neighbor,christofides+three_opt")
      deposit_run="christofides+three_opt"
      ;;
  esac

  start_s=$SECONDS
  raw="$work_dir/$name"
  (cd "$root" && "$depotwin" compare "scenarios/$name.yaml" --out "$raw" --quiet \
    "${compare_flags[@]}" >"$work_dir/$name.log" 2>&1) || {
    cat "$work_dir/$name.log" >&2
    echo "render-examples: depotwin compare failed for $name" >&2
    exit 1
  }

  # exactly regenerated: the scenario folder is emptied first
  target="$out_dir/$name"
  rm -rf "$target"
  mkdir -p "$target"
  cp "$raw/comparison.png" "$target/"

  runs=()
  for run_path in "$raw"/*/; do
    run="$(basename "$run_path")"
    runs+=("$run")
    mkdir -p "$target/$run"
    for image in "${run_images[@]}"; do
      [[ -f "$raw/$run/$image" ]] || continue
      if [[ -n "$deposit_run" && "$run" != "$deposit_run" ]] &&
        [[ " ${deposit_images[*]} " == *" $image "* ]]; then
        continue
      fi
      cp "$raw/$run/$image" "$target/$run/"
    done
  done

  # comparison.md with only the links whose file was copied
  (cd "$target" && perl -pe '
    if (/^- \*\*/) {
      my ($head, $list) = /^(- \*\*[^*]*\*\*: )(.*)$/;
      if (defined $list) {
        my @kept = grep { /\]\(([^)]*)\)/ && -f $1 } split /, /, $list;
        $_ = $head . join(", ", @kept) . "\n";
      }
    }' "$raw/comparison.md" >"$target/comparison.md")

  files=$(find "$target" -type f | wc -l)
  size=$(du -sk "$target" | cut -f1)
  printf 'render-examples: %-20s %d runs, %2d files, %5d KiB, %3d s\n' "$name" "${#runs[@]}" \
    "$files" "$size" "$((SECONDS - start_s))"
done

# parameter studies: the sweep run on every core, its summary.png kept
for name in ${DEPOTWIN_RENDER_SWEEPS:-corner_study}; do
  [[ "$name" == none ]] && continue
  start_s=$SECONDS
  raw="$work_dir/sweeps/$name"
  (cd "$root" && "$depotwin" sweep "scenarios/sweeps/$name.yaml" --out "$raw" --quiet \
    -j "$(nproc)" >"$work_dir/sweep-$name.log" 2>&1) || {
    cat "$work_dir/sweep-$name.log" >&2
    echo "render-examples: depotwin sweep failed for $name" >&2
    exit 1
  }
  target="$out_dir/sweeps/$name"
  rm -rf "$target"
  mkdir -p "$target"
  cp "$raw/summary.png" "$target/"
  printf 'render-examples: %-20s sweep, summary.png, %5d KiB, %3d s\n' "$name" \
    "$(du -sk "$target" | cut -f1)" "$((SECONDS - start_s))"
done

echo "render-examples: $(du -sh "$out_dir" | cut -f1) in $out_dir"
