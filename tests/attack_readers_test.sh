#!/usr/bin/env bash
# The readers, writers, render estimate and merge against hostile or real inputs (issue 32): every reader
# linear in its input and sized against the file, text from a file escaped in every text format, one-line
# errors naming the file, frame or key. Time-bounded, so a regression fails rather than hangs.
# Usage: attack_readers_test.sh HAIRGEN SOURCE_DIR CASE
source "$(dirname "$0")/cli_lib.sh" "$@"

# A small valid OpenEXR (scanlines in ZIP chunks of 16, as hairgen writes them) of W x H pixels with
# channels A B G R (half) and Z d1 d2 (float); with DECLARED, the header's data window is DECLARED
# pixels a side and nothing else changes: a 13 kB file that says 16384 x 16384.
write_exr() { # file W H [DECLARED]
  python3 - "$@" <<'EOF'
import random, struct, sys, zlib
out, w, h = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
dw = dh = int(sys.argv[4]) if len(sys.argv) > 4 else None
if dw is None: dw, dh = w, h
rng = random.Random(1)
chans = [("A", 1), ("B", 1), ("G", 1), ("R", 1), ("Z", 2), ("d1", 2), ("d2", 2)]  # 1 half, 2 float
def attr(name, typ, data):
    return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(data)) + data
chl = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", t, 0, 1, 1) for n, t in chans) + b"\0"
hdr = b"\x76\x2f\x31\x01" + struct.pack("<I", 2) + attr("channels", "chlist", chl)
hdr += attr("compression", "compression", b"\x03")
hdr += attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, dw - 1, dh - 1))
hdr += attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, dw - 1, dh - 1))
hdr += attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
hdr += attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
hdr += attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0"
def row():
    return b"".join(b"".join(struct.pack("<H", 0x3000 + rng.randrange(0x0c00)) for _ in range(w)) if n == "R"
                    else (b"\0\x3c" if t == 1 else struct.pack("<f", 0.5)) * w for n, t in chans)
def deflate(raw):  # EXR's ZIP: bytes split into even and odd halves, delta-coded, then zlib
    t = bytearray(raw[0::2] + raw[1::2])
    for i in range(len(t) - 1, 0, -1): t[i] = (t[i] - t[i - 1] + 128) & 255
    c = zlib.compress(bytes(t), 9)
    return c if len(c) < len(raw) else raw
n = (h + 15) // 16
chunks, offsets = b"", []
for c in range(n):
    data = deflate(b"".join(row() for _ in range(min(16, h - 16 * c))))
    offsets.append(len(hdr) + 8 * n + len(chunks))
    chunks += struct.pack("<ii", 16 * c, len(data)) + data
open(out, "wb").write(hdr + b"".join(struct.pack("<Q", o) for o in offsets) + chunks)
EOF
}

# An ASCII PLY of two strands of three points; COMMENT (bytes, printf-escaped) as its comment line.
write_ply() { # file comment
  printf 'ply\nformat ascii 1.0\ncomment %b\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\nelement strand 2\nproperty ushort nsegs\nend_header\n0 0 0\n0 0.01 0\n0 0.02 0\n0.01 0 0\n0.01 0.01 0\n0.01 0.02 0\n2\n2\n' "$2" > "$1"
}

# A USC-HairSalon .data file: a strand count, then per strand a point count and its points (little-endian).
write_data() { # file count points...
  python3 - "$@" <<'EOF'
import struct, sys
out, counts = sys.argv[1], [int(c) for c in sys.argv[2:]]
body = struct.pack("<i", len(counts))
for c in counts: body += struct.pack("<i", c) + struct.pack("<3f", 0, 0, 0) * max(c, 0)
open(out, "wb").write(body)
EOF
}

case "$case" in
ply_header_linear)
  # 300,000 properties in one element, 4.5 MB of header: read in linear time (quadratic took minutes).
  python3 - "$tmp/wide.ply" <<'EOF'
import sys
lines = ["ply", "format ascii 1.0", "element vertex 1"] + ["property float p%d" % i for i in range(300000)]
lines += ["property float x", "property float y", "property float z", "property float p7", "end_header"]
open(sys.argv[1], "w").write("\n".join(lines) + "\n")
EOF
  [ "$(stat -c %s "$tmp/wide.ply")" -gt 4500000 ] || fail "the header is too small to tell"
  expect_rc 2 timeout 10 "$hairgen" info "$tmp/wide.ply"
  expect_err "wide.ply:300007: property 'p7' appears twice in element 'vertex'"
  ;;
