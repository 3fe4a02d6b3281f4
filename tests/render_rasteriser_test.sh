#!/usr/bin/env bash
# Where hairgen's rasteriser runs (issue 34: one rasteriser, one answer): `render --rasteriser device`
# (GLSL compute passes, compute_raster.h) and `--rasteriser cpu` (hair_raster.h on TBB's threads) write
# the same EXRs to the byte, image and --dom, a sequence's frames too; --stats says which ran, and on the
# device the time of each of its compute passes and transfers (device.passes, device.transfers: the next
# GPU session profiles with them); a word other than auto, cpu or device is refused.
source "$(dirname "$0")/cli_lib.sh" "$@"

setup="$src/configs/thesis/coupe2/setup.txt"
size=(--quiet --set "Render.Resolution=160 120" --set Render.Samples=4)

case "$case" in
  same_bytes)
    expect_rc 0 "$hairgen" interpolate "$setup" --guides "$src/golden/fixtures/guides-coupe2.hair" \
      -o "$tmp/coupe.hair" --quiet --set Hairstyle.HairDensity=10
    for where in cpu device; do
      "$hairgen" render "$setup" --hair "$tmp/coupe.hair" -o "$tmp/$where.exr" --dom "$tmp/dom-$where.exr" \
        "${size[@]}" --rasteriser "$where" --stats "$tmp/$where.json"
      rc=$?
      [ "$rc" -eq 3 ] && skip "no rendering device here"
      [ "$rc" -eq 0 ] || fail "render --rasteriser $where exited $rc"
      grep -q "\"rasteriser\": *\"$where\"" "$tmp/$where.json" || fail "--stats does not say $where: $(cat "$tmp/$where.json")"
    done
    cmp "$tmp/cpu.exr" "$tmp/device.exr" || fail "the image differs between the CPU's and the device's rasteriser"
    cmp "$tmp/dom-cpu.exr" "$tmp/dom-device.exr" || fail "the light's maps differ"
    ;;
  sequence_same_bytes)
    expect_rc 0 "$hairgen" interpolate "$setup" --guides "$src/golden/fixtures/guides-coupe2.hair" \
      -o "$tmp/coupe.0001.hair" --quiet --set Hairstyle.HairDensity=5
    cp "$tmp/coupe.0001.hair" "$tmp/coupe.0002.hair"
    for where in cpu device; do
      "$hairgen" render "$setup" --hair "$tmp/coupe.####.hair" --frames 1-2 -o "$tmp/$where.####.exr" "${size[@]}" \
        --rasteriser "$where"
      rc=$?
      [ "$rc" -eq 3 ] && skip "no rendering device here"
      [ "$rc" -eq 0 ] || fail "render --frames --rasteriser $where exited $rc"
    done
    for f in 0001 0002; do cmp "$tmp/cpu.$f.exr" "$tmp/device.$f.exr" || fail "frame $f differs"; done
    ;;
  device_stats)
    expect_rc 0 "$hairgen" interpolate "$setup" --guides "$src/golden/fixtures/guides-coupe2.hair" \
      -o "$tmp/coupe.0001.hair" --quiet --set Hairstyle.HairDensity=5
    cp "$tmp/coupe.0001.hair" "$tmp/coupe.0002.hair"
    for where in cpu device; do
      "$hairgen" render "$setup" --hair "$tmp/coupe.0001.hair" -o "$tmp/$where.exr" "${size[@]}" \
        --rasteriser "$where" --stats "$tmp/$where.json"
      rc=$?
      [ "$rc" -eq 3 ] && skip "no rendering device here"
      [ "$rc" -eq 0 ] || fail "render --rasteriser $where exited $rc"
    done
    "$hairgen" render "$setup" --hair "$tmp/coupe.####.hair" --frames 1-2 -o "$tmp/seq.####.exr" "${size[@]}" \
      --rasteriser device --stats "$tmp/seq.json" || fail "render --frames --rasteriser device failed"
    # Every pass and transfer, each a time of its own, not negative and no more than the host
    # waited for it: the camera's passes fit in hairFragmentSeconds (device seconds, not nanoseconds);
    # the CPU's rasteriser lists none; a sequence's frames add up.
    python3 - "$tmp" <<'PY' || fail "--stats' device passes: $(cat "$tmp/device.json")"
import json, sys
d = json.load(open(sys.argv[1] + "/device.json"))["device"]
passes = ["light_start", "light_layers", "light_finish", "camera_count", "camera_scan", "camera_fill",
          "camera_keep", "camera_first", "camera_pack"]
transfers = ["light_upload", "camera_upload", "camera_totals_read", "camera_kept_read"]
assert list(d["passes"]) == passes, list(d["passes"])
assert list(d["transfers"]) == transfers, list(d["transfers"])
for p in d["passes"].values():
    assert p["seconds"] >= 0 and p["runs"] >= 1, p
for t in d["transfers"].values():
    assert t["seconds"] >= 0 and t["bytes"] > 0 and t["runs"] >= 1, t
camera = sum(v["seconds"] for k, v in d["passes"].items() if k.startswith("camera_"))
assert 0 < camera <= d["hairFragmentSeconds"] * 1.01 + 0.001, (camera, d["hairFragmentSeconds"])
cpu = json.load(open(sys.argv[1] + "/cpu.json"))["device"]
assert cpu["passes"] == {} and cpu["transfers"] == {}, cpu
seq = json.load(open(sys.argv[1] + "/seq.json"))["device"]
assert all(seq["passes"][k]["runs"] == 2 * d["passes"][k]["runs"] for k in passes), seq["passes"]
assert seq["transfers"]["camera_upload"]["bytes"] == 2 * d["transfers"]["camera_upload"]["bytes"], seq
PY
    ;;
  unknown_word)
    expect_rc 2 "$hairgen" render "$setup" -o "$tmp/x.exr" --rasteriser gpu
    expect_err "--rasteriser"
    [ ! -e "$tmp/x.exr" ] || fail "an image was written"
    ;;
  *) fail "unknown case" ;;
esac
echo "ok ($case)"
