#!/usr/bin/env bash
# End-to-end checks of the hairgen command line: exit codes, messages, no partial output.
# Usage: cli_test.sh HAIRGEN SOURCE_DIR CASE
source "$(dirname "$0")/cli_lib.sh" "$@"

case "$case" in
help)
  expect_rc 0 "$hairgen" --help
  grep -q "Exit codes" "$tmp/out" || fail "--help lists no exit codes"
  for cmd in grow info convert check assets; do
    grep -q "^  $cmd" "$tmp/out" || fail "--help does not list $cmd"
  done
  for word in simulate farm; do grep -q "$word" "$tmp/out" || fail "--help's description omits $word"; done
  for cmd in grow info convert check assets; do
    expect_rc 0 "$hairgen" "$cmd" --help
    for flag in --threads --quiet --stats; do grep -q -- "$flag" "$tmp/out" || fail "$cmd --help lacks $flag"; done
  done
  for flag in --set --seed; do
    "$hairgen" check --help | grep -q -- "$flag" || fail "check --help lacks $flag"
  done
  # Every command and subcommand: human labels (N, FILE, A-B), not CLI11's types and validators; the
  # exit-code table once, in hairgen --help, and a pointer to it in each command's.
  commands=$("$hairgen" --help | sed -n '/^Subcommands:/,/^$/s/^  \([a-z]*\) .*/\1/p')
  [ "$(echo "$commands" | wc -w)" -ge 14 ] || fail "the command list was not read: $commands"
  for cmd in $commands "farm plan" "farm submit"; do
    # shellcheck disable=SC2086 # "farm plan" is two words
    expect_rc 0 "$hairgen" $cmd --help
    grep -E "^ +-.* (TEXT|INT|UINT|FLOAT)\b|^ +[A-Z]+ (TEXT|INT|FLOAT)|[A-Z]:[A-Z(]|AND \(|in \[" "$tmp/out" &&
      fail "$cmd --help shows a parser's type label"
    grep -q "^Exit codes: see hairgen --help" "$tmp/out" || fail "$cmd --help does not point at the exit codes"
    [ "$(grep -c '^  [0-9]  ' "$tmp/out")" -eq 0 ] || fail "$cmd --help repeats the exit-code table"
  done
  # Required positionals show as required; the descriptions say what the commands do.
  expect_rc 0 "$hairgen" render --help
  grep -q "Usage: hairgen render \[OPTIONS\] SETUP$" "$tmp/out" && grep -q "^  SETUP  *REQUIRED" "$tmp/out" ||
    fail "render --help does not show SETUP as required"
  for model in kajiya-kay thesis anjyo volumetric; do
    grep -q "$model" "$tmp/out" || fail "render --help does not name the shading model $model"
  done
  for flag in --frames --guides; do grep -q -- "$flag" "$tmp/out" || fail "render --help omits $flag"; done
  for cmd in check "farm plan" grow simulate; do
    # shellcheck disable=SC2086
    "$hairgen" $cmd --help | grep -q "^  SETUP  *REQUIRED" || fail "$cmd --help does not show SETUP as required"
  done
  expect_rc 0 "$hairgen" run --help
  grep -q "shaded.hair (only when the Setup shades)" "$tmp/out" || fail "run --help says shaded.hair is always written"
  grep -q "sim/guides.####.hair" "$tmp/out" && grep -q "beauty.mp4" "$tmp/out" ||
    fail "run --help does not say what a shot writes"
  # The flags that need no SETUP still work without one.
  expect_rc 0 "$hairgen" check --keys
  grep -q '^| `HairDensity` |' "$tmp/out" || fail "check --keys printed no keys"
  expect_rc 2 "$hairgen" check
  grep -q "SETUP is required" "$tmp/err" || fail "check without SETUP: $(cat "$tmp/err")"
  ;;
usage)
  expect_rc 2 "$hairgen"
  # A usage error is one line; a --set value the shell split, or one without '=', says how to write it.
  expect_rc 2 "$hairgen" check "$src/configs/default/setup.txt" --set Render.Resolution=320 320
  expect_err "quote it, --set 'Render.Resolution=320 320'"
  [ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "the usage error is not one line: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" check "$src/configs/default/setup.txt" --set Hairstyle.HairDensity 20
  expect_err "--set takes KEY=VALUE as one argument: --set 'Hairstyle.HairDensity=20'"
  expect_rc 2 "$hairgen" frobnicate
  expect_err "unknown command 'frobnicate'; the commands are run, grow,"
  expect_rc 2 "$hairgen" gorw setup.txt -o g.hair
  expect_err "unknown command 'gorw'; did you mean 'grow'?"
  expect_rc 2 "$hairgen" info "$tmp/x.foo"
  expect_err "info reads .hair, .gltf, .glb, .ply, .data, .usda, .obj and .exr"
  expect_rc 2 "$hairgen" info
  expect_rc 2 "$hairgen" convert a.hair
  expect_rc 2 "$hairgen" info "$tmp/missing.hair"
  grep -q "hairgen info: error: $tmp/missing.hair" "$tmp/err" || fail "missing file not named: $(cat "$tmp/err")"
  ;;
config_errors)
  expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt" --set Hairstyle.HairDensity=160 --stats "$tmp/s.json"
  grep -q '"Hairstyle.HairDensity=160"' "$tmp/s.json" || fail "--stats does not report the override"
  grep -q '"configDigest": "[0-9a-f]\{16\}"' "$tmp/s.json" && grep -q '"seed": 1' "$tmp/s.json" ||
    fail "check --stats lacks the digest or the seed every stage's has"
  expect_rc 2 "$hairgen" check "$src/configs/default/setup.txt" --set Hairstyle.HairDensty=160
  grep -q "did you mean 'HairDensity'" "$tmp/err" || fail "no hint: $(cat "$tmp/err")"
  printf 'HairLengths 0.04\nYoung abc\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel %s\n' "$src/configs/assets/wick.obj" > "$tmp/setup.txt"
  expect_rc 2 "$hairgen" check "$tmp/setup.txt"
  grep -q "^hairgen check: error: $tmp/h.txt:2: 'Young': 'abc' is not a number" "$tmp/err" || fail "bad message: $(cat "$tmp/err")"
  printf 'Load true\n' > "$tmp/load.txt"
  expect_rc 2 "$hairgen" check "$tmp/load.txt"
  grep -q "load.txt:1:" "$tmp/err" || fail "Load without LoadFile not located: $(cat "$tmp/err")"
  # check judges a Setup as run reads it: an empty one is no job, and a LoadFile run cannot read is
  # refused by check too.
  : > "$tmp/empty.txt"
  expect_rc 2 "$hairgen" check "$tmp/empty.txt"
  expect_err "missing required key 'HairstyleInfo'"
  # A Setup for render --hair alone (a Render Info and a head, no wick) is checked as a render's.
  printf 'RenderInfo %s\nHeadModel %s\n' "$src/configs/default/render.txt" "$src/configs/assets/head.obj" > "$tmp/render.txt"
  expect_rc 0 "$hairgen" check "$tmp/render.txt"
  printf 'not hair\n' > "$tmp/coupe.hair"
  expect_rc 2 "$hairgen" check "$src/configs/default/setup.txt" --set Setup.Load=true --set "Setup.LoadFile=$tmp/coupe.hair"
  expect_err "$tmp/coupe.hair"
  ;;
no_partial_output)
  head -c 300 "$src/tests/cli_test.sh" > "$tmp/broken.hair"
  expect_rc 2 "$hairgen" convert "$tmp/broken.hair" "$tmp/out.glb"
  [ ! -e "$tmp/out.glb" ] || fail "a failed convert left output behind"
  [ -z "$(ls "$tmp" | grep tmp-)" ] || fail "a temporary file was left behind"
  expect_rc 2 "$hairgen" convert "$tmp/broken.hair" "$tmp/out.xyz"
  ;;
render_units_head)
  # render --units/--up-axis convert the hair file alone: a data set's hair (cyHair, 4 mm a unit, z up)
  # sits on the bundled head, the image the same as of the hair converted to metres first
  # (docs/real-heads.md).
  [ -f "$real/luxcore/straight.hair" ] || skip "shared/testdata/real is absent"
  small=(--quiet --set "Render.Resolution=48 48")
  on_head=(--translate 0 -0.094 -0.01)
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$real/luxcore/straight.hair" \
    --units 0.004 --up-axis z "${on_head[@]}" -o "$tmp/units.exr" "${small[@]}"
  expect_rc 0 "$hairgen" convert "$real/luxcore/straight.hair" "$tmp/metres.hair" --units 0.004 --up-axis z -q
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/metres.hair" "${on_head[@]}" \
    -o "$tmp/metres.exr" "${small[@]}"
  cmp "$tmp/units.exr" "$tmp/metres.exr" || fail "render --units converted the head too"
  # A head in the hair's units is asked for in the Setup: then the images differ.
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$real/luxcore/straight.hair" \
    --units 0.004 --up-axis z "${on_head[@]}" -o "$tmp/both.exr" "${small[@]}" --set Setup.MeshUnits=0.004 \
    --set Setup.MeshUpAxis=z
  expect_rc 4 "$hairgen" diff "$tmp/metres.exr" "$tmp/both.exr"
  ;;
render_units_note)
  # A coupe in centimetres read as metres (here, one in metres made 100 times larger) renders, framed, as
  # strands drawn a hundredth of their width: a nearly empty image. The render says why and what to give,
  # on stderr and in --stats; a coupe in metres hears nothing of it.
  expect_rc 0 "$hairgen" grow "$src/configs/default/setup.txt" -o "$tmp/g.hair" --quiet --set Hairstyle.HairDensity=5
  expect_rc 0 "$hairgen" convert "$tmp/g.hair" "$tmp/large.hair" --units 100 --quiet
  framed=(--frame --set "Render.Resolution=48 48")
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/large.hair" -o "$tmp/large.exr" \
    "${framed[@]}" --stats "$tmp/large.json"
  expect_err "if the hair file is not in metres, give its unit (render --units cm, mm or in;"
  grep -q '"note": "the longest strand is [0-9.]* m, and the strands are drawn [0-9.e-]* pixels wide' "$tmp/large.json" ||
    fail "no note in --stats: $(cat "$tmp/large.json")"
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/g.hair" -o "$tmp/metres.exr" \
    "${framed[@]}" --stats "$tmp/metres.json"
  ! grep -q "unit" "$tmp/err" || fail "a coupe in metres was told of units: $(cat "$tmp/err")"
  ! grep -q '"note"' "$tmp/metres.json" || fail "a coupe in metres has a note: $(cat "$tmp/metres.json")"
  ;;