obj_names_linear)
  # 200,000 distinct group, object and material names: read in linear time, and the error that lists
  # them stays one short line.
  python3 - "$tmp/names.obj" <<'EOF'
import sys
with open(sys.argv[1], "w") as f:
    f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    for i in range(200000): f.write("%s n%d\nf 1 2 3\n" % (("g", "o", "usemtl")[i % 3], i))
EOF
  expect_rc 0 timeout 10 "$hairgen" info "$tmp/names.obj"
  grep -q "200000 triangles" "$tmp/out" || fail "info: $(cat "$tmp/out")"
  printf 'HairLengths 0.04\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel names.obj\nWickGroup scalp\n' > "$tmp/setup.txt"
  expect_rc 2 timeout 10 "$hairgen" grow "$tmp/setup.txt" -o "$tmp/g.hair"
  expect_err "WickGroup 'scalp' is not a group, object or material of this mesh; it has n0, n1,"
  expect_err "and 199980 more"
  [ "$(wc -c < "$tmp/err")" -lt 1000 ] || fail "the error lists every name: $(wc -c < "$tmp/err") bytes"
  ;;
exr_header_sized)
  # A 13 kB EXR whose header says 16384 x 16384 (7 channels: 7.5 GB as floats) is refused at once, by
  # every command that reads an EXR, and under another name; the same file with its true header reads.
  write_exr "$tmp/ok.exr" 64 96
  write_exr "$tmp/lie.exr" 64 96 16384
  [ "$(stat -c %s "$tmp/lie.exr")" -lt 20000 ] || fail "the lying file is not small"
  expect_rc 0 timeout 10 "$hairgen" diff "$tmp/ok.exr" "$tmp/ok.exr"
  expect_rc 0 timeout 10 "$hairgen" info "$tmp/ok.exr"
  grep -q "64x96, 7 channels" "$tmp/out" || fail "info: $(cat "$tmp/out")"
  expect_rc 2 timeout 10 "$hairgen" diff "$tmp/lie.exr" "$tmp/ok.exr"
  expect_err "lie.exr: "
  [ "$(wc -l < "$tmp/err")" -eq 1 ] || fail "not one line: $(cat "$tmp/err")"
  expect_rc 2 timeout 10 "$hairgen" info "$tmp/lie.exr"
  expect_err "lie.exr: "
  cp "$tmp/lie.exr" "$tmp/lie.png"
  expect_rc 2 timeout 10 "$hairgen" diff "$tmp/lie.png" "$tmp/ok.exr"
  expect_err "lie.png: "
  ;;
render_strand_width)
  # Render.StrandWidth 0.5 (legal: (0, 1]) on coupe 3's 759 guides drew 759 sheets for 40 s: refused at
  # once, naming the key; the default width renders.
  setup="$src/configs/thesis/coupe3/setup.txt"
  expect_rc 0 timeout 120 "$hairgen" grow "$setup" -o "$tmp/g.hair" --quiet
  "$hairgen" render --list-devices >/dev/null 2>&1 || skip "no rendering device here"
  expect_rc 2 timeout 20 "$hairgen" render "$setup" --hair "$tmp/g.hair" -o "$tmp/w.exr" --quiet \
    --set Render.StrandWidth=0.5
  expect_err "Render.StrandWidth 0.5 m draws each strand about"
  expect_err "--force"
  [ ! -e "$tmp/w.exr" ] || fail "an image was written after the refusal"
  expect_rc 0 timeout 120 "$hairgen" render "$setup" --hair "$tmp/g.hair" -o "$tmp/n.exr" --quiet
  ;;
