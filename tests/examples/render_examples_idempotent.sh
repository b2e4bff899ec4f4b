#!/usr/bin/env bash
# scripts/render-examples.sh is deterministic: two runs into two fresh folders give the same
# file list and the same bytes in every file (so regenerating renders/ leaves git clean), and in
# the normal build its comparison tables equal the committed renders/ ones (not stale).
# Every scenario but the two long arm jobs (shembekar_beam, shembekar_bonnet: minutes each; the
# arm's determinism is checked on shembekar_fillet here and by the arm pipeline tests).
set -euo pipefail
export DEPOTWIN_RENDER_SCENARIOS="${DEPOTWIN_RENDER_SCENARIOS:-$(
  cd "$(dirname "${BASH_SOURCE[0]}")/../../scenarios" &&
    for f in *.yaml; do
      name="${f%.yaml}"
      [[ "$name" == shembekar_beam || "$name" == shembekar_bonnet ]] || printf '%s ' "$name"
    done
)}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/depotwin-idempotent.XXXXXX")"
trap 'rm -rf "$work"' EXIT

"$root/scripts/render-examples.sh" "$work/first"
# the second run goes into a folder holding stale files: it must leave exactly the same tree
mkdir -p "$work/second/thompson_fig7/lspb_mtt"
echo stale >"$work/second/thompson_fig7/stale.png"
echo stale >"$work/second/thompson_fig7/lspb_mtt/scene.png"
"$root/scripts/render-examples.sh" "$work/second"

listing() { (cd "$1" && find . -type f | LC_ALL=C sort); }
checksums() { (cd "$1" && find . -type f -print0 | LC_ALL=C sort -z | xargs -0 sha256sum); }

# every scenario rendered has its folder with a comparison sheet
for name in $DEPOTWIN_RENDER_SCENARIOS; do
  for file in comparison.png comparison.md; do
    [[ -s "$work/first/$name/$file" ]] || { echo "missing $name/$file"; exit 1; }
  done
done

if ! diff <(listing "$work/first") <(listing "$work/second"); then
  echo "FAIL: the file lists differ"
  exit 1
fi
if ! diff <(checksums "$work/first") <(checksums "$work/second"); then
  echo "FAIL: file contents differ"
  exit 1
fi
# every link in a comparison.md points at a copied file
while IFS= read -r md; do
  dir="$(dirname "$md")"
  while IFS= read -r link; do
    [[ -f "$dir/$link" ]] || { echo "FAIL: $md links to missing $link"; exit 1; }
  done < <(grep -o '](\([^)]*\))' "$md" | sed 's/^](\(.*\))$/\1/')
done < <(find "$work/first" -name comparison.md)
echo "identical: $(listing "$work/first" | wc -l) files"

# and the committed renders/ is what the code gives now: every comparison table regenerated
# equals the committed one (DEPOTWIN_RENDER_CHECK_COMMITTED=1, set for the normal build: a
# sanitizer or fuzz build's optimisation may round a last printed digit differently)
if [[ "${DEPOTWIN_RENDER_CHECK_COMMITTED:-0}" == 1 ]]; then
  stale=0
  for name in $DEPOTWIN_RENDER_SCENARIOS; do
    committed="$root/renders/$name/comparison.md"
    if [[ ! -f "$committed" ]]; then
      echo "FAIL: renders/$name/comparison.md is not committed"
      stale=1
    elif ! diff -u "$committed" "$work/first/$name/comparison.md"; then
      echo "FAIL: renders/$name/comparison.md is stale"
      stale=1
    fi
  done
  if [[ $stale == 1 ]]; then
    echo "regenerate with scripts/render-examples.sh and commit renders/"
    exit 1
  fi
  echo "committed comparison tables current: $DEPOTWIN_RENDER_SCENARIOS"
fi
