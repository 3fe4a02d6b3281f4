#!/usr/bin/env bash
# Issue 36: a shot's frames as one animated USD stage, read back by an independent reader (TinyUSDZ:
# the time codes and rate of the shot, every frame's points equal to its cache); convert --frames for
# every format; shade --vdb on a sequence; one-point strands left out of USD with a count. Errors are
# one line, exit 2, nothing written.
source "$(dirname "$0")/cli_lib.sh" "$@"

gust="$src/configs/anjyo/gust/setup.txt"
reader="$src/tools/node_modules/tinyusdz"
# A small shot at 30 frames a second (not USD's default 24, so a rate read from nowhere shows).
small=(--quiet --set Hairstyle.HairDensity=4 --set "Dynamics.Frames=1 3" --set Dynamics.FrameRate=30)

simulated() { # the gust's guides simulated into $tmp/sim/g.####.hair
  expect_rc 0 "$hairgen" grow "$gust" -o "$tmp/g.hair" "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$gust" --guides "$tmp/g.hair" -o "$tmp/sim/g.####.hair" "${small[@]}"
}
need_reader() {
  [ -f "$reader/tinyusdz.wasm" ] || skip "tinyusdz is not installed (scripts/setup.sh installs it)"
  command -v node >/dev/null || skip "no node"
}
# validate FILE PRIM FIRST LAST FPS PLY_PATTERN: TinyUSDZ against the frames' ASCII PLYs.
validate() {
  node "$src/tests/validate_usd_shot.mjs" "$reader" "$@" >"$tmp/v" 2>&1 || fail "$(cat "$tmp/v")"
  cat "$tmp/v"
}

case "$case" in
stage_guides)
  # The simulated guides as one stage: time codes 1-3 at the caches' 30 fps, marked as guides, every
  # frame's points those of its cache.
  need_reader
  simulated
  expect_rc 0 "$hairgen" convert "$tmp/sim/g.####.hair" --frames 1-3 -o "$tmp/shot.usda"
  grep -q "int primvars:groom_guide = 1" "$tmp/shot.usda" || fail "the guides are not marked groom_guide"
  expect_rc 0 "$hairgen" convert "$tmp/sim/g.####.hair" "$tmp/p.####.ply" --ascii --frames 1-3 --quiet
  validate "$tmp/shot.usda" guides 1 3 30 "$tmp/p.####.ply"
  expect_rc 0 "$hairgen" info "$tmp/shot.usda"
  grep -q "timeCodesPerSecond: 30" "$tmp/out" || fail "info does not say the rate: $(cat "$tmp/out")"
  ;;
stage_coupe_and_guides)
  # The coupe's frames and the guides' in one stage, the coupe's closest guides naming guide ids that
  # the guides prim holds; and the rest coupe beside the moving guides (Unreal's guide cache).
  need_reader
  simulated
  expect_rc 0 "$hairgen" interpolate "$gust" --guides "$tmp/sim/g.####.hair" -o "$tmp/c.####.hair" --frames 1-3 "${small[@]}"
  expect_rc 0 "$hairgen" convert "$tmp/c.####.hair" --guides "$tmp/sim/g.####.hair" --frames 2-3 -o "$tmp/shot.usda" --quiet
  expect_rc 0 "$hairgen" convert "$tmp/c.####.hair" "$tmp/c.####.ply" --ascii --frames 2-3 --quiet
  expect_rc 0 "$hairgen" convert "$tmp/sim/g.####.hair" "$tmp/g.####.ply" --ascii --frames 1-3 --quiet
  validate "$tmp/shot.usda" strands 2 3 30 "$tmp/c.####.ply"
  validate "$tmp/shot.usda" guides 2 3 30 "$tmp/g.####.ply"
  python3 - "$tmp/shot.usda" <<'EOF' || fail "groom_closest_guides name guides the stage does not hold"