merge_counts)
  # A part whose strands are not the guides its range declares is refused, naming the part.
  setup="$src/configs/default/setup.txt"
  small=(--quiet --set Hairstyle.HairDensity=20)
  # Shards are written as .hair; as PLY their provenance is comments a script can edit.
  for k in 1/2 2/2 1/3; do
    expect_rc 0 timeout 120 "$hairgen" grow "$setup" --shard $k -o "$tmp/g.${k/\//of}.hair" "${small[@]}"
    expect_rc 0 "$hairgen" convert "$tmp/g.${k/\//of}.hair" "$tmp/g.${k/\//of}.ply" --quiet
  done
  expect_rc 0 "$hairgen" merge "$tmp/g.1of2.ply" "$tmp/g.2of2.ply" -o "$tmp/m.hair" -q
  range=$(grep -a -o 'range=[0-9]*-[0-9]*/' "$tmp/g.2of2.ply" | head -1 | tr -dc '0-9-')
  first=${range%-*} end=${range#*-}
  # Shard 1/3's guides (a third of them) labelled as shard 2/2 (half of them).
  python3 - "$tmp/g.1of3.ply" "$tmp/fake.ply" "$first" "$end" <<'EOF'
import re, sys
data = open(sys.argv[1], "rb").read()
head, body = data.split(b"end_header\n", 1)
head = re.sub(rb"shard=1/3", b"shard=2/2", head)
head = re.sub(rb"range=\d+-\d+/", b"range=%s-%s/" % (sys.argv[3].encode(), sys.argv[4].encode()), head)
open(sys.argv[2], "wb").write(head + b"end_header\n" + body)
EOF
  expect_rc 2 "$hairgen" merge "$tmp/g.1of2.ply" "$tmp/fake.ply" -o "$tmp/x.hair" -q
  expect_err "fake.ply: holds "
  expect_err " strands, but its range $first-$end declares"
  [ ! -e "$tmp/x.hair" ] || fail "a merge was written"
  # A range that is not the one its K/N gives is refused too.
  python3 - "$tmp/g.2of2.ply" "$tmp/shifted.ply" <<'EOF'
import re, sys
data = open(sys.argv[1], "rb").read()
head, body = data.split(b"end_header\n", 1)
head = re.sub(rb"range=(\d+)-", lambda m: b"range=%d-" % (int(m.group(1)) + 1), head)
open(sys.argv[2], "wb").write(head + b"end_header\n" + body)
EOF
  expect_rc 2 "$hairgen" merge "$tmp/g.1of2.ply" "$tmp/shifted.ply" -o "$tmp/x.hair" -q
  expect_err "shifted.ply: declares shard 2/2 as guides"
  ;;
text_escaped)
  # A NUL and a line end in a PLY comment, and bytes that are not UTF-8, reach no text format raw: the
  # .usda, the glTF JSON, a PLY header, info's lines and JSON, --stats; every conversion succeeds.
  write_ply "$tmp/nul.ply" 'made by \0000 tool\r with \0377\0376 bytes'
  for out in n.usda n.gltf n.glb n.ply n.hair; do
    expect_rc 0 timeout 10 "$hairgen" convert "$tmp/nul.ply" "$tmp/$out" --quiet --stats "$tmp/$out.json"
  done
  python3 - "$tmp" <<'EOF' || fail "raw bytes in a text output"
import json, sys
d = sys.argv[1]
for name in ["n.usda", "n.gltf", "n.gltf.json", "n.glb.json", "n.usda.json"]:
    data = open(d + "/" + name, "rb").read()
    assert b"\0" not in data and b"\r" not in data, name
    data.decode("utf-8")
    if name.endswith(".json") or name.endswith(".gltf"): json.loads(data)
usda = open(d + "/n.usda", "rb").read()
assert b"made by \\\\x00" in usda, usda[:600]
assert "\ufffd\ufffd bytes".encode() in usda, usda[:600]
head = open(d + "/n.ply", "rb").read().split(b"end_header")[0]
assert b"\0" not in head and b"\r" not in head and b"\xff" not in head, head
EOF
  for file in n.hair n.glb n.ply; do
    expect_rc 0 timeout 10 "$hairgen" info "$tmp/$file"
    python3 -c "import sys; d = open(sys.argv[1], 'rb').read(); d.decode(); assert b'\0' not in d" "$tmp/out" ||
      fail "info $file printed raw bytes"
    grep -qF 'made by \x00' "$tmp/out" || fail "info $file: $(cat "$tmp/out")"
    expect_rc 0 timeout 10 "$hairgen" info "$tmp/$file" --json
    python3 -c "import json, sys; json.load(open(sys.argv[1]))" "$tmp/out" || fail "info --json $file"
  done
  # An independent reader (TinyUSDZ, when tools/ has it) reads the .usda as hairgen describes the strands.
  reader="$src/tools/node_modules/tinyusdz"
  if [ -f "$reader/tinyusdz.wasm" ] && command -v node >/dev/null; then
    "$hairgen" info "$tmp/nul.ply" --json > "$tmp/nul.json" || fail "info nul.ply --json"
    node "$src/tests/validate_usd.mjs" "$reader" "$tmp/n.usda" "$tmp/nul.json" >"$tmp/v" 2>&1 ||
      fail "TinyUSDZ cannot read the .usda: $(cat "$tmp/v")"
  fi
  ;;
