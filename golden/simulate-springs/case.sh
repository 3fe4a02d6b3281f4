# Simulate alone: Petrovic et al.'s mass-spring keyhairs (configs/pixar/wind: the default coupe in a
# steady wind, head still) for frames 1-3 from fixed rest guides, a quarter of the scalp's.
stage=simulate
rest="$src/golden/fixtures/guides-default-quarter.hair"
produce() {
  "$hairgen" simulate "$src/configs/pixar/wind/setup.txt" --guides "$rest" --frames 1-3 -o "$out/guides.####.hair" --quiet
}
cache="$out/guides.0003.hair"
# Every frame: the roots stay on the scalp, and each segment keeps its rest length within 0.2%: the
# stretch solve holds every bundled shot within 0.1% (libcore/io/restart_state.h), and 1% is the
# bound past which simulate stops.
check() {
  for frame in 0001 0002 0003; do
    "$invariants" roots-on-mesh "$out/guides.$frame.hair" "$src/configs/assets/wick.obj" &&
      "$invariants" segments-kept "$out/guides.$frame.hair" "$rest" 0.002 || return 1
  done
}
