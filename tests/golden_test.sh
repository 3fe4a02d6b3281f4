#!/usr/bin/env bash
# One golden case (golden/README.md): runs golden/CASE/case.sh's `produce` into WORK/CASE, then
# - a stage case (case.sh names a `cache`): compares it with golden/CASE/reference.hair by `hairgen diff`
#   (strand count, points per strand and roots exactly, points within diff's tolerance, normals and
#   colours), then runs the case's `check` (the stage's invariants, by STAGE_INVARIANTS);
# - a render case (case.sh names an `image`): compares it with golden/CASE/reference.exr by `hairgen diff`
#   (default thresholds). On failure WORK/CASE keeps the rendered image, a copy of the reference, the
#   difference (diff.exr) and the three side by side (sheet.png: reference | rendered | 10 × difference).
# A case that cannot run here (no rendering device: exit 3) exits 77, which ctest reports as skipped.
# Usage: golden_test.sh HAIRGEN SOURCE_DIR CASE WORK STAGE_INVARIANTS
set -uo pipefail
hairgen=$1 src=$2 case=$3 work=$4 invariants=$5
dir="$src/golden/$case"
out="$work/$case"
rm -rf "$out" && mkdir -p "$out"
cache="" image=""
# shellcheck source=/dev/null
source "$dir/case.sh"
fail() { echo "golden $case: $*"; exit 1; }
if [ -n "$cache" ]; then reference="$dir/reference.hair"; else reference="$dir/reference.exr"; fi
[ -f "$reference" ] || fail "no $(basename "$reference"); run scripts/update-golden.sh $case"
produce
rc=$?
if [ "$rc" -eq 3 ]; then
  echo "SKIP (golden $case): no rendering device could be opened"
  exit 77
fi
[ "$rc" -eq 0 ] || fail "the command failed (exit $rc)"

if [ -n "$cache" ]; then
  "$hairgen" diff "$reference" "$cache" || fail "differs from its reference (above)"
  if declare -F check >/dev/null; then check || fail "an invariant of the $stage stage fails (above)"; fi
  exit 0
fi
if report=$("$hairgen" diff "$reference" "$image"); then
  # diff compares the reference's channels by name: it must have compared the beauty and every AOV layer.
  for channel in R G B A Z opacity.Y shadow.Y; do
    grep -q "^  $channel: mean" <<<"$report" || fail "the comparison did not cover $channel"
  done
  exit 0
fi
cp "$reference" "$out/reference.exr"
"$hairgen" diff "$reference" "$image" --out "$out/diff.exr" --sheet "$out/sheet.png"
fail "differs from its reference; look at $out/sheet.png (reference | rendered | 10 x difference)"
