#!/usr/bin/env bash
# The renderer's memory on hostile sizes (issue 34's leftovers): `render --reference` keeps 64 fragments
# a sub-pixel at 8 x 8 sub-pixels, and what hairgen's rasteriser holds for that (each thread's slots for a
# band, the kept fragments' words, the per-pixel arrays) is counted before any work, so a size that
# cannot fit is refused with exit 2 and no image, and a modest one renders.
source "$(dirname "$0")/cli_lib.sh" "$@"

setup="$src/configs/thesis/coupe2/setup.txt"

case "$case" in
  reference_memory)
    command -v prlimit >/dev/null || skip "no prlimit here"
    expect_rc 0 "$hairgen" interpolate "$setup" --guides "$src/golden/fixtures/guides-coupe2.hair" \
      -o "$tmp/coupe.hair" --quiet --set Hairstyle.HairDensity=20
    # Under a 6 GB address space (about 4.4 GB left to the work once the GL driver is loaded) on two
    # threads: at 1600x900 the sub-pixel targets alone need 2.7 GB, which fit, and the rasteriser's
    # slots (1.5 GB) and per-sub-pixel arrays (1.5 GB) do not.
    limit=(prlimit --as=6000000000 "$hairgen")
    "${limit[@]}" render "$setup" --hair "$tmp/coupe.hair" -o "$tmp/small.exr" --quiet --threads 2 \
      --set "Render.Resolution=128 128" --reference 2>"$tmp/err"
    rc=$?
    [ "$rc" -eq 3 ] && skip "no rendering device here"
    [ "$rc" -eq 0 ] || fail "a modest render --reference exited $rc: $(cat "$tmp/err")"
    expect_rc 2 "${limit[@]}" render "$setup" --hair "$tmp/coupe.hair" -o "$tmp/large.exr" --quiet --threads 2 \
      --set "Render.Resolution=1600 900" --reference
    expect_err "render would need about"
    expect_err "Render.Resolution"
    [ -e "$tmp/large.exr" ] && fail "a refused render left an image"
    [ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "the refusal is not one line: $(cat "$tmp/err")"
    ;;
  *) fail "unknown case" ;;
esac
echo "ok ($case)"