import re, sys
text = open(sys.argv[1]).read()
strands, guides = text.split('def BasisCurves "guides"')
ids = set(map(int, re.search(r"groom_id = \[([^\]]*)\]", guides).group(1).split(",")))
closest = set(map(int, re.findall(r"-?\d+", re.search(r"groom_closest_guides = \[([^\]]*)\]", strands).group(1))))
sys.exit(0 if closest and closest <= ids else 1)
EOF
  # The rest coupe (no ####) beside the moving guides: the strands are not time-sampled.
  expect_rc 0 "$hairgen" convert "$tmp/c.0001.hair" --guides "$tmp/sim/g.####.hair" --frames 1-3 -o "$tmp/rest.usda" --quiet
  awk '/def BasisCurves "guides"/ { exit } /points.timeSamples/ { bad = 1 } END { exit bad }' "$tmp/rest.usda" ||
    fail "the rest coupe is time-sampled"
  validate "$tmp/rest.usda" guides 1 3 30 "$tmp/g.####.ply"
  ;;
run_writes_stage)
  # run on a shot writes DIR/shot.usda: the guides of the frames it wrote at Dynamics FrameRate.
  need_reader
  expect_rc 0 "$hairgen" run "$gust" -o "$tmp/run" --no-render --frames 2-3 "${small[@]}"
  [ -s "$tmp/run/shot.usda" ] || fail "run wrote no shot.usda: $(ls "$tmp/run")"
  expect_rc 0 "$hairgen" convert "$tmp/run/sim/guides.####.hair" "$tmp/g.####.ply" --ascii --frames 2-3 --quiet
  validate "$tmp/run/shot.usda" guides 2 3 30 "$tmp/g.####.ply"
  grep -q 'def BasisCurves "strands"' "$tmp/run/shot.usda" || fail "run's stage has no rest coupe"
  ;;
convert_frames_formats)
  # convert --frames writes every frame in every format, each frame the strands of its cache.
  simulated
  for ext in hair gltf glb ply data usda; do
    expect_rc 0 "$hairgen" convert "$tmp/sim/g.####.hair" "$tmp/$ext/f.####.$ext" --frames 1-3 --quiet
    for f in 0001 0002 0003; do [ -s "$tmp/$ext/f.$f.$ext" ] || fail "no frame $f as .$ext"; done
  done
  for ext in gltf glb ply data; do
    expect_rc 0 "$hairgen" convert "$tmp/$ext/f.####.$ext" "$tmp/back.####.hair" --frames 3-3 --quiet
    "$hairgen" info "$tmp/back.0003.hair" | sed -n 2p > "$tmp/a"
    "$hairgen" info "$tmp/sim/g.0003.hair" | sed -n 2p > "$tmp/b"
    cmp -s "$tmp/a" "$tmp/b" || fail ".$ext frame 3: $(cat "$tmp/a") vs $(cat "$tmp/b")"
  done
  ;;
convert_frames_errors)
  # A missing frame, a name without ####, --guides without a stage: one line, exit 2, nothing written.
  simulated
  expect_rc 2 "$hairgen" convert "$tmp/sim/g.####.hair" "$tmp/o/f.####.ply" --frames 1-4
  expect_err "g.0004.hair: cannot open: frame 4 of --frames 1-4 is missing"
  [ "$(wc -l < "$tmp/err")" -eq 1 ] || fail "not one line: $(cat "$tmp/err")"
  [ ! -e "$tmp/o" ] || [ -z "$(ls -A "$tmp/o")" ] || fail "a refused convert wrote $(ls "$tmp/o")"
  expect_rc 2 "$hairgen" convert "$tmp/sim/g.####.hair" --frames 1-4 -o "$tmp/shot.usda"
  expect_err "g.0004.hair: cannot open"
  [ ! -e "$tmp/shot.usda" ] || fail "a refused stage was written"
  expect_rc 2 "$hairgen" convert "$tmp/sim/g.####.hair" "$tmp/f.ply" --frames 1-3
  expect_err "f.ply: with --frames, OUT needs #### where the frame number goes"
  expect_rc 2 "$hairgen" convert "$tmp/g.hair" --frames 1-3 -o "$tmp/shot.usda"
  expect_err "with --frames, IN needs ####"
  expect_rc 2 "$hairgen" convert "$tmp/g.hair" "$tmp/g.usda" --guides "$tmp/sim/g.####.hair"
  expect_err "--guides is for one animated stage"
  # Caches that do not say their frame and time: the rate is asked for, and --fps gives it.
  expect_rc 0 "$hairgen" convert "$tmp/sim/g.####.hair" "$tmp/d.####.data" --frames 1-3 --quiet
  expect_rc 2 "$hairgen" convert "$tmp/d.####.data" --frames 1-3 -o "$tmp/d.usda"
  expect_err "give --fps"
  expect_rc 0 "$hairgen" convert "$tmp/d.####.data" --frames 1-3 -o "$tmp/d.usda" --fps 25 --quiet
  grep -q "timeCodesPerSecond = 25$" "$tmp/d.usda" || fail "--fps 25 is not the stage's rate"
  ;;