real_cyhair)
  [ -f "$real/luxcore/straight.hair" ] || skip "shared/testdata/real is absent"
  expect_rc 0 "$hairgen" info "$real/luxcore/straight.hair"
  grep -q "10000 strands, 160000 points" "$tmp/out" || fail "info: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" convert "$real/luxcore/straight.hair" "$tmp/s.glb" --quiet
  expect_rc 0 "$hairgen" convert "$tmp/s.glb" "$tmp/back.hair" --quiet
  expect_rc 0 "$hairgen" convert "$real/luxcore/straight.hair" "$tmp/direct.hair" --quiet
  # The same points: the cyHair core (header counts and arrays) is identical; only provenance differs.
  core=$((128 + 160000 * 12 + 160000 * 12))
  cmp -n "$core" "$tmp/back.hair" "$tmp/direct.hair" || fail "points changed through .glb"
  expect_rc 0 "$hairgen" info "$tmp/s.glb" --json
  grep -q '"points": 160000' "$tmp/out" || fail "glb info"
  ;;
grow_errors)
  printf 'HairLengths 0.04\nMaxIter 0\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel %s\n' "$src/configs/assets/wick.obj" > "$tmp/setup.txt"
  expect_rc 2 "$hairgen" grow "$tmp/setup.txt" -o "$tmp/g.hair"
  grep -q "h.txt:2:" "$tmp/err" || fail "MaxIter 0 not located: $(cat "$tmp/err")"
  [ ! -e "$tmp/g.hair" ] || fail "output written after an error"
  printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n' > "$tmp/flat.obj"
  printf 'HairLengths 0.04\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel flat.obj\n' > "$tmp/setup.txt"
  expect_rc 2 "$hairgen" grow "$tmp/setup.txt" -o "$tmp/g.glb"
  grep -q "flat.obj:4: normal of zero length" "$tmp/err" || fail "zero normal not located: $(cat "$tmp/err")"
  [ ! -e "$tmp/g.glb" ] || fail "output written after a zero normal"
  ;;
run_equals_stages)
  setup="$src/configs/thesis/coupe2/setup.txt"
  set_density=(--set Hairstyle.HairDensity=15 --set "Render.Resolution=64 64")
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/run" --quiet "${set_density[@]}"
  expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/g.hair" --quiet --threads 1 "${set_density[@]}" \
    --stats "$tmp/grow.json"
  # The parts are laps of one clock: together no more than the whole (write once held the grow too).
  awk -F'[:,]' '/"(read|grow|write)":/ { parts += $2 } /"total":/ { total = $2 }
    END { exit !(total > 0 && parts <= total * 1.01 + 0.002) }' "$tmp/grow.json" ||
    fail "grow --stats parts exceed the total: $(cat "$tmp/grow.json")"
  expect_rc 0 "$hairgen" interpolate "$setup" --guides "$tmp/g.hair" -o "$tmp/c.hair" --threads 2 "${set_density[@]}" \
    --stats "$tmp/stats.json"
  cmp "$tmp/run/guides.hair" "$tmp/g.hair" || fail "run's guides differ from grow's"
  cmp "$tmp/run/coupe.hair" "$tmp/c.hair" || fail "run's coupe differs from interpolate's"
  grep -q '"strands"' "$tmp/stats.json" || fail "no strand count in --stats"
  expect_rc 0 "$hairgen" render "$setup" --hair "$tmp/c.hair" -o "$tmp/beauty.exr" --quiet "${set_density[@]}" \
    --stats "$tmp/render.json"
  cmp "$tmp/run/beauty.exr" "$tmp/beauty.exr" || fail "run's image differs from render's"
  # Who drew the light's maps: hairgen's integer rasteriser, on every device.
  grep -q '"lightMaps": *"cpu"' "$tmp/render.json" || fail "the light's maps not drawn by hairgen's rasteriser"
  # The coupe read where the file's pages lie, and the same image as run's, which held it in memory.
  grep -q '"hairMapped": *true' "$tmp/render.json" || fail "the coupe was not read where the file lies"
  # With the camera aimed by the stage (auto, as a real head's Setup leaves it), the same bytes too: the
  # EXR carries the Setup's digest, which a farm plan checks to take the render task for done.
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/auto" --quiet "${set_density[@]}" --set Render.CameraPosition=auto
  expect_rc 0 "$hairgen" render "$setup" --hair "$tmp/auto/coupe.hair" -o "$tmp/auto.exr" --quiet \
    "${set_density[@]}" --set Render.CameraPosition=auto
  cmp "$tmp/auto/beauty.exr" "$tmp/auto.exr" || fail "with an auto camera, run's image differs from render's"
  # Load and Save: render a saved coupe without growing it.
  printf 'Load true\nLoadFile %s\nSave true\nSaveFile saved.hair\nHeadModel %s\n' "$tmp/c.hair" \
    "$src/configs/assets/head.obj" > "$tmp/load.txt"
  expect_rc 0 "$hairgen" run "$tmp/load.txt" -o "$tmp/loaded" --quiet --set "Render.Resolution=48 48"
  cmp "$tmp/saved.hair" "$tmp/c.hair" || fail "Save did not write the loaded coupe"
  [ -s "$tmp/loaded/beauty.exr" ] && [ ! -e "$tmp/loaded/guides.hair" ] || fail "Load should render without growing"
  printf 'Load true\n' > "$tmp/noload.txt"
  expect_rc 2 "$hairgen" run "$tmp/noload.txt" -o "$tmp/x"
  grep -q "noload.txt:1:" "$tmp/err" || fail "Load without LoadFile not located: $(cat "$tmp/err")"
  expect_rc 0 "$hairgen" convert "$tmp/c.hair" "$tmp/c.glb"
  expect_rc 0 "$hairgen" convert "$tmp/c.glb" "$tmp/back.hair"
  cmp "$tmp/c.hair" "$tmp/back.hair" || fail "coupe does not round-trip through GLB"
  ;;
interpolate_errors)
  printf 'v 0 0 0\nv 0.01 0 0\nv 0 0 0.01\nvn 0 1 0\nf 1//1 2//1 3//1\n' > "$tmp/tri.obj"
  printf 'HairLengths 0.04\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel tri.obj\n' > "$tmp/tri.txt"
  expect_rc 0 "$hairgen" grow "$tmp/tri.txt" -o "$tmp/tri.hair" --quiet
  expect_rc 2 "$hairgen" interpolate "$src/configs/default/setup.txt" --guides "$tmp/tri.hair" -o "$tmp/c.hair"
  grep -q "tri.hair: has 3 guides but the wick has 759 vertices" "$tmp/err" || fail "mismatch: $(cat "$tmp/err")"
  head -c 300 "$tmp/tri.hair" > "$tmp/cut.hair"
  expect_rc 2 "$hairgen" interpolate "$tmp/tri.txt" --guides "$tmp/cut.hair" -o "$tmp/c.hair"
  grep -q "cut.hair" "$tmp/err" || fail "truncated guides not named: $(cat "$tmp/err")"
  [ ! -e "$tmp/c.hair" ] || fail "output written after an error"
  expect_rc 0 "$hairgen" interpolate "$tmp/tri.txt" --guides "$tmp/tri.hair" -o "$tmp/c.glb" --quiet
  ;;
render_errors)
  expect_rc 2 "$hairgen" render "$src/configs/default/setup.txt" -o "$tmp/i.exr"
  grep -q -- "--hair" "$tmp/err" || fail "missing --hair not named: $(cat "$tmp/err")"
  printf 'HAIR' > "$tmp/bad.hair"
  expect_rc 2 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/bad.hair" -o "$tmp/i.exr"
  grep -q "bad.hair" "$tmp/err" || fail "bad cache not named: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/bad.hair" -o "$tmp/i.png"
  [ ! -e "$tmp/i.exr" ] && [ ! -e "$tmp/i.png" ] || fail "output written after an error"
  expect_rc 0 "$hairgen" render --list-devices
  grep -q "opens" "$tmp/out" || fail "no device opens: $(cat "$tmp/out")"
  # Without any EGL vendor (glvnd finds none): bad input is still bad input (2), a good coupe cannot be
  # rendered (3, one line), and --list-devices says so with 3 too.
  expect_rc 0 "$hairgen" run "$src/configs/thesis/coupe1/setup.txt" -o "$tmp/c1" --no-render -q \
    --set Hairstyle.HairDensity=5
  export __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/vendor.json
  expect_rc 2 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/missing.hair" -o "$tmp/i.exr"
  expect_rc 3 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/c1/coupe.hair" -o "$tmp/i.exr"
  [ "$(wc -l < "$tmp/err")" -eq 1 ] || fail "the no-device error is not one line: $(cat "$tmp/err")"
  expect_rc 3 "$hairgen" render --list-devices
  unset __EGL_VENDOR_LIBRARY_FILENAMES
  ;;