plan_version)
  # A farm plan's version of another JSON type is a bad plan (exit 2), not an internal error.
  printf '{"format": "hairgen-farm-plan", "version": "two\\u0000"}' > "$tmp/plan.json"
  expect_rc 2 "$hairgen" farm submit "$tmp/plan.json" --scheduler slurm
  expect_err 'plan.json: is a farm plan of version "two\u0000"; this hairgen reads version 1'
  ;;
shade_rest_frame)
  # shade --rest over a sequence names the frame whose strands are not the rest's.
  setup="$src/configs/default/setup.txt"
  expect_rc 0 timeout 120 "$hairgen" run "$setup" -o "$tmp/r" --no-render --quiet --set Hairstyle.HairDensity=10
  expect_rc 0 timeout 120 "$hairgen" shade "$setup" --hair "$tmp/r/coupe.hair" -o "$tmp/r/shaded.hair" --quiet \
    --set Render.ShadingModel=volumetric
  expect_rc 0 timeout 120 "$hairgen" interpolate "$setup" --guides "$tmp/r/guides.hair" -o "$tmp/c.0002.hair" \
    --quiet --set Hairstyle.HairDensity=12
  cp "$tmp/r/coupe.hair" "$tmp/c.0001.hair"
  expect_rc 2 timeout 60 "$hairgen" shade --rest "$tmp/r/shaded.hair" "$tmp/c.####.hair" -o "$tmp/s.####.hair" \
    --frames 1-2 --quiet
  expect_err "c.0002.hair: the coupe's strand ids differ from the rest coupe's"
  [ "$(wc -l < "$tmp/err")" -eq 1 ] || fail "not one line: $(cat "$tmp/err")"
  ;;
writer_names_file)
  # What a writer refuses names the file it would have written; a negative count says so.
  write_data "$tmp/bare.data" 3 0
  expect_rc 2 "$hairgen" convert "$tmp/bare.data" "$tmp/out.hair" --quiet
  expect_err "out.hair: strand 1 has no points; a .hair file cannot store it"
  [ ! -e "$tmp/out.hair" ] || fail "a refused output was written"
  # USD leaves the strand out instead, and says so naming the file (issue 36).
  expect_rc 0 "$hairgen" convert "$tmp/bare.data" "$tmp/out.usda" --quiet
  expect_err "out.usda: 1 strand(s) of fewer than two points (bare follicles) left out"
  write_data "$tmp/neg.data" 3 -5
  expect_rc 2 "$hairgen" convert "$tmp/neg.data" "$tmp/out.hair" --quiet
  expect_err "neg.data: strand 1's point count is -5, negative"
  printf '\xfb\xff\xff\xff' > "$tmp/negs.data"
  expect_rc 2 "$hairgen" info "$tmp/negs.data"
  expect_err "negs.data: the header's strand count is -5, negative"
  ;;
mesh_format)
  # A head or wick in another format is refused as such, naming the key, before it is parsed as OBJ.
  write_ply "$tmp/head.ply" 'a head'
  printf 'HairLengths 0.04\n' > "$tmp/h.txt"
  printf 'HairstyleInfo h.txt\nWickModel %s\nHeadModel head.ply\n' "$src/configs/assets/wick.obj" > "$tmp/setup.txt"
  expect_rc 2 timeout 60 "$hairgen" check "$tmp/setup.txt"
  expect_err "head.ply: HeadModel ($tmp/setup.txt:3) must be an OBJ mesh (.obj), and this is a PLY file"
  cp "$tmp/head.ply" "$tmp/head.obj"
  printf 'HairstyleInfo h.txt\nWickModel head.obj\n' > "$tmp/setup.txt"
  expect_rc 2 timeout 60 "$hairgen" grow "$tmp/setup.txt" -o "$tmp/g.hair"
  expect_err "head.obj: WickModel ($tmp/setup.txt:2) must be an OBJ mesh (.obj), and this is a PLY file"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
