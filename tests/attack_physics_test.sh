#!/usr/bin/env bash
# Issue 32's attack on the simulation (area `physics`): a restart state is an input and is refused
# (exit 2, naming the file, nothing written) when it was crafted, comes from other rest guides or from
# a hairgen that did not record them; a simulation that leaves its validity stops with exit 2 naming
# the key, the frame and the strand, and writes nothing of that frame; unreasonable FrameRate, MeshUnits
# and DensitySpacings are refused by range with their unit, and the density grids' memory by estimate.
source "$(dirname "$0")/cli_lib.sh" "$@"

springs="$src/configs/pixar/headturn/setup.txt"
anjyo="$src/configs/anjyo/gust/setup.txt"

# rechunk IN OUT TAG PERL: OUT is the .hair file IN with the payload of its chunk TAG ($_ in the perl
# code PERL) rewritten, and its length and CRC-32 made right again: a state crafted as a file is.
rechunk() {
  perl -MCompress::Zlib -e '
    my ($in, $out, $tag, $code) = @ARGV;
    open(my $f, "<:raw", $in) or die "$in: $!"; local $/; my $b = <$f>; close $f;
    my $block = index($b, "HGEN"); my $at = index($b, $tag, $block);
    die "no chunk $tag in $in\n" if $block < 0 || $at < 0;
    my $length = unpack("Q<", substr($b, $at + 4, 8));
    local $_ = substr($b, $at + 12, $length);
    eval $code; die $@ if $@;
    my $head = $tag . pack("Q<", length($_));
    substr($b, $at, 12 + $length + 4) = $head . $_ . pack("V", crc32($head . $_));
    open(my $o, ">:raw", $out) or die "$out: $!"; print $o $b; close $o;' "$@" || fail "rechunk $*"
}

# The frame a divergence message names ("frame N: ...").
failed_frame() { sed -n 's/.*error: frame \([0-9]*\): .*/\1/p' "$tmp/err" | head -n 1; }

case "$case" in
restart_crafted_springs)
  # Frame 2 of a springs shot with one value of its state changed: a position of 1e200 m (it crashed),
  # of 1e30 m (it resumed, strands 1e16 m long), a NaN, a velocity past any hair's, and a state a
  # segment short. Each is refused naming the file, and frame 3 is not written.
  small=(--quiet --set "Dynamics.Frames=1 4" --set Dynamics.Substeps=2)
  expect_rc 0 "$hairgen" grow "$springs" -o "$tmp/g.hair" --quiet
  expect_rc 0 "$hairgen" simulate "$springs" --guides "$tmp/g.hair" -o "$tmp/a/g.####.hair" --frames 1-2 "${small[@]}"
  cp "$tmp/a/g.0002.hair" "$tmp/good.hair"
  for craft in 'substr($_, 0, 8) = pack("d<", 1e200)' 'substr($_, 8, 8) = pack("d<", 1e30)' \
               'substr($_, 16, 8) = pack("Q<", 0x7ff8000000000000)' 'substr($_, 24, 8) = pack("d<", 1e5)' \
               '$_ = substr($_, 0, length($_) - 48)'; do
    rechunk "$tmp/good.hair" "$tmp/a/g.0002.hair" DYNS "$craft"
    expect_rc 2 "$hairgen" simulate "$springs" --guides "$tmp/g.hair" -o "$tmp/a/g.####.hair" --frames 3-4 "${small[@]}"
    expect_err "g.0002.hair"
    [ ! -e "$tmp/a/g.0003.hair" ] || fail "wrote frame 3 from a crafted state ($craft)"
  done
  # The state as written resumes.
  cp "$tmp/good.hair" "$tmp/a/g.0002.hair"
  expect_rc 0 "$hairgen" simulate "$springs" --guides "$tmp/g.hair" -o "$tmp/a/g.####.hair" --frames 3-4 "${small[@]}"
  ;;
