#!/usr/bin/env bash
# What DCCs and players read from hairgen's movies and EXRs (issue 36): the MP4 tagged BT.709 and
# converted with BT.709's matrix, the GIF at the frames' size, each frame's EXR carrying its frame
# number and OpenEXR's framesPerSecond, the light's deep opacity maps as the layer dom.
# Usage: formats_test.sh HAIRGEN SOURCE_DIR CASE
source "$(dirname "$0")/cli_lib.sh" "$@"

gust="$src/configs/anjyo/gust/setup.txt"
small=(--quiet --set Hairstyle.HairDensity=5 --set "Render.Resolution=40 40")
# Three flat frames of 64x48 pixels, 8-bit sRGB red (255, 0, 0), named f.0001.png to f.0003.png.
red_frames() {
  ffmpeg -v error -f lavfi -i "color=c=0xff0000:size=64x48:rate=1" -frames:v 3 -start_number 1 "$tmp/f.%04d.png" ||
    fail "ffmpeg cannot make the frames"
}

case "$case" in
movie_bt709)
  # ffprobe reads BT.709 tags, and the luma of pure red is BT.709's, 16 + 219 x 0.2126 = 62.6 in
  # limited range (BT.601's would be 16 + 219 x 0.299 = 81.5).
  command -v ffprobe >/dev/null || skip "no ffmpeg here (scripts/setup.sh installs it)"
  red_frames
  expect_rc 0 "$hairgen" movie "$tmp/f.####.png" --frames 1-3 -o "$tmp/m.mp4"
  tags=$(ffprobe -v error -select_streams v:0 \
    -show_entries stream=color_space,color_primaries,color_transfer,color_range -of csv=p=0 "file:$tmp/m.mp4")
  [ "$tags" = "tv,bt709,bt709,bt709" ] || fail "the movie's colour tags are '$tags', not tv,bt709,bt709,bt709"
  ffmpeg -v error -i "file:$tmp/m.mp4" -frames:v 1 -f rawvideo -pix_fmt yuv420p "$tmp/y.yuv" || fail "cannot decode"
  luma=$(od -An -tu1 -j $((48 * 64 / 2 + 32)) -N1 "$tmp/y.yuv" | tr -d ' ')
  [ "$luma" -ge 61 ] && [ "$luma" -le 64 ] || fail "pure red has luma $luma, not BT.709's 62.6"
  ;;
gif_frame_size)
  # The GIF is the frames' size, not scaled up or down.
  command -v ffprobe >/dev/null || skip "no ffmpeg here (scripts/setup.sh installs it)"
  red_frames
  expect_rc 0 "$hairgen" movie "$tmp/f.####.png" --frames 1-3 -o "$tmp/m.mp4" --gif "$tmp/m.gif"
  size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=p=0 "file:$tmp/m.gif")
  [ "$size" = "64,48" ] || fail "the GIF is $size, not the frames' 64,48"
  ;;
exr_frame_rate)
  # Each frame of a shot (run, and render --frames) names its frame and the shot's rate; a still neither.
  command -v exrheader >/dev/null || skip "no exrheader here (Debian's openexr)"
  expect_rc 0 "$hairgen" run "$gust" -o "$tmp/run" "${small[@]}" --set "Dynamics.Frames=1 3" --set Dynamics.FrameRate=25
  for f in 1 2 3; do
    exrheader "$tmp/run/beauty.000$f.exr" >"$tmp/h" || fail "exrheader cannot read frame $f"
    grep -q "hairgen:frame (type int): $f\$" "$tmp/h" || fail "frame $f's EXR lacks its frame: $(cat "$tmp/h")"
    grep -q "framesPerSecond (type rational): 25/1" "$tmp/h" || fail "frame $f's EXR lacks framesPerSecond 25/1"
  done
  expect_rc 0 "$hairgen" render "$gust" --guides "$tmp/run/sim/guides.####.hair" -o "$tmp/r.####.exr" --frames 2-3 \
    --rest "$tmp/run/shaded.hair" "${small[@]}" --set Dynamics.FrameRate=23.976
  exrheader "$tmp/r.0003.exr" >"$tmp/h" || fail "exrheader cannot read render's frame 3"
  grep -q "hairgen:frame (type int): 3\$" "$tmp/h" || fail "render --frames: no frame number: $(cat "$tmp/h")"
  grep -q "framesPerSecond (type rational): 24000/1001" "$tmp/h" || fail "23.976 fps is not 24000/1001: $(grep -i frames "$tmp/h")"
  expect_rc 0 "$hairgen" render "$gust" --hair "$tmp/run/shaded.hair" -o "$tmp/still.exr" "${small[@]}"
  exrheader "$tmp/still.exr" >"$tmp/h"
  ! grep -q "hairgen:frame\|framesPerSecond" "$tmp/h" || fail "a still names a frame"
  ;;
dom_layers)
  # The light's deep opacity maps: Z and the layer dom's channels layer1-4, as Nuke sorts them.
  command -v exrheader >/dev/null || skip "no exrheader here (Debian's openexr)"
  expect_rc 0 "$hairgen" run "$gust" -o "$tmp/run" "${small[@]}" --no-render
  expect_rc 0 "$hairgen" render "$gust" --hair "$tmp/run/coupe.hair" -o "$tmp/b.exr" --dom "$tmp/dom.exr" "${small[@]}"
  exrheader "$tmp/dom.exr" >"$tmp/h" || fail "exrheader cannot read the maps"
  for c in Z dom.layer1 dom.layer2 dom.layer3 dom.layer4; do
    grep -q "^ *$c, 32-bit floating-point" "$tmp/h" || fail "the maps lack channel $c: $(cat "$tmp/h")"
  done
  ! grep -q "^ *layer1," "$tmp/h" || fail "a bare layer1 channel is left"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
