# Simulate alone: Anjyo's cantilever dynamics (configs/anjyo/gust: the bob in a side wind) for frames
# 1-3 from fixed rest guides, a quarter of the bob's.
stage=simulate
rest="$src/golden/fixtures/guides-bob-quarter.hair"
produce() {
  "$hairgen" simulate "$src/configs/anjyo/gust/setup.txt" --guides "$rest" --frames 1-3 -o "$out/guides.####.hair" --quiet
}
cache="$out/guides.0003.hair"
# Every frame: the roots stay on the scalp, and the segments are rigid: each keeps its rest length within
# 1e-5, float's round-off of points rebuilt from angles along 20 segments (a change of the model's
# lengths is percents).
check() {
  for frame in 0001 0002 0003; do
    "$invariants" roots-on-mesh "$out/guides.$frame.hair" "$src/configs/assets/wick.obj" &&
      "$invariants" segments-kept "$out/guides.$frame.hair" "$rest" 1e-5 || return 1
  done
}
