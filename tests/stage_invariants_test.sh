#!/usr/bin/env bash
# The goldens' invariant checker (tests/stage_invariants.cpp) is not vacuous: each check holds on what the
# stage makes and fails on what breaks it (roots off the scalp, a stretched segment, moved points or
# missing normals), and refuses bad usage with exit 2.
# Usage: stage_invariants_test.sh HAIRGEN SOURCE_DIR CASE STAGE_INVARIANTS
source "$(dirname "$0")/cli_lib.sh" "$@"
invariants=$4
fixtures="$src/golden/fixtures"
wick="$src/configs/assets/wick.obj"

case "$case" in
roots)
  expect_rc 0 "$invariants" roots-on-mesh "$fixtures/coupe-default.hair" "$wick"
  # The same roots against the head mesh, whose surface lies up to a millimetre from the scalp's.
  expect_rc 1 "$invariants" roots-on-mesh "$fixtures/coupe-default.hair" "$src/configs/assets/head.obj"
  grep -q "^FAILS: 491 roots on the mesh" "$tmp/out" || fail "no failure line: $(cat "$tmp/out")"
  ;;
segments)
  springs="$src/configs/pixar/wind/setup.txt" rest="$fixtures/guides-default-quarter.hair"
  expect_rc 0 "$hairgen" simulate "$springs" --guides "$rest" --frames 1-3 -o "$tmp/g.####.hair" --quiet
  expect_rc 0 "$invariants" segments-kept "$tmp/g.0003.hair" "$rest" 0.002
  # The springs stretch by up to 0.1%: a limit of 0.01% fails, and so do other strands.
  expect_rc 1 "$invariants" segments-kept "$tmp/g.0003.hair" "$rest" 0.0001
  expect_rc 1 "$invariants" segments-kept "$tmp/g.0003.hair" "$fixtures/guides-bob-quarter.hair" 0.5
  ;;
points)
  expect_rc 0 "$hairgen" shade "$src/configs/default/setup.txt" --hair "$fixtures/coupe-default.hair" \
    -o "$tmp/s.hair" --quiet --set Render.ShadingModel=volumetric
  expect_rc 0 "$invariants" points-kept "$tmp/s.hair" "$fixtures/coupe-default.hair"
  expect_rc 1 "$invariants" points-kept "$fixtures/coupe-default.hair" "$fixtures/coupe-default.hair"  # no normals
  expect_rc 1 "$invariants" points-kept "$tmp/s.hair" "$fixtures/guides-default.hair"
  ;;
usage)
  expect_rc 2 "$invariants" roots-on-mesh "$fixtures/coupe-default.hair"
  expect_rc 2 "$invariants" segments-kept "$fixtures/coupe-default.hair" "$fixtures/coupe-default.hair" much
  expect_rc 2 "$invariants" roots-on-mesh "$tmp/absent.hair" "$wick"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
