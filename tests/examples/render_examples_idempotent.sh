#!/usr/bin/env bash
# scripts/render-examples.sh is deterministic: two runs into two fresh folders give the same
# file list and the same bytes in every file (so regenerating renders/ leaves git clean).
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