render_shader_errors)
  # A Setup's HairFrag that does not compile: exit 2 at the file's line, naming the Setup line, and no
  # image; fixed, the same commands render with it.
  c2="$src/configs/thesis/coupe2"
  printf 'HairstyleInfo %s\nCollisionInfo %s\nVisualityInfo %s\nRenderInfo %s\nHeadModel %s\nWickModel %s\nHairFrag hairfrag.glsl\n' \
    "$c2/hairstyle.txt" "$c2/collision.txt" "$c2/visuality.txt" "$c2/render.txt" \
    "$src/configs/assets/head.obj" "$src/configs/assets/wick.obj" > "$tmp/setup.txt"
  printf 'layout(location = 0) out vec4 oColor;\nlayout(location = 1) out vec4 oData;\nvoid main() {\n  oColor = vec4(foo);\n  oData = vec4(0.0);\n}\n' \
    > "$tmp/hairfrag.glsl"
  small=(--set "Render.Resolution=48 48" --set Hairstyle.HairDensity=5 --quiet)
  expect_rc 0 "$hairgen" run "$tmp/setup.txt" -o "$tmp/coupe" --no-render "${small[@]}"
  expect_rc 2 "$hairgen" run "$tmp/setup.txt" -o "$tmp/run" "${small[@]}"
  [ "$(wc -l < "$tmp/err")" -eq 1 ] || fail "not one line: $(cat "$tmp/err")"
  grep -q "^hairgen run: error: $tmp/hairfrag.glsl:4: .*foo.*(compiling HairFrag.*, named at $tmp/setup.txt:7)$" "$tmp/err" \
    || fail "file and line not named: $(cat "$tmp/err")"
  [ -z "$(ls -A "$tmp/run")" ] || fail "a failed run left outputs: $(ls "$tmp/run")"
  expect_rc 2 "$hairgen" render "$tmp/setup.txt" --hair "$tmp/coupe/coupe.hair" -o "$tmp/i.exr" "${small[@]}"
  grep -q "^hairgen render: error: $tmp/hairfrag.glsl:4: " "$tmp/err" || fail "render: $(cat "$tmp/err")"
  [ ! -e "$tmp/i.exr" ] || fail "render wrote an image after a shader error"
  [ -z "$(ls "$tmp" "$tmp/run" | grep tmp-)" ] || fail "a temporary file was left behind"
  printf 'in float vAlpha;\nin float vDepth;\nlayout(location = 0) out vec4 oColor;\nlayout(location = 1) out vec4 oData;\nvoid main() {\n  screenDoor(vAlpha);\n  oColor = vec4(1.0, 0.0, 0.0, vAlpha);\n  oData = vec4(vDepth, 1.0, lightArriving(vec3(0.0), kShadowBiasHair), 0.0);\n}\n' \
    > "$tmp/hairfrag.glsl"
  expect_rc 0 "$hairgen" render "$tmp/setup.txt" --hair "$tmp/coupe/coupe.hair" -o "$tmp/i.exr" "${small[@]}"
  [ -s "$tmp/i.exr" ] || fail "no image from a working HairFrag"
  # A shader file that is not there is reported before anything runs, as `check` does for the thesis'
  # Appendix B Setup.
  sed -i 's/^HairFrag .*/HairFrag missing.glsl/' "$tmp/setup.txt"
  expect_rc 2 "$hairgen" check "$tmp/setup.txt"
  grep -q "setup.txt:7: HairFrag names '.*missing.glsl', which does not exist" "$tmp/err" || fail "missing: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" check "$src/configs/thesis/appendix-b/setup.txt"
  grep -q "which does not exist" "$tmp/err" || fail "appendix-b: $(cat "$tmp/err")"
  ;;
render_diff)
  expect_rc 0 "$hairgen" grow "$src/configs/thesis/coupe2/setup.txt" -o "$tmp/g.hair" --quiet
  small=(--set "Render.Resolution=96 96" --quiet)
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/g.hair" -o "$tmp/a.exr" "${small[@]}" \
    --preview "$tmp/a.png" --dom "$tmp/dom.exr"
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/g.hair" -o "$tmp/b.exr" "${small[@]}" \
    --set "Render.LightPosition=-0.6 1.0 0.8"
  if command -v exrheader >/dev/null; then
    exrheader "$tmp/a.exr" > "$tmp/header"
    for c in "R, 16-bit floating" "G, 16-bit" "B, 16-bit" "A, 16-bit" "Z, 32-bit floating" "opacity.Y, 32-bit" \
             "shadow.Y, 32-bit" 'producer (type string): "hairgen' "hairgen:configDigest" "worldToCamera" \
             "hairgen:fieldOfView (type float)" "hairgen:resolution (type v2i): (96 96)" "hairgen:alpha"; do
      grep -q "$c" "$tmp/header" || fail "exrheader does not show '$c'"
    done
    exrheader "$tmp/dom.exr" | grep -q "layer4, 32-bit" || fail "the DOM file lacks its fourth layer"
  fi
  [ -s "$tmp/a.png" ] || fail "no preview"
  expect_rc 0 "$hairgen" diff "$tmp/a.exr" "$tmp/a.exr"
  grep -q "^PASS" "$tmp/out" || fail "an image differs from itself: $(cat "$tmp/out")"
  expect_rc 4 "$hairgen" diff "$tmp/a.exr" "$tmp/b.exr" --out "$tmp/d.exr"
  grep -q "^FAIL" "$tmp/out" || fail "no FAIL verdict: $(cat "$tmp/out")"
  grep -q "worst pixel ([0-9]*, [0-9]*) channel" "$tmp/out" || fail "worst pixel not named: $(cat "$tmp/out")"
  [ -s "$tmp/d.exr" ] || fail "no difference image"
  # Moving the light changes the shading, not the geometry.
  expect_rc 0 "$hairgen" diff "$tmp/a.exr" "$tmp/b.exr" --channels Z,opacity.Y
  expect_rc 2 "$hairgen" diff "$tmp/a.exr" "$tmp/missing.exr"
  # An image is read by the reader its extension names (in any case), and by no other.
  cp "$tmp/a.exr" "$tmp/A.EXR" && cp "$tmp/a.exr" "$tmp/mislabelled.png"
  expect_rc 0 "$hairgen" diff "$tmp/A.EXR" "$tmp/a.exr"
  expect_rc 0 "$hairgen" diff "$tmp/a.png" "$tmp/a.png"
  expect_rc 2 "$hairgen" diff "$tmp/mislabelled.png" "$tmp/a.exr"
  # An EXR header's sizes are checked against the file before OpenEXR allocates what they declare.
  expect_rc 2 "$hairgen" diff "$src/tests/fuzz/corpus/fuzz_exr/string-attribute-declares-1.9GB.exr" "$tmp/a.exr"
  grep -q "not a readable OpenEXR file: .*Invalid size" "$tmp/err" || fail "bad EXR header: $(cat "$tmp/err")"
  # HeadModel none (any case) draws no head: the image of HeadModel "" (no head), whose alpha differs from
  # the image with the head; and check names no head.
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/g.hair" -o "$tmp/none.exr" "${small[@]}" \
    --set Setup.HeadModel=NONE
  expect_rc 0 "$hairgen" render "$src/configs/default/setup.txt" --hair "$tmp/g.hair" -o "$tmp/empty.exr" "${small[@]}" \
    --set 'Setup.HeadModel=""'
  expect_rc 0 "$hairgen" diff "$tmp/none.exr" "$tmp/empty.exr"
  expect_rc 4 "$hairgen" diff "$tmp/a.exr" "$tmp/none.exr" --channels A
  expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt"
  grep -q "^  head .*head.obj" "$tmp/out" || fail "check names no head with one: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt" --set Setup.HeadModel=none
  ! grep -q "^  head " "$tmp/out" || fail "check names a head with HeadModel none: $(cat "$tmp/out")"
  ;;
run_default)
  # With no Setup, run finds configs/default beside an installed executable, or through HAIRGEN_DATA.
  cmake --install "$(dirname "$hairgen")" --prefix "$tmp/prefix" >/dev/null || fail "install failed"
  (cd "$tmp" && expect_rc 0 "$tmp/prefix/bin/hairgen" run -o "$tmp/installed" --no-render --quiet \
    --set Hairstyle.HairDensity=5) || exit 1
  [ -s "$tmp/installed/coupe.hair" ] || fail "the installed hairgen did not find its default coupe"
  mkdir -p "$tmp/lonely" && cp "$hairgen" "$tmp/lonely/hairgen"
  (cd "$tmp" && expect_rc 2 "$tmp/lonely/hairgen" run --no-render) || exit 1
  grep -q "HAIRGEN_DATA" "$tmp/err" || fail "no hint at HAIRGEN_DATA: $(cat "$tmp/err")"
  (cd "$tmp" && HAIRGEN_DATA="$src" expect_rc 0 "$tmp/lonely/hairgen" run -o "$tmp/viaenv" --no-render --quiet \
    --set Hairstyle.HairDensity=5) || exit 1
  ;;
anjyo_errors)
  printf 'Model cantilever\nHairLengths 0.2\nForce 1 0 0 sideways\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel %s\n' "$src/configs/assets/wick.obj" > "$tmp/setup.txt"
  expect_rc 2 "$hairgen" grow "$tmp/setup.txt" -o "$tmp/g.hair"
  grep -q "h.txt:3: .*region 'sideways'" "$tmp/err" || fail "bad Force not located: $(cat "$tmp/err")"
  printf 'Model cantilever\nHairLengths 0.2\nCut 0 90 nan 0.1\n' > "$tmp/h.txt"
  expect_rc 2 "$hairgen" grow "$tmp/setup.txt" -o "$tmp/g.hair"
  grep -q "h.txt:3:" "$tmp/err" || fail "bad Cut not located: $(cat "$tmp/err")"
  printf 'Model cantilever\nHairLengths 0.2\nSegments 10\nCut -180 180 180 0.12\n' > "$tmp/h.txt"
  expect_rc 0 "$hairgen" grow "$tmp/setup.txt" -o "$tmp/g.hair" --quiet
  expect_rc 0 "$hairgen" interpolate "$tmp/setup.txt" --guides "$tmp/g.hair" -o "$tmp/c.hair" --quiet \
    --set Hairstyle.HairDensity=5
  [ ! -e "$tmp/g.hair.tmp" ] && [ -s "$tmp/c.hair" ] || fail "cut guides did not interpolate"
  ;;