restart_crafted_anjyo)
  small=(--quiet --set Hairstyle.HairDensity=5 --set "Dynamics.Frames=1 4")
  expect_rc 0 "$hairgen" grow "$anjyo" -o "$tmp/g.hair" "${small[@]}"
  expect_rc 0 "$hairgen" simulate "$anjyo" --guides "$tmp/g.hair" -o "$tmp/a/g.####.hair" --frames 1-2 "${small[@]}"
  cp "$tmp/a/g.0002.hair" "$tmp/good.hair"
  for craft in 'substr($_, 64, 4) = pack("f<", 1e30)' 'substr($_, 64, 8) = pack("Q<", 0x7ff8000000000000)' \
               '$_ = substr($_, 0, length($_) - 8)' 'substr($_, 0, 8) = pack("d<", 1)'; do
    rechunk "$tmp/good.hair" "$tmp/a/g.0002.hair" DYNS "$craft"
    expect_rc 2 "$hairgen" simulate "$anjyo" --guides "$tmp/g.hair" -o "$tmp/a/g.####.hair" --frames 3-4 "${small[@]}"
    expect_err "g.0002.hair"
    [ ! -e "$tmp/a/g.0003.hair" ] || fail "wrote frame 3 from a crafted state ($craft)"
  done
  ;;
restart_other_guides)
  # A cache simulated from other rest guides with the same strand layout (grown under another gravity)
  # is refused for both models, as is one from a hairgen that did not record its rest guides.
  for model in springs anjyo; do
    setup=${!model}
    small=(--quiet --set "Dynamics.Frames=1 4" --set Dynamics.Substeps=2)
    [ "$model" = anjyo ] && small+=(--set Hairstyle.HairDensity=5)
    expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/$model-g1.hair" --quiet
    expect_rc 0 "$hairgen" grow "$setup" -o "$tmp/$model-g2.hair" --quiet --set Hairstyle.Gravity=5
    cmp -s "$tmp/$model-g1.hair" "$tmp/$model-g2.hair" && fail "$model: the two groups of guides are the same"
    out="$tmp/$model/g.####.hair"
    expect_rc 0 "$hairgen" simulate "$setup" --guides "$tmp/$model-g1.hair" -o "$out" --frames 1-2 "${small[@]}"
    expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/$model-g2.hair" -o "$out" --frames 3-4 "${small[@]}"
    expect_err "g.0002.hair: was simulated from other rest guides"
    [ ! -e "$tmp/$model/g.0003.hair" ] || fail "$model: wrote frame 3 from other guides' state"
    cp "$tmp/$model/g.0002.hair" "$tmp/$model-good.hair"
    rechunk "$tmp/$model-good.hair" "$tmp/$model/g.0002.hair" PROV 's/^rest=.*\n//m'
    expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/$model-g1.hair" -o "$out" --frames 3-4 "${small[@]}"
    expect_err "g.0002.hair: was made by another hairgen"
  done
  ;;
diverge_springs)
  # Legal settings that stretched the hair without limit, all exit 0: now each stops at the frame where
  # the hair leaves its validity, naming the key that drove it, the frame and the strand, and that frame
  # is not written (the frames before it are).
  expect_rc 0 "$hairgen" grow "$springs" -o "$tmp/g.hair" --quiet
  run=0
  # (FrameRate on the wind shot: the head turn's head is still for its first frames. Gravity 1000, the
  # key's largest, diverged too while the rest tension was explicit; implicit, it holds.)
  for set in "Dynamics.Wind=1 100 0 0" "Dynamics.FrameRate=1"; do
    key=${set%%=*}
    run=$((run + 1))
    setup=$springs
    [ "$key" = Dynamics.FrameRate ] && setup="$src/configs/pixar/wind/setup.txt"
    expect_rc 2 "$hairgen" simulate "$setup" --guides "$tmp/g.hair" -o "$tmp/$run/g.####.hair" --quiet \
      --set "Dynamics.Frames=1 8" --set "$set"
    expect_err "$key"
    expect_err "left its validity"
    grep -q "strand [0-9]" "$tmp/err" || fail "$set: no strand named: $(cat "$tmp/err")"
    frame=$(failed_frame)
    [ -n "$frame" ] || fail "$set: no frame named: $(cat "$tmp/err")"
    [ ! -e "$tmp/$run/g.$(printf %04d "$frame").hair" ] || fail "$set: frame $frame was written"
    # A failed frame never costs the frames that succeeded: every frame before it is kept.
    for ((f = 1; f < frame; f++)); do
      [ -s "$tmp/$run/g.$(printf %04d "$f").hair" ] || fail "$set: frame $f, before the divergence, is gone"
    done
  done
  # The Fig. 5 shot's density force at 1e9 m/s².
  expect_rc 2 "$hairgen" simulate "$src/configs/pixar/target/setup.txt" --guides "$tmp/g.hair" -o "$tmp/t/g.####.hair" \
    --quiet --set "Dynamics.Frames=1 4" --set Dynamics.DensityStrength=1e9
  expect_err "Dynamics.DensityStrength"
  frame=$(failed_frame)
  [ -n "$frame" ] && [ ! -e "$tmp/t/g.$(printf %04d "$frame").hair" ] || fail "density: $(cat "$tmp/err")"
  ;;
