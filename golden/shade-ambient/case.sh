# Shade alone: Anjyo's per-strand ambient (the bob's distribution, mean 1, deviation 0.15) as colours on a
# fixed coupe (golden/fixtures/coupe-default.hair).
stage=shade
input="$src/golden/fixtures/coupe-default.hair"
produce() {
  "$hairgen" shade "$src/configs/default/setup.txt" --hair "$input" -o "$out/shaded.hair" --quiet \
    --set Visuality.AmbientMean=1.0 --set Visuality.AmbientDeviation=0.15
}
cache="$out/shaded.hair"
check() { "$invariants" points-kept "$cache" "$input"; }