shade_volume)
  setup="$src/configs/thesis/coupe3/setup.txt"
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/r" --no-render --quiet --set Hairstyle.HairDensity=5
  vol=(--set Render.ShadingModel=volumetric --set Render.VoxelSize=0.005)
  expect_rc 0 "$hairgen" shade "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/s1.hair" --vdb "$tmp/v1.vdb" "${vol[@]}" --threads 1
  expect_rc 0 "$hairgen" shade "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/s2.hair" --vdb "$tmp/v2.vdb" "${vol[@]}" --threads 2 \
    --stats "$tmp/stats.json"
  cmp -s "$tmp/s1.hair" "$tmp/s2.hair" || fail "shaded caches differ between 1 and 2 threads"
  grep -q '"grid"' "$tmp/stats.json" || fail "--stats lacks the grid size"
  expect_rc 0 "$hairgen" info "$tmp/s1.hair"
  grep -q "attributes: .*normals" "$tmp/out" && grep -q "(shade)" "$tmp/out" || fail "no normals: $(cat "$tmp/out")"
  # OpenVDB's own reader: both grids, by their documented names, at the configured voxel size.
  if command -v vdb_print >/dev/null; then
    vdb_print -l "$tmp/v1.vdb" >"$tmp/vdb" 2>&1 || fail "vdb_print cannot read the volume: $(cat "$tmp/vdb")"
    grep -q "Name: density" "$tmp/vdb" && grep -q "Name: sdf" "$tmp/vdb" || fail "grids missing: $(cat "$tmp/vdb")"
    [ "$(grep -c "voxel size: 0.005" "$tmp/vdb")" -eq 2 ] || fail "voxel size is not 0.005 m: $(cat "$tmp/vdb")"
    grep -q "class: level set" "$tmp/vdb" && grep -q "class: fog volume" "$tmp/vdb" || fail "grid classes: $(cat "$tmp/vdb")"
  else
    fail "vdb_print (Debian's libopenvdb-tools) is not installed; scripts/setup.sh installs it"
  fi
  # The same through the glTF cache: NORMAL per vertex.
  expect_rc 0 "$hairgen" shade "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/s.gltf" "${vol[@]}"
  grep -q '"NORMAL"' "$tmp/s.gltf" || fail "the glTF has no NORMAL attribute"
  # Volumetric rendering wants normals: a plain coupe is refused at its file, and nothing is written.
  expect_rc 2 "$hairgen" render "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/b.exr" --set Render.ShadingModel=volumetric
  grep -q "coupe.hair: .*hairgen shade" "$tmp/err" && [ ! -e "$tmp/b.exr" ] || fail "render without normals: $(cat "$tmp/err")"
  expect_rc 0 "$hairgen" render "$setup" --hair "$tmp/s1.hair" -o "$tmp/b.exr" "${vol[@]}" --quiet \
    --set "Render.Resolution=48 48"
  # A volume file that cannot be written (its folder is a file) leaves no coupe behind.
  expect_rc 1 "$hairgen" shade "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/s3.hair" --vdb "$tmp/r/coupe.hair/v.vdb"
  [ ! -e "$tmp/s3.hair" ] || fail "a failed --vdb left the coupe"
  expect_rc 2 "$hairgen" shade "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/s3.hair" --vdb "$tmp/v.txt"
  expect_rc 2 "$hairgen" shade "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/s3.hair" --set Render.VoxelSize=-1
  grep -q "VoxelSize" "$tmp/err" || fail "bad VoxelSize: $(cat "$tmp/err")"
  ;;
shade_rest)
  setup="$src/configs/thesis/coupe3/setup.txt"
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/r" --no-render --quiet --set Hairstyle.HairDensity=5
  expect_rc 0 "$hairgen" shade "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/rest.hair" --quiet
  # The paper's animated-hair path, in the issue's own words: no Setup, the deformed coupe on its own.
  expect_rc 0 "$hairgen" shade --rest "$tmp/rest.hair" "$tmp/r/coupe.hair" -o "$tmp/posed.hair" --stats "$tmp/st.json"
  expect_rc 0 "$hairgen" info "$tmp/posed.hair"
  grep -q "attributes: .*normals" "$tmp/out" || fail "re-posed coupe has no normals: $(cat "$tmp/out")"
  grep -q '"repose"' "$tmp/st.json" || fail "--stats lacks the re-pose time"
  # A rest without normals, coupes of different strands, and a volume asked of --rest: exit 2, no output.
  expect_rc 2 "$hairgen" shade --rest "$tmp/r/coupe.hair" "$tmp/r/coupe.hair" -o "$tmp/x.hair"
  grep -q "no normals" "$tmp/err" || fail "rest without normals: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" shade --rest "$tmp/rest.hair" "$tmp/r/guides.hair" -o "$tmp/x.hair"
  grep -q "differ" "$tmp/err" || fail "mismatched coupes: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" shade --rest "$tmp/rest.hair" "$tmp/r/coupe.hair" -o "$tmp/x.hair" --vdb "$tmp/x.vdb"
  expect_rc 2 "$hairgen" shade --rest "$tmp/rest.hair" -o "$tmp/x.hair"
  [ ! -e "$tmp/x.hair" ] && [ ! -e "$tmp/x.vdb" ] || fail "a refused re-pose wrote output"
  ;;
formats)
  # PLY (binary and ASCII) and .data round trips keep every point bit for bit: compared as .data, whose
  # bytes are the points alone.
  small=(--set "Render.Resolution=48 48" --set Hairstyle.HairDensity=5 --quiet)
  expect_rc 0 "$hairgen" run "$src/configs/thesis/coupe2/setup.txt" -o "$tmp/r" --no-render "${small[@]}"
  expect_rc 0 "$hairgen" convert "$tmp/r/coupe.hair" "$tmp/direct.data" -q
  for via in "b.ply" "a.ply --ascii" "d.data"; do
    set -- $via
    expect_rc 0 "$hairgen" convert "$tmp/r/coupe.hair" "$tmp/$1" -q ${2:-}
    expect_rc 0 "$hairgen" convert "$tmp/$1" "$tmp/back-$1.hair" -q
    expect_rc 0 "$hairgen" convert "$tmp/back-$1.hair" "$tmp/back-$1.data" -q
    cmp "$tmp/direct.data" "$tmp/back-$1.data" || fail "points changed through $1"
  done
  head -c 30 "$tmp/a.ply" | grep -q "format ascii 1.0" || fail "--ascii did not write ASCII"
  # What each format holds, and where a converted file came from.
  expect_rc 0 "$hairgen" info "$tmp/back-d.data.hair"
  grep -q "converted from d.data by hairgen" "$tmp/out" && grep -q "units: unknown" "$tmp/out" || fail "provenance: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" convert "$tmp/d.data" "$tmp/m.ply" --units cm --up-axis z -q
  expect_rc 0 "$hairgen" info "$tmp/m.ply"
  grep -q "converted with units cm (x0.01); up axis z turned to +y" "$tmp/out" && grep -q "units: metres, +y up" "$tmp/out" \
    || fail "conversion not recorded: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" convert "$tmp/r/coupe.hair" "$tmp/c.usda" -q
  expect_rc 0 "$hairgen" info "$tmp/c.usda"
  grep -q "curves" "$tmp/out" && grep -q "metersPerUnit: 1" "$tmp/out" || fail "usda info: $(cat "$tmp/out")"
  expect_rc 2 "$hairgen" convert "$tmp/c.usda" "$tmp/x.hair"
  grep -q "does not read it" "$tmp/err" || fail "reading USD: $(cat "$tmp/err")"
  # The stages take the data sets' formats, with their units.
  expect_rc 0 "$hairgen" convert "$tmp/r/guides.hair" "$tmp/g.ply" -q
  expect_rc 0 "$hairgen" interpolate "$src/configs/thesis/coupe2/setup.txt" --guides "$tmp/g.ply" -o "$tmp/c2.hair" "${small[@]}"
  cmp "$tmp/c2.hair" "$tmp/r/coupe.hair" || fail "interpolating PLY guides differs from .hair guides"
  expect_rc 0 "$hairgen" convert "$tmp/r/coupe.hair" "$tmp/mm.data" -q
  expect_rc 0 "$hairgen" render "$src/configs/thesis/coupe2/setup.txt" --hair "$tmp/mm.data" --units 1 -o "$tmp/i.exr" "${small[@]}"
  expect_rc 0 "$hairgen" info "$tmp/i.exr"
  for want in "48x48, 7 channels" "opacity.Y (float)" "shadow.Y (float)" "A (half)" "hairgen:alpha: premultiplied" \
              "hairgen:fieldOfView: " "hairgen:configDigest: "; do
    grep -q "$want" "$tmp/out" || fail "info of the EXR lacks '$want': $(cat "$tmp/out")"
  done
  # Bad units, an --ascii that is not PLY, and curves USD cannot hold are exit 2 with nothing written.
  expect_rc 2 "$hairgen" convert "$tmp/d.data" "$tmp/x.ply" --units furlong
  expect_rc 2 "$hairgen" convert "$tmp/d.data" "$tmp/x.glb" --ascii
  printf '\1\0\0\0\1\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0' > "$tmp/one.data"
  expect_rc 2 "$hairgen" convert "$tmp/one.data" "$tmp/x.usda"
  grep -q "no strands of two points or more" "$tmp/err" || fail "one-point curve: $(cat "$tmp/err")"
  [ ! -e "$tmp/x.ply" ] && [ ! -e "$tmp/x.glb" ] && [ ! -e "$tmp/x.usda" ] || fail "a refused convert wrote output"
  ;;
real_hairutil)
  # hairutil's test data: the same 100 strands as .hair, .data and ASCII and binary PLY read to the same
  # points, bit for bit.
  d="$real/hairutil"
  [ -f "$d/Bangs_100.data" ] || skip "shared/testdata/real is absent"
  for f in Bangs_100.hair Bangs_100_ascii.ply Bangs_100_binary.ply Bangs_100.data; do
    expect_rc 0 "$hairgen" convert "$d/$f" "$tmp/$f.data" -q
    cmp "$tmp/$f.data" "$d/Bangs_100.data" || fail "$f does not read to Bangs_100.data's points"
  done
  expect_rc 0 "$hairgen" info "$d/Curly_100.ply"
  grep -q "100 strands, 2528 points" "$tmp/out" || fail "Curly: $(cat "$tmp/out")"
  expect_rc 2 "$hairgen" info "$d/Bangs_head.ply"
  grep -q "a mesh (it has faces), not strands" "$tmp/err" || fail "head mesh: $(cat "$tmp/err")"
  ;;