diverge_anjyo)
  # Anjyo's gust under a 10000 m/s² wind in steps of a second: the recurrences overflow (a turn past
  # 1000 rad a substep). It wrote those frames with exit 0, frames a restart then refused; now it stops
  # at the first, naming the wind, the step's keys, the frame and the strand.
  small=(--quiet --set Hairstyle.HairDensity=5 --set "Dynamics.Frames=1 4")
  expect_rc 0 "$hairgen" grow "$anjyo" -o "$tmp/g.hair" "${small[@]}"
  expect_rc 2 "$hairgen" simulate "$anjyo" --guides "$tmp/g.hair" -o "$tmp/a/g.####.hair" "${small[@]}" \
    --set Dynamics.Substeps=1 --set Dynamics.FrameRate=1 --set "Dynamics.Wind=1 10000 0 0"
  for word in "Dynamics.Wind 10000" "Dynamics.FrameRate 1" "Dynamics.Substeps 1" "left its validity"; do
    expect_err "$word"
  done
  grep -q "strand [0-9]" "$tmp/err" || fail "no strand named: $(cat "$tmp/err")"
  frame=$(failed_frame)
  [ -n "$frame" ] && [ ! -e "$tmp/a/g.$(printf %04d "$frame").hair" ] || fail "frame ${frame:-?}: $(cat "$tmp/err")"
  ;;
ranges)
  # Out of physical range, refused before any work with the unit: FrameRate (frames/s), MeshUnits
  # (metres per unit), DensitySpacings (m).
  expect_rc 0 "$hairgen" grow "$springs" -o "$tmp/g.hair" --quiet
  for rate in 0.1 1e-20 1e-100 20000; do
    expect_rc 2 "$hairgen" simulate "$springs" --guides "$tmp/g.hair" -o "$tmp/s/g.####.hair" --quiet \
      --set "Dynamics.FrameRate=$rate"
    expect_err "FrameRate"
    expect_err "frames/s"
  done
  for units in 1e-300 1e300 1e-9 1e4; do
    expect_rc 2 "$hairgen" grow "$springs" -o "$tmp/u.hair" --quiet --set "Setup.MeshUnits=$units"
    expect_err "MeshUnits"
    expect_err "metres per unit"
    [ ! -e "$tmp/u.hair" ] || fail "MeshUnits $units: grew guides"
  done
  expect_rc 2 "$hairgen" simulate "$src/configs/pixar/target/setup.txt" --guides "$tmp/g.hair" -o "$tmp/t/g.####.hair" \
    --quiet --set "Dynamics.DensitySpacings=1e-6"
  expect_err "DensitySpacings"
  expect_err "] m"
  [ ! -e "$tmp/s" ] && [ ! -e "$tmp/t" ] || fail "an out-of-range setting wrote frames"
  ;;
density_memory)
  # Fine density grids (1 mm over the head and its target) are refused by simulate's estimate under a
  # 4 GB address space, naming the key, not by the allocator ("out of memory").
  command -v prlimit >/dev/null || skip "no prlimit here"
  expect_rc 0 "$hairgen" grow "$springs" -o "$tmp/g.hair" --quiet
  expect_rc 2 prlimit --as=4000000000 "$hairgen" simulate "$src/configs/pixar/target/setup.txt" --guides "$tmp/g.hair" \
    -o "$tmp/t/g.####.hair" --quiet --set "Dynamics.Frames=1 2" --set Dynamics.DensitySpacings=0.001
  expect_err "Dynamics.DensitySpacings"
  ! grep -q "out of memory" "$tmp/err" || fail "out of memory: $(cat "$tmp/err")"
  [ ! -e "$tmp/t" ] || fail "wrote frames"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