one_point_strands)
  # USC-HairSalon's bare follicles (one-point strands) are no USD curves: left out with a count on
  # stderr, the rest written; a stage of them too.
  python3 - "$tmp/h.0001.data" "$tmp/h.0002.data" <<'EOF'
import struct, sys
for name in sys.argv[1:]:
    counts = [3, 1, 2, 1]
    body = struct.pack("<i", len(counts))
    for i, c in enumerate(counts):
        body += struct.pack("<i", c) + b"".join(struct.pack("<3f", i, k * 0.01, 0) for k in range(c))
    open(name, "wb").write(body)
EOF
  expect_rc 0 "$hairgen" convert "$tmp/h.0001.data" "$tmp/h.usda"
  expect_err "2 strand(s) of fewer than two points (bare follicles) left out"
  grep -q "int\[\] curveVertexCounts = \[3,2\]" "$tmp/h.usda" || fail "the curves left: $(grep curveVertexCounts "$tmp/h.usda")"
  expect_rc 0 "$hairgen" convert "$tmp/h.####.data" --frames 1-2 -o "$tmp/hs.usda" --fps 24 --quiet
  expect_err "2 strand(s) of fewer than two points"
  # glTF likewise: a one-point strand would be a loose vertex readers join to the strand before it.
  expect_rc 0 "$hairgen" convert "$tmp/h.0001.data" "$tmp/h.glb"
  expect_err "h.glb: 2 strand(s) of fewer than two points (bare follicles) left out"
  if [ -f "$reader/tinyusdz.wasm" ] && command -v node >/dev/null; then
    "$hairgen" info "$tmp/h.usda" >/dev/null || fail "info cannot read the header"
    node "$src/tests/validate_usd.mjs" "$reader" "$tmp/h.usda" /dev/stdin <<<'{"strands":2,"points":5,"attributes":[],"defaults":{"thickness":7e-05},"units":"unknown","upAxis":"unknown"}' >"$tmp/v" 2>&1 ||
      fail "TinyUSDZ: $(cat "$tmp/v")"
  fi
  ;;
shade_vdb_frames)
  # shade --vdb on a sequence: each frame its shaded coupe and its volume.
  simulated
  expect_rc 0 "$hairgen" interpolate "$gust" --guides "$tmp/sim/g.####.hair" -o "$tmp/c.####.hair" --frames 1-2 "${small[@]}"
  expect_rc 0 "$hairgen" shade "$gust" --hair "$tmp/c.####.hair" -o "$tmp/s.####.hair" --vdb "$tmp/v.####.vdb" \
    --frames 1-2 "${small[@]}" --set Render.ShadingModel=volumetric
  for f in 0001 0002; do
    [ -s "$tmp/s.$f.hair" ] && [ -s "$tmp/v.$f.vdb" ] || fail "frame $f: $(ls "$tmp")"
  done
  "$hairgen" info "$tmp/s.0002.hair" | grep -q "normals" || fail "frame 2 is not shaded"
  cmp -s "$tmp/v.0001.vdb" "$tmp/v.0002.vdb" && fail "the frames' volumes are the same: the hair moved"
  expect_rc 2 "$hairgen" shade "$gust" --hair "$tmp/c.####.hair" -o "$tmp/t.####.hair" --vdb "$tmp/w.vdb" \
    --frames 1-2 "${small[@]}"
  expect_err "each frame has its volume"
  [ "$(wc -l < "$tmp/err")" -eq 1 ] && [ ! -e "$tmp/t.0001.hair" ] && [ ! -e "$tmp/w.vdb" ] ||
    fail "a refused shade: $(cat "$tmp/err"); $(ls "$tmp")"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