wick_info)
  expect_rc 0 "$hairgen" info "$src/configs/assets/wick.obj"
  grep -q "759 vertices, 1443 triangles, area" "$tmp/out" || fail "wick info: $(cat "$tmp/out")"
  # Roots alone, as grow takes them: described, and check says that run cannot interpolate over them.
  printf 'v 0 0.2 0\nv 0.01 0.2 0\nv 0 0.2 0.01\n' > "$tmp/roots.obj"
  expect_rc 0 "$hairgen" info "$tmp/roots.obj"
  grep -q "3 vertices, 0 triangles" "$tmp/out" || fail "roots info: $(cat "$tmp/out")"
  printf 'HairLengths 0.05\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel roots.obj\n' > "$tmp/setup.txt"
  expect_rc 0 "$hairgen" check "$tmp/setup.txt"
  expect_err "the wick has no faces, only points (roots)"
  # RootFlow's point far from this wick (a Hairstyle Info made for another head): said, naming auto.
  printf 'HairLengths 0.05\nRootTilt 30\nRootFlow away-from 0 2 0\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel %s\n' "$src/configs/assets/wick.obj" > "$tmp/setup.txt"
  expect_rc 0 "$hairgen" check "$tmp/setup.txt"
  expect_err "RootFlow's point (0 2 0) lies"
  expect_err "RootFlow away-from auto"
  # The bundled head's whorl on a scalp 20 cm higher (another head: nearer the wick's centre than its
  # size, 20 cm from every follicle): said too.
  awk '$1 == "v" { $3 += 0.2 } { print }' "$src/configs/assets/wick.obj" > "$tmp/high.obj"
  printf 'HairLengths 0.05\nRootTilt 30\nRootFlow away-from 0 0.14 -0.04\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel high.obj\n' > "$tmp/setup.txt"
  expect_rc 0 "$hairgen" check "$tmp/setup.txt"
  expect_err "from the nearest follicle, so it is no whorl of this scalp"
  expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt"
  grep -q "RootFlow" "$tmp/err" && fail "the default coupe's RootFlow was warned of: $(cat "$tmp/err")"
  # away-from auto: check prints the line that freezes the whorl, and grow with that line grows what
  # grow with auto grows (the guides' bounds to a tenth of a millimetre).
  auto=(--set "Hairstyle.RootFlow=away-from auto" --set Hairstyle.HairDensity=10)
  expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt" "${auto[@]}"
  frozen=$(grep -o 'RootFlow away-from [-0-9.]* [-0-9.]* [-0-9.]*' "$tmp/out" | head -1)
  [ -n "$frozen" ] || fail "check printed no RootFlow line for auto: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" grow "$src/configs/default/setup.txt" "${auto[@]}" -q -o "$tmp/auto.hair"
  expect_rc 0 "$hairgen" grow "$src/configs/default/setup.txt" --set Hairstyle.HairDensity=10 -q \
    --set "Hairstyle.RootFlow=${frozen#RootFlow }" -o "$tmp/frozen.hair"
  bounds() { "$hairgen" info "$1" --json | tr -d ' \n' | grep -o '"bounds":{[^}]*}' | grep -o '[-0-9.e]*[0-9]'; }
  paste <(bounds "$tmp/auto.hair") <(bounds "$tmp/frozen.hair") |
    awk '{ d = $1 - $2; if (d < 0) d = -d; if (d > 1e-4) bad = 1; n++ } END { exit bad || n != 6 }' ||
    fail "auto and its frozen line grow different guides: $(paste <(bounds "$tmp/auto.hair") <(bounds "$tmp/frozen.hair"))"
  ;;
hardening_flags)
  # Flags are validated like config values: no sign wrapping, no NaN passing a range.
  expect_rc 2 "$hairgen" check "$src/configs/default/setup.txt" --seed -5
  grep -q -- "--seed: '-5' is not a non-negative integer" "$tmp/err" || fail "seed: $(cat "$tmp/err")"
  ref="$src/golden/default/reference.exr"
  expect_rc 2 "$hairgen" diff "$ref" "$ref" --fail nan
  expect_rc 2 "$hairgen" diff "$ref" "$ref" --hardfail inf
  # Names and provenance that are not UTF-8 are written into JSON, not thrown on.
  cp "$src/golden/fixtures/coupe3-shaded.hair" "$tmp/$(printf 'bad\xff.hair')"
  expect_rc 0 "$hairgen" info "$tmp/$(printf 'bad\xff.hair')" --json --stats "$tmp/s.json"
  ;;
hardening_outputs)
  # A character device named as --stats stays a device (as root: a node of our own, so nothing real is
  # at stake); without root, /dev/null and /dev/full stand in.
  if [ "$(id -u)" -eq 0 ] && mknod "$tmp/null" c 1 3 2>/dev/null; then
    expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt" -q --stats "$tmp/null"
    [ -c "$tmp/null" ] || fail "--stats replaced the character device with a $(stat -c %F "$tmp/null")"
  else
    echo "not root or no mknod here: checking /dev/null instead"
    expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt" -q --stats /dev/null
    [ -c /dev/null ] || fail "/dev/null is no longer a device"
  fi
  expect_rc 2 "$hairgen" convert "$src/golden/fixtures/coupe3-shaded.hair" "$tmp/c.ply" --stats "$tmp"
  [ "$(wc -l < "$tmp/err")" -eq 1 ] && [ ! -e "$tmp/c.ply" ] || fail "--stats DIR: $(cat "$tmp/err")"
  expect_rc 1 "$hairgen" check "$src/configs/default/setup.txt" -q --stats /dev/full
  grep -q "/dev/full: write failed" "$tmp/err" || fail "full: $(cat "$tmp/err")"
  expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt" -q --stats /dev/stdout
  grep -q '"command": "check"' "$tmp/out" || fail "--stats /dev/stdout wrote nothing"
  # With stdout appended to a farm log, the log keeps its lines before and after the stats.
  { echo "before"; "$hairgen" check "$src/configs/default/setup.txt" -q --stats /dev/stdout; echo "after"; } >> "$tmp/farm.log"
  [ "$(head -1 "$tmp/farm.log")" = before ] && [ "$(tail -1 "$tmp/farm.log")" = after ] &&
    grep -q '"command": "check"' "$tmp/farm.log" || fail "--stats /dev/stdout >> log: $(cat "$tmp/farm.log")"
  # A command that fails removes what it wrote: grow's diagnostics when the guides cannot be written,
  # render's EXR when its preview cannot.
  mkdir "$tmp/taken.hair" "$tmp/taken.png"
  expect_rc 2 "$hairgen" grow "$src/configs/thesis/coupe1/setup.txt" -o "$tmp/taken.hair" --diagnostics "$tmp/d.json" -q
  [ ! -e "$tmp/d.json" ] || fail "a failed grow left its diagnostics"
  # Found before the work: a directory named as the output, a file named as its folder.
  expect_rc 2 "$hairgen" grow "$src/configs/default/setup.txt" -o "$tmp/taken.hair"
  expect_err "taken.hair: is a directory; name a file to write"
  grep -q "guides" "$tmp/err" && fail "grew before finding the output is a directory: $(cat "$tmp/err")"
  # A relative name in folders that do not exist yet: they are made.
  (cd "$tmp" && "$hairgen" grow "$src/configs/thesis/coupe1/setup.txt" -o new/deeper/g.hair -q) ||
    fail "grow -o new/deeper/g.hair (relative, folders to make) failed"
  [ -s "$tmp/new/deeper/g.hair" ] || fail "no guides in the new folders"
  # A descriptor that is not open, or open for reading only, is refused before the work, in one line.
  expect_rc 2 "$hairgen" check "$src/configs/default/setup.txt" -q --stats /dev/fd/57
  [ "$(wc -l < "$tmp/err")" -eq 1 ] || fail "closed descriptor: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" check "$src/configs/default/setup.txt" -q --stats /dev/fd/0 < /dev/null
  expect_err "open for reading only"
  # --stats /dev/stdout after the report the command prints, not before it.
  "$hairgen" check "$src/configs/default/setup.txt" --stats /dev/stdout > "$tmp/report.txt" 2>/dev/null
  [ "$(head -c 1 "$tmp/report.txt")" != "{" ] && [ "$(tail -1 "$tmp/report.txt")" = "}" ] ||
    fail "--stats /dev/stdout came before the report: $(head -3 "$tmp/report.txt")"
  : > "$tmp/a-file"
  expect_rc 2 "$hairgen" grow "$src/configs/default/setup.txt" -o "$tmp/a-file/g.hair"
  expect_err "a-file: is not a folder"
  expect_rc 2 "$hairgen" render "$src/configs/thesis/coupe3/setup.txt" --hair "$src/golden/fixtures/coupe3-shaded.hair" \
    -o "$tmp/i.exr" --preview "$tmp/taken.png" --set "Render.Resolution=32 32" -q
  [ ! -e "$tmp/i.exr" ] || fail "a failed render left its EXR"
  [ -z "$(ls -A "$tmp" | grep tmp-)" ] || fail "temporaries left: $(ls -A "$tmp")"
  ;;
hardening_interrupt)
  # SIGTERM while interpolate writes a large coupe: exit 143, and neither the coupe nor a temporary.
  expect_rc 0 "$hairgen" grow "$src/configs/default/setup.txt" -o "$tmp/g.hair" -q
  for attempt in 1 2 3; do
    "$hairgen" interpolate "$src/configs/default/setup.txt" --guides "$tmp/g.hair" -o "$tmp/c.hair" -q \
      --set Hairstyle.HairDensity=400 &
    pid=$!
    seen=0
    for _ in $(seq 3000); do
      if ls "$tmp" | grep -q '^c\.hair\.tmp-'; then seen=1; kill -TERM "$pid"; break; fi
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.01
    done
    wait "$pid"; rc=$?
    [ "$seen" -eq 1 ] || { rm -f "$tmp/c.hair"; echo "attempt $attempt: the write finished before it was seen"; continue; }
    [ "$rc" -eq 143 ] || fail "interpolate ended with $rc after SIGTERM, expected 143"
    [ -z "$(ls -A "$tmp" | grep tmp-)" ] || fail "SIGTERM left a temporary: $(ls -A "$tmp")"
    [ ! -e "$tmp/c.hair" ] || fail "SIGTERM left a coupe"
    echo "ok ($case)"; exit 0
  done
  fail "never caught interpolate while it wrote"
  ;;
