#!/usr/bin/env bash
# One device for a whole sequence (issue 34 item 5): `render --frames` keeps its context, programs and
# buffers from frame to frame, and each frame's files equal, byte for byte, that frame rendered alone
# in a process of its own, with and without sub-pixels, motion vectors and the light's maps (whose
# readback needs a larger buffer than the beauty's), while the head turns under its keys.
source "$(dirname "$0")/cli_lib.sh" "$@"

setup="$src/configs/pixar/headturn/setup.txt"
# Frames 10-13: the head starts turning at frame 10 (HeadKey 10 to 22), so it moves every frame.
small=(--quiet --set Hairstyle.HairDensity=5 --set "Dynamics.Frames=10 13" --set "Render.Resolution=64 48")

# render_sequence A B [flags...]: frames A to B of the simulated guides into $tmp/seq, each frame also
# alone into $tmp/alone, then compares every file.
render_sequence() {
  local first=$1 last=$2
  shift 2
  rm -rf "$tmp/seq" "$tmp/alone"
  expect_rc 0 "$hairgen" render "$setup" --guides "$tmp/sim/g.####.hair" --frames "$first-$last" \
    -o "$tmp/seq/b.####.exr" --dom "$tmp/seq/d.####.exr" "${small[@]}" "$@"
  for ((f = first; f <= last; ++f)); do
    expect_rc 0 "$hairgen" render "$setup" --guides "$tmp/sim/g.####.hair" --frames "$f-$f" \
      -o "$tmp/alone/b.####.exr" --dom "$tmp/alone/d.####.exr" "${small[@]}" "$@"
    local n
    n=$(printf %04d "$f")
    for file in "b.$n.exr" "d.$n.exr"; do
      cmp -s "$tmp/seq/$file" "$tmp/alone/$file" || fail "frame $f's $file differs from the frame alone ($*)"
    done
  done
}

case "$case" in
frames_equal_alone)
  expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/g.hair" "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/sim/g.####.hair" "${small[@]}"
  render_sequence 10 13 --set Render.Samples=1
  render_sequence 10 13 --set Render.Samples=4
  render_sequence 11 13 --set Render.Samples=1 --motion
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
