#!/usr/bin/env bash
# `hairgen diff A.hair B.hair` as scripts and the goldens use it: exit 0 for the same hair, 4 for hair
# beyond the tolerance or of another structure (with the figures and the reason on stdout), 2 for a cache
# against an image, a flag of the other kind, or an unreadable file; the same caches in another format
# compare equal. The help and the errors name exactly the cache formats diff reads: not .usda, which
# hairgen only writes.
source "$(dirname "$0")/cli_lib.sh" "$@"

fixture="$src/golden/fixtures/guides-default-quarter.hair"
setup="$src/configs/default/setup.txt"

case "$case" in
same_and_moved)
  expect_rc 0 "$hairgen" diff "$fixture" "$fixture"
  grep -q "^  points: mean 0 m  max 0 m" "$tmp/out" || fail "no zero distances: $(cat "$tmp/out")"
  # The same guides grown by Rosenbrock's search instead of BFGS: points move, roots do not.
  expect_rc 0 "$hairgen" grow "$setup" --shard 1/4 -o "$tmp/moved.hair" --quiet --set Hairstyle.VisualityStep=0.02 \
    --set Hairstyle.Minimiser=rosenbrock
  expect_rc 4 "$hairgen" diff "$fixture" "$tmp/moved.hair"
  grep -q "^FAIL: point [0-9]* of strand [0-9]* is .* m from the reference's (tolerance 1e-05 m)" "$tmp/out" ||
    fail "no located failure: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" diff "$fixture" "$tmp/moved.hair" --tolerance 10
  ;;
structure)
  # The same guides as ASCII PLY compare equal; with strand 0's root moved along x by 10 µm they fail
  # whatever the tolerance, and with one strand less too.
  expect_rc 0 "$hairgen" convert "$fixture" "$tmp/same.ply" --ascii --quiet
  expect_rc 0 "$hairgen" diff "$fixture" "$tmp/same.ply"
  header=$(grep -n -m1 '^end_header' "$tmp/same.ply" | cut -d: -f1)
  awk -v root=$((header + 1)) 'NR == root { $1 = $1 + 1e-5 } { print }' "$tmp/same.ply" >"$tmp/root.ply"
  expect_rc 4 "$hairgen" diff "$fixture" "$tmp/root.ply" --tolerance 10
  grep -q "^FAIL: strand 0's root moved" "$tmp/out" || fail "roots not compared exactly: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" grow "$setup" --shard 2/4 -o "$tmp/other.hair" --quiet --set Hairstyle.VisualityStep=0.02
  expect_rc 4 "$hairgen" diff "$fixture" "$tmp/other.hair" --tolerance 10
  grep -q "^FAIL: the reference has 189 strands, the other 190" "$tmp/out" || fail "strand count: $(cat "$tmp/out")"
  ;;
usage)
  expect_rc 2 "$hairgen" diff "$fixture" "$src/golden/default/reference.exr"
  expect_err "is a hair cache and"
  expect_rc 2 "$hairgen" diff "$fixture" "$fixture" --hardfail 0.1
  expect_err "--hardfail applies to images"
  expect_rc 2 "$hairgen" diff "$src/golden/default/reference.exr" "$src/golden/default/reference.exr" --tolerance 1
  expect_err "--tolerance applies to hair caches"
  expect_rc 2 "$hairgen" diff "$fixture" "$tmp/absent.hair"
  ;;
formats)
  readable=".hair, .gltf, .glb, .ply, .data"
  expect_rc 0 "$hairgen" diff --help
  grep -qF "a hair cache ($readable)" "$tmp/out" || fail "help lists other formats: $(grep -F cache "$tmp/out")"
  expect_rc 0 "$hairgen" convert "$fixture" "$tmp/guides.usda" --quiet
  expect_rc 2 "$hairgen" diff "$fixture" "$tmp/guides.usda"
  expect_err "$tmp/guides.usda: diff reads hair caches ($readable) and images; hairgen writes USD"
  expect_rc 2 "$hairgen" diff "$fixture" "$src/golden/default/reference.exr"
  expect_err "compare two images or two caches ($readable)"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
