#!/usr/bin/env bash
# One golden case: runs golden/CASE/case.sh's command into the build tree and compares its image with
# golden/CASE/reference.exr by `hairgen diff` (default thresholds). On failure WORK/CASE keeps the
# rendered image, a copy of the reference, the difference (diff.exr) and the three side by side
# (sheet.png: reference | rendered | 10 × difference) for a person to look at.
# Usage: golden_test.sh HAIRGEN SOURCE_DIR CASE WORK
set -uo pipefail
hairgen=$1 src=$2 case=$3 work=$4
dir="$src/golden/$case"
out="$work/$case"
rm -rf "$out" && mkdir -p "$out"
# shellcheck source=/dev/null
source "$dir/case.sh"
[ -f "$dir/reference.exr" ] || { echo "golden $case: no reference.exr; run scripts/update-golden.sh $case"; exit 1; }
"$hairgen" "${args[@]}" || { echo "golden $case: the command failed"; exit 1; }
if report=$("$hairgen" diff "$dir/reference.exr" "$image"); then
  # diff compares the reference's channels by name: it must have compared the beauty and every AOV layer.
  for channel in R G B A Z opacity.Y shadow.Y; do
    grep -q "^  $channel: mean" <<<"$report" || { echo "golden $case: the comparison did not cover $channel"; exit 1; }
  done
  exit 0
fi
cp "$dir/reference.exr" "$out/reference.exr"
"$hairgen" diff "$dir/reference.exr" "$image" --out "$out/diff.exr" --sheet "$out/sheet.png"
echo "golden $case: differs from its reference; look at $out/sheet.png (reference | rendered | 10 x difference)"
exit 1