hardening_memory)
  # Under a 4 GB address-space limit no config ends in "out of memory": each is refused first, naming
  # the key to change.
  command -v prlimit >/dev/null || skip "no prlimit here"
  limit=(prlimit --as=4000000000)
  d="$src/configs/default/setup.txt"
  for set in "Hairstyle.HairDensity=1e20" "Hairstyle.CollisionStep=1e-9" "Hairstyle.VisualityStep=1e-9" \
             "Render.Resolution=16384 16384" "Render.VoxelSize=1e-6"; do
    key=${set%%=*}; key=${key#*.}
    expect_rc 2 "${limit[@]}" "$hairgen" run "$d" -o "$tmp/r" -q --set Render.ShadingModel=volumetric --set "$set"
    grep -q "$key" "$tmp/err" || fail "$set: the message does not name $key: $(cat "$tmp/err")"
    ! grep -q "out of memory" "$tmp/err" || fail "$set: out of memory"
  done
  expect_rc 2 "${limit[@]}" "$hairgen" run "$src/configs/anjyo/bob/setup.txt" -o "$tmp/r" -q --set Hairstyle.Segments=100000
  grep -q "Segments" "$tmp/err" || fail "Segments: $(cat "$tmp/err")"
  expect_rc 2 "${limit[@]}" "$hairgen" render "$d" --hair "$src/golden/fixtures/coupe3-shaded.hair" -o "$tmp/i.exr" -q \
    --set "Render.Resolution=16384 16384"
  expect_rc 2 "$hairgen" grow "$d" -o "$tmp/g.hair" -q --set "Hairstyle.HairLengths=$(printf '0.000625 %.0s' $(seq 256))" \
    --set Hairstyle.Minimiser=rosenbrock
  grep -q -- "--force" "$tmp/err" || fail "256 elements: $(cat "$tmp/err")"
  ;;
simulate)
  # Anjyo's gust on the bob at a low density: threads and a split run with a restart change no byte.
  setup="$src/configs/anjyo/gust/setup.txt"
  small=(--quiet --set Hairstyle.HairDensity=5 --set "Dynamics.Frames=1 12")
  expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/g.hair" "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/a/g.####.hair" --threads 1 "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/b/g.%04d.hair" --threads 2 "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/c/g.####.hair" --frames 1-6 "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/c/g.####.hair" --frames 7-12 "${small[@]}"
  for f in 0001 0006 0007 0012; do
    cmp "$tmp/a/g.$f.hair" "$tmp/b/g.$f.hair" || fail "frame $f differs between 1 and 2 threads"
    cmp "$tmp/a/g.$f.hair" "$tmp/c/g.$f.hair" || fail "frame $f differs in a split run"
  done
  expect_rc 0 "$hairgen" info "$tmp/a/g.0012.hair"
  grep -q "frame 12" "$tmp/out" || fail "info does not show the frame: $(cat "$tmp/out")"
  # A restart needs the frame before; frames outside the shot, a missing pattern or Dynamics Info are refused.
  expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/d/g.####.hair" --frames 7-12 "${small[@]}"
  grep -q "frame 6's cache" "$tmp/err" || fail "restart without frame 6: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/d/g.####.hair" --frames 1-13 "${small[@]}"
  expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/d/g.hair" "${small[@]}"
  expect_rc 2 "$hairgen" simulate "$src/configs/anjyo/bob/setup.txt" --guides "$tmp/g.hair" -o "$tmp/d/g.####.hair" --quiet
  grep -q "names no Dynamics Info" "$tmp/err" || fail "no dynamics: $(cat "$tmp/err")"
  # A restart from another configuration is refused, naming the file.
  expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/c/g.####.hair" --frames 7-12 "${small[@]}" \
    --set Dynamics.Damping=2
  grep -q "g.0006.hair: was simulated with another configuration" "$tmp/err" || fail "foreign restart: $(cat "$tmp/err")"
  ;;
springs)
  # Model springs (Petrovic et al. §5) on the Pixar head turn with velocity smoothing, a few frames:
  # threads and a split run with a restart change no byte; the Fig. 5 shot finds its DensityTarget; a
  # key of the other model is refused.
  setup="$src/configs/pixar/headturn/setup.txt"
  small=(--quiet --set "Dynamics.Frames=1 6" --set Dynamics.Substeps=2)
  expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/g.hair" --quiet
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/a/g.####.hair" --threads 1 "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/b/g.####.hair" --threads 2 "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/c/g.####.hair" --frames 1-3 "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/c/g.####.hair" --frames 4-6 "${small[@]}"
  for f in 0001 0003 0004 0006; do
    cmp "$tmp/a/g.$f.hair" "$tmp/b/g.$f.hair" || fail "frame $f differs between 1 and 2 threads"
    cmp "$tmp/a/g.$f.hair" "$tmp/c/g.$f.hair" || fail "frame $f differs in a split run"
  done
  cmp -s "$tmp/a/g.0001.hair" "$tmp/a/g.0006.hair" && fail "the head turned and the hair did not move"
  expect_rc 0 "$hairgen" simulate "$src/configs/pixar/target/setup.txt" --guides "$tmp/g.hair" -o "$tmp/t/g.####.hair" \
    --quiet --set "Dynamics.Frames=1 2"
  expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/d/g.####.hair" "${small[@]}" --set "Dynamics.PseudoForce=-0.75 0.1 0.01"
  grep -q "PseudoForce is a key of Model anjyo" "$tmp/err" || fail "anjyo key on springs: $(cat "$tmp/err")"
  # A key that would be read and not used is refused: a smoothing grid with no smoothing.
  expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/d/g.####.hair" "${small[@]}" --set Dynamics.VelocitySmoothing=0
  grep -q "SmoothingSpacing is the grid of VelocitySmoothing" "$tmp/err" || fail "unused SmoothingSpacing: $(cat "$tmp/err")"
  ;;
shot_run_equals_stages)
  # `run` on a shot writes what the stages chained by hand write: the simulated guides and every frame.
  setup="$src/configs/anjyo/gust/setup.txt"
  small=(--quiet --set Hairstyle.HairDensity=5 --set "Dynamics.Frames=1 4" --set "Render.Resolution=40 40")
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/run" "${small[@]}"
  expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/g.hair" "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/sim/g.####.hair" "${small[@]}"
  expect_rc 0 "$hairgen" interpolate "$setup" --guides "$tmp/sim/g.####.hair" -o "$tmp/c.####.hair" --frames 1-4 "${small[@]}"
  expect_rc 0 "$hairgen" interpolate "$setup" --guides "$tmp/g.hair" -o "$tmp/rest.hair" "${small[@]}"
  expect_rc 0 "$hairgen" shade "$setup" --hair "$tmp/rest.hair" -o "$tmp/rest-shaded.hair" "${small[@]}"
  expect_rc 0 "$hairgen" shade --rest "$tmp/rest-shaded.hair" "$tmp/c.####.hair" -o "$tmp/s.####.hair" --frames 1-4 --quiet
  expect_rc 0 "$hairgen" render "$setup" --hair "$tmp/s.####.hair" -o "$tmp/b.####.exr" --frames 1-4 "${small[@]}"
  # render --guides interpolates and re-poses each frame in memory, as run does.
  expect_rc 0 "$hairgen" render "$setup" --guides "$tmp/sim/g.####.hair" --rest "$tmp/rest-shaded.hair" \
    -o "$tmp/m.####.exr" --frames 1-4 "${small[@]}"
  for f in 0001 0004; do
    cmp "$tmp/run/sim/guides.$f.hair" "$tmp/sim/g.$f.hair" || fail "run's simulated frame $f differs"
    cmp "$tmp/run/beauty.$f.exr" "$tmp/b.$f.exr" || fail "run's frame $f differs from the stages'"
    cmp "$tmp/run/beauty.$f.exr" "$tmp/m.$f.exr" || fail "render --guides's frame $f differs from run's"
  done
  # With motion vectors too: the same frames, and the same vectors as render --motion.
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/runm" --motion "${small[@]}"
  expect_rc 0 "$hairgen" render "$setup" --hair "$tmp/s.####.hair" -o "$tmp/m.####.exr" --frames 1-4 --motion "${small[@]}"
  for f in 0001 0004; do
    cmp "$tmp/runm/beauty.$f.exr" "$tmp/m.$f.exr" || fail "run --motion's frame $f differs from the stages'"
  done
  expect_rc 2 "$hairgen" run "$src/configs/default/setup.txt" -o "$tmp/still" --motion --quiet
  expect_err "names no Dynamics Info"
  expect_rc 2 "$hairgen" render "$setup" --guides "$tmp/sim/g.####.hair" -o "$tmp/m.####.exr" --frames 1-4 "${small[@]}"
  grep -q -- "--rest" "$tmp/err" || fail "render --guides without --rest: $(cat "$tmp/err")"
  # scripts/setup.sh installs ffmpeg, so the movie is always checked.
  [ -s "$tmp/run/beauty.mp4" ] && [ -s "$tmp/run/beauty.gif" ] || fail "no preview movie"
  ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 \
    "$tmp/run/beauty.mp4" | grep -qx 4 || fail "the movie does not hold the shot's 4 frames"
  ;;
run_frames)
  # run --frames A-B on a shot writes exactly those frames, each equal byte for byte to the same frame
  # of the whole shot (simulated from its first frame; motion vectors from the frame before A).
  setup="$src/configs/anjyo/gust/setup.txt"
  small=(--quiet --set Hairstyle.HairDensity=5 --set "Dynamics.Frames=1 5" --set "Render.Resolution=40 40")
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/all" "${small[@]}"
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/part" --frames 1-3 "${small[@]}"
  [ "$(cd "$tmp/part" && echo sim/guides.*.hair beauty.*.exr)" = \
    "sim/guides.0001.hair sim/guides.0002.hair sim/guides.0003.hair beauty.0001.exr beauty.0002.exr beauty.0003.exr" ] ||
    fail "run --frames 1-3 wrote other frames: $(ls "$tmp/part" "$tmp/part/sim")"
  for f in 0001 0002 0003; do
    cmp "$tmp/all/sim/guides.$f.hair" "$tmp/part/sim/guides.$f.hair" || fail "run --frames: simulated frame $f differs"
    cmp "$tmp/all/beauty.$f.exr" "$tmp/part/beauty.$f.exr" || fail "run --frames: frame $f differs"
  done
  ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 \
    "$tmp/part/beauty.mp4" | grep -qx 3 || fail "the movie of run --frames 1-3 does not hold 3 frames"
  # A range after the shot's first frame, with motion vectors.
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/allm" --motion "${small[@]}"
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/partm" --motion --frames 3-4 "${small[@]}"
  [ ! -e "$tmp/partm/beauty.0002.exr" ] && [ ! -e "$tmp/partm/sim/guides.0002.hair" ] &&
    [ ! -e "$tmp/partm/beauty.0005.exr" ] || fail "run --frames 3-4 wrote frames outside 3-4"
  for f in 0003 0004; do
    cmp "$tmp/allm/sim/guides.$f.hair" "$tmp/partm/sim/guides.$f.hair" || fail "run --frames 3-4: simulated frame $f differs"
    cmp "$tmp/allm/beauty.$f.exr" "$tmp/partm/beauty.$f.exr" || fail "run --frames 3-4 --motion: frame $f differs"
  done
  expect_rc 2 "$hairgen" run "$src/configs/default/setup.txt" -o "$tmp/still" --frames 1-3 --quiet
  expect_err "names no Dynamics Info; a still has no frames"
  [ ! -e "$tmp/still" ] || fail "run --frames on a still made its output folder"
  expect_rc 2 "$hairgen" run "$setup" -o "$tmp/out6" --frames 4-9 "${small[@]}"
  expect_err "the shot's frames are 1-5"
  ;;
check_shot_time)
  # check on a shot estimates its time as well as its memory: each stage's, the frames' render (the
  # most of it), and the total.
  expect_rc 0 "$hairgen" check "$src/configs/shots/headturn/setup.txt"
  grep -Eq "^  render, 72 frames: about [0-9.]+ (MB|GB), [0-9]+ (s|min [0-9]+ s|h [0-9]+ min) \([0-9]+ s a frame\)" "$tmp/out" ||
    fail "check names no time for the render of the shot's frames: $(cat "$tmp/out")"
  grep -Eq "^  simulate, 72 frames: " "$tmp/out" || fail "check names no simulation: $(cat "$tmp/out")"
  grep -Eq "^  in all about [0-9]+ (s|min|h)" "$tmp/out" || fail "check names no total time: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" check "$src/configs/shots/headturn/setup.txt" --json
  python3 - "$tmp/out" <<'PY' || fail "check --json's times do not add up"
import json, sys
r = json.load(open(sys.argv[1]))
render = [w for w in r["work"] if w["stage"] == "render"]
assert len(render) == 1 and render[0]["frames"] == 72 and render[0]["seconds"] > 0, render
assert abs(sum(w["seconds"] for w in r["work"]) - r["workSeconds"]) < 1e-6 * r["workSeconds"]
PY
  # A still: one render, no frames.
  expect_rc 0 "$hairgen" check "$src/configs/default/setup.txt"
  grep -Eq "^  render: about [0-9.]+ (MB|GB), ([0-9]+ s|under a second)" "$tmp/out" || fail "check names no render time: $(cat "$tmp/out")"
  ;;
shot_headturn)
  # The bundled head turn, small: the shot runs end to end, the head has turned by its last frame (the
  # pictures differ) and the hair settles once the head stops.
  setup="$src/configs/shots/headturn/setup.txt"
  small=(--quiet --set Hairstyle.HairDensity=3 --set "Render.Resolution=48 48")
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/run" "${small[@]}"
  for f in 0001 0036 0072; do [ -s "$tmp/run/beauty.$f.exr" ] || fail "no frame $f"; done
  expect_rc 4 "$hairgen" diff "$tmp/run/beauty.0001.exr" "$tmp/run/beauty.0072.exr"
  # The share of pixels that change from one frame to the next: large while the head turns (frames
  # 10-22), small once the hair has settled (measured: 44% and 6%).
  changed() {
    "$hairgen" diff "$tmp/run/beauty.$1.exr" "$tmp/run/beauty.$2.exr" --channels R,G,B,A 2>&1 |
      sed -n 's/.*pixels (\([0-9.]*\)%) differ.*/\1/p'
  }
  turning=$(changed 0015 0016) settled=$(changed 0071 0072)
  awk -v t="$turning" -v s="${settled:-0}" 'BEGIN { exit !(t > 20 && s < t / 4) }' ||
    fail "the hair does not settle after the turn: ${turning}% of pixels change at frame 16, ${settled}% at 72"
  ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 \
    "$tmp/run/beauty.mp4" | grep -qx 72 || fail "the movie does not hold the shot's 72 frames"
  ;;
render_motion)
  # Motion vectors of a frame are the move since the frame before, read from the sequence whenever it
  # is in the shot: a range rendered in two jobs gives the bytes of one job.
  setup="$src/configs/anjyo/gust/setup.txt"
  small=(--quiet --set Hairstyle.HairDensity=5 --set "Dynamics.Frames=1 4" --set "Render.Resolution=40 40")
  expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/g.hair" "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/sim/g.####.hair" "${small[@]}"
  expect_rc 0 "$hairgen" render "$setup" --hair "$tmp/sim/g.####.hair" -o "$tmp/one/b.####.exr" --frames 1-4 --motion "${small[@]}"
  expect_rc 0 "$hairgen" render "$setup" --hair "$tmp/sim/g.####.hair" -o "$tmp/two/b.####.exr" --frames 1-2 --motion "${small[@]}"
  expect_rc 0 "$hairgen" render "$setup" --hair "$tmp/sim/g.####.hair" -o "$tmp/two/b.####.exr" --frames 3-4 --motion "${small[@]}"
  for f in 0001 0002 0003 0004; do
    cmp "$tmp/one/b.$f.exr" "$tmp/two/b.$f.exr" || fail "frame $f's motion differs when the range is split"
  done
  "$hairgen" info "$tmp/one/b.0003.exr" | grep -q "motion.u" || fail "no motion layer"
  expect_rc 2 "$hairgen" render "$setup" --hair "$tmp/sim/g.0001.hair" -o "$tmp/x.exr" --motion "${small[@]}"
  expect_err "needs --frames"
  rm "$tmp/sim/g.0002.hair"
  expect_rc 2 "$hairgen" render "$setup" --hair "$tmp/sim/g.####.hair" -o "$tmp/y/b.####.exr" --frames 3-4 --motion "${small[@]}"
  expect_err "g.0002.hair"
  [ ! -e "$tmp/y" ] || [ -z "$(ls -A "$tmp/y")" ] || fail "a failed render left frames behind"
  ;;
shards_merge)
  # grow and interpolate in 4 shards, merged in any order, give the whole run's bytes; merge refuses a
  # missing, an overlapping or a foreign shard, naming it.
  setup="$src/configs/default/setup.txt"
  small=(--quiet --set Hairstyle.HairDensity=20)
  expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/g.hair" "${small[@]}"
  for k in 1 2 3 4; do expect_rc 0 "$hairgen" grow "$setup" --shard $k/4 -o "$tmp/g.$k.hair" "${small[@]}"; done
  expect_rc 0 "$hairgen" info "$tmp/g.2.hair"
  grep -q "shard 2/4" "$tmp/out" || fail "info does not show the shard: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" merge "$tmp/g.3.hair" "$tmp/g.1.hair" "$tmp/g.4.hair" "$tmp/g.2.hair" -o "$tmp/gm.hair" -q
  cmp "$tmp/g.hair" "$tmp/gm.hair" || fail "merged guides differ from the whole run's"
  expect_rc 0 "$hairgen" interpolate "$setup" --guides "$tmp/g.hair" -o "$tmp/c.hair" "${small[@]}"
  for k in 1 2 3 4; do
    expect_rc 0 "$hairgen" interpolate "$setup" --guides "$tmp/g.hair" --shard $k/4 -o "$tmp/c.$k.hair" "${small[@]}"
  done
  expect_rc 0 "$hairgen" merge "$tmp"/c.[1-4].hair -o "$tmp/cm.hair" -q
  cmp "$tmp/c.hair" "$tmp/cm.hair" || fail "merged coupe differs from the whole run's"
  # The cantilever model (Anjyo's bob) splits the same way.
  bob="$src/configs/anjyo/bob/setup.txt"
  expect_rc 0 "$hairgen" grow "$bob" -o "$tmp/b.hair" --quiet
  for k in 1 2 3; do expect_rc 0 "$hairgen" grow "$bob" --shard $k/3 -o "$tmp/b.$k.hair" --quiet; done
  expect_rc 0 "$hairgen" merge "$tmp"/b.[1-3].hair -o "$tmp/bm.hair" -q
  cmp "$tmp/b.hair" "$tmp/bm.hair" || fail "merged cantilever guides differ"
  # Refusals, exit 2, naming the culprit; nothing written.
  expect_rc 2 "$hairgen" merge "$tmp/g.1.hair" "$tmp/g.2.hair" "$tmp/g.4.hair" -o "$tmp/x.hair" -q
  grep -q "a shard is missing: guides .* before $tmp/g.4.hair" "$tmp/err" || fail "missing: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" merge "$tmp/g.1.hair" "$tmp/g.2.hair" "$tmp/g.3.hair" -o "$tmp/x.hair" -q
  grep -q "a shard is missing: guides .*after $tmp/g.3.hair" "$tmp/err" || fail "missing last: $(cat "$tmp/err")"
  expect_rc 0 "$hairgen" grow "$setup" --shard 2/3 -o "$tmp/g.2of3.hair" "${small[@]}"
  expect_rc 2 "$hairgen" merge "$tmp"/g.[1-4].hair "$tmp/g.2of3.hair" -o "$tmp/x.hair" -q
  grep -q "g.2of3.hair.*shard 2/3" "$tmp/err" || fail "another split: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" merge "$tmp"/g.[1-4].hair "$tmp/g.2.hair" -o "$tmp/x.hair" -q
  grep -q "g.2.hair.*overlaps" "$tmp/err" || fail "overlap: $(cat "$tmp/err")"
  expect_rc 0 "$hairgen" grow "$setup" --shard 3/4 -o "$tmp/g.3x.hair" --quiet --set Hairstyle.HairDensity=20 --seed 7
  expect_rc 2 "$hairgen" merge "$tmp/g.1.hair" "$tmp/g.2.hair" "$tmp/g.3x.hair" "$tmp/g.4.hair" -o "$tmp/x.hair" -q
  grep -q "g.3x.hair: comes from another config" "$tmp/err" || fail "foreign: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" merge "$tmp/g.1.hair" "$tmp/c.2.hair" -o "$tmp/x.hair" -q
  expect_rc 2 "$hairgen" merge "$tmp/g.hair" -o "$tmp/x.hair" -q
  grep -q "g.hair: is not a shard" "$tmp/err" || fail "not a shard: $(cat "$tmp/err")"
  [ ! -e "$tmp/x.hair" ] || fail "a refused merge wrote its output"
  expect_rc 2 "$hairgen" grow "$setup" --shard 5/4 -o "$tmp/x.hair" -q
  expect_rc 2 "$hairgen" grow "$setup" --shard 1/4 -o "$tmp/x.glb" -q
  expect_rc 2 "$hairgen" interpolate "$setup" --guides "$tmp/g.hair" --shard 0/4 -o "$tmp/x.hair" -q
  ;;
farm_plan)
  # A plan of the default coupe and of a shot: tasks, dependencies, requests; --dry-run prints the sbatch
  # lines and submits nothing (no Slurm needed).
  setup="$src/configs/default/setup.txt"
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/still" --shards 3 --quiet --set Hairstyle.HairDensity=20
  plan="$tmp/still/plan.json"
  for id in grow.1 grow.3 merge-guides interpolate.3 merge-coupe render; do
    grep -q "\"id\": \"$id\"" "$plan" || fail "the still's plan has no task $id"
  done
  grep -q '"Hairstyle.HairDensity=20"' "$plan" || fail "the plan's commands lose the overrides"
  expect_rc 0 "$hairgen" farm plan "$src/configs/anjyo/gust/setup.txt" -o "$tmp/shot" --frames 1-12 --chunk 5 --quiet
  for id in simulate.1 simulate.3 shade render.3 movie; do
    grep -q "\"id\": \"$id\"" "$tmp/shot/plan.json" || fail "the shot's plan has no task $id"
  done
  ! grep -q '"render.4"' "$tmp/shot/plan.json" || fail "12 frames in chunks of 5 make 3 render tasks"
  expect_rc 0 "$hairgen" farm submit "$tmp/shot/plan.json" --scheduler slurm --dry-run --quiet
  grep -q "^job_grow=\$('sbatch' '--parsable' .*'--array=1,2,3,4'" "$tmp/out" || fail "dry run: $(cat "$tmp/out")"
  grep -qF "job_render=\$('sbatch' '--parsable' '--job-name=hairgen-render' '--array=1,2,3'" "$tmp/out" &&
    grep -qF "'--dependency=afterok:'\"\${job_shade}\"',afterok:'\"\${job_simulate__1}\"',afterok:'\"\${job_simulate__2}\"',afterok:'\"\${job_simulate__3}\"" "$tmp/out" ||
    fail "render waits for the simulation and the shaded rest coupe: $(cat "$tmp/out")"
  grep -qF "'--dependency=afterok:'\"\${job_render}\" '--kill-on-invalid-dep=yes' '$tmp/shot/slurm/movie.sh'" "$tmp/out" ||
    fail "the movie waits for every frame: $(cat "$tmp/out")"
  grep -q "^job_simulate__3=.*'--array=3'.*'--dependency=afterok:'\"\${job_merge_guides}\"',afterok:'\"\${job_simulate__2}\"" "$tmp/out" ||
    fail "a simulation chunk waits for the one before: $(cat "$tmp/out")"
  ! grep -q "interpolate-frames\|/frames/" "$tmp/shot/plan.json" || fail "the shot's plan writes per-frame coupes"
  grep -q "^job_merge_guides=.*'--dependency=afterok:'\"\${job_grow}\"" "$tmp/out" || fail "merge waits for every shard: $(cat "$tmp/out")"
  [ ! -e "$tmp/shot/slurm" ] || fail "a dry run wrote scripts"
  expect_rc 2 "$hairgen" farm plan "$src/configs/default/setup.txt" -o "$tmp/x" --frames 1-4 --quiet
  expect_rc 2 "$hairgen" farm submit "$src/tests/cli_test.sh" --scheduler slurm --dry-run
  grep -q "is not a hairgen farm plan" "$tmp/err" || fail "not a plan: $(cat "$tmp/err")"
  expect_rc 2 "$hairgen" farm submit "$plan" --scheduler pbs --dry-run
  # A mesh edited after the plan: its tasks' outputs could never carry the plan's digest, so submitting
  # it is refused until it is planned again.
  mkdir "$tmp/edit"
  cp "$src/configs/assets/wick.obj" "$tmp/edit/wick.obj"
  printf 'HairLengths 0.05\nHairDensity 5\n' > "$tmp/edit/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel wick.obj\n' > "$tmp/edit/setup.txt"
  expect_rc 0 "$hairgen" farm plan "$tmp/edit/setup.txt" -o "$tmp/edit/plan" --shards 1 --quiet
  expect_rc 0 "$hairgen" farm submit "$tmp/edit/plan/plan.json" --scheduler slurm --dry-run --quiet
  echo "# edited" >> "$tmp/edit/wick.obj"
  expect_rc 2 "$hairgen" farm submit "$tmp/edit/plan/plan.json" --scheduler slurm --dry-run
  expect_err "has changed since this plan was made"
  ;;
farm_slurm)
  # On a one-node Slurm (scripts/slurm-local.sh): the default coupe grown and interpolated in 4 shards,
  # merged, and a 24-frame shot rendered in chunks of 5 equal `hairgen run` byte for byte; a cancelled
  # render task fails --wait naming it, and submitting again redoes only that task.
  slurm="$src/scripts/slurm-local.sh"
  was_up=0; bash "$slurm" status && was_up=1
  bash "$slurm" start >"$tmp/slurm.log" 2>&1; rc=$?
  [ "$rc" -eq 0 ] || skip "no local Slurm: $(cat "$tmp/slurm.log")"
  [ "$was_up" -eq 1 ] || trap 'bash "$slurm" stop >/dev/null 2>&1; rm -rf "$tmp"' EXIT
  setup="$src/configs/default/setup.txt"
  small=(--quiet --set Hairstyle.HairDensity=20 --set "Render.Resolution=64 48")
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/farm" --shards 4 "${small[@]}"
  expect_rc 0 "$hairgen" farm submit "$tmp/farm/plan.json" --scheduler slurm --wait
  grep -q "^grow: job [0-9]* (4 tasks)" "$tmp/out" || fail "no job ids printed: $(cat "$tmp/out")"
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/run" "${small[@]}"
  for f in guides.hair coupe.hair beauty.exr; do cmp "$tmp/run/$f" "$tmp/farm/$f" || fail "farm's $f differs from run's"; done
  # The shot.
  gust="$src/configs/anjyo/gust/setup.txt"
  shot=(--quiet --set Hairstyle.HairDensity=5 --set "Render.Resolution=40 40")
  expect_rc 0 "$hairgen" farm plan "$gust" -o "$tmp/shot" --shards 4 --frames 1-24 --chunk 5 "${shot[@]}"
  "$hairgen" farm submit "$tmp/shot/plan.json" --scheduler slurm --wait >"$tmp/sub.out" 2>"$tmp/sub.err" &
  submitter=$!
  for _ in $(seq 100); do grep -q "^render: job" "$tmp/sub.out" && break; sleep 0.1; done
  job=$(sed -n 's/^render: job \([0-9]*\).*/\1/p' "$tmp/sub.out")
  [ -n "$job" ] || fail "no render job: $(cat "$tmp/sub.out" "$tmp/sub.err")"
  # Cancel chunk 3 (frames 11-15) mid-frame when the test sees it running, else while it waits.
  for _ in $(seq 1200); do
    state=$(squeue --noheader --array --jobs="${job}_3" --format=%T 2>/dev/null)
    [ "$state" = RUNNING ] && { sleep 0.3; break; }
    [ -z "$state" ] && break
    sleep 0.05
  done
  echo "render.3 was ${state:-gone} when cancelled"
  scancel "${job}_3"
  wait "$submitter"; rc=$?
  if [ "$rc" -eq 0 ]; then
    echo "render.3 finished before it could be cancelled: its outputs are removed instead"
    rm -f "$tmp"/shot/beauty.001[1-5].*
  else
    [ "$rc" -eq 1 ] || fail "--wait after a cancelled task exited $rc: $(cat "$tmp/sub.err")"
    if ! grep -q "task render.3 (job ${job}_3, log $tmp/shot/logs/render.3.log)\|render.3 (job ${job}_3" "$tmp/sub.err"; then
      # The cancel can land after the chunk committed its last frame and before the task ended (its five
      # 40x40 frames take a third of a second): its frames are whole, so the farm rightly counts it done,
      # and only the movie, which waited on it, never ran. Its frames are removed instead.
      [ -e "$tmp/shot/beauty.0015.png" ] && grep -q "1 task never ran (movie (job" "$tmp/sub.err" ||
        fail "--wait does not name the cancelled task: $(cat "$tmp/sub.err")"
      echo "render.3 had committed its frames when cancelled: they are removed instead"
      rm -f "$tmp"/shot/beauty.001[1-5].*
    fi
  fi
  [ ! -e "$tmp/shot/beauty.0015.png" ] || fail "the cancelled chunk finished"
  ! ls "$tmp/shot" | grep -q 'tmp-' || fail "the cancelled task left a temporary file: $(ls "$tmp/shot")"
  find "$tmp/shot" -name '*.hair' -o -name '*.exr' -o -name '*.png' | grep -v 'beauty\.001[1-5]\.' | sort |
    xargs stat -c '%n %.9Y' >"$tmp/before"
  expect_rc 0 "$hairgen" farm submit "$tmp/shot/plan.json" --scheduler slurm --wait
  # Only the cancelled chunk is redone, and the movie that waited on it.
  [ "$(grep -c ': job ' "$tmp/out")" -eq 2 ] && grep -q "^render: job [0-9]* (1 task)" "$tmp/out" &&
    grep -q "^movie: job [0-9]* (1 task)" "$tmp/out" ||
    fail "the resubmission redid more than the cancelled task and the movie: $(cat "$tmp/out")"
  ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 \
    "$tmp/shot/beauty.mp4" | grep -qx 24 || fail "the farm's movie does not hold the shot's 24 frames"
  [ -s "$tmp/shot/beauty.gif" ] || fail "the farm made no GIF"
  xargs stat -c '%n %.9Y' <<<"$(cut -d' ' -f1 "$tmp/before")" | cmp - "$tmp/before" || fail "a finished output was rewritten"
  expect_rc 0 "$hairgen" run "$gust" -o "$tmp/shotrun" "${shot[@]}" --set "Dynamics.Frames=1 24"
  for f in $(seq -f %04g 1 24); do
    cmp "$tmp/shotrun/sim/guides.$f.hair" "$tmp/shot/sim/guides.$f.hair" || fail "simulated frame $f differs"
    cmp "$tmp/shotrun/beauty.$f.exr" "$tmp/shot/beauty.$f.exr" || fail "frame $f differs from run's"
  done
  expect_rc 0 "$hairgen" farm submit "$tmp/shot/plan.json" --scheduler slurm --wait
  grep -q "every task is done" "$tmp/err" "$tmp/out" || fail "a done plan was submitted again: $(cat "$tmp/out")"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
