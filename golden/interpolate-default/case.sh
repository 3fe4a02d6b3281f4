# Interpolate alone: the default coupe at 1 strand/cm² from fixed guides (golden/fixtures), so a
# minimiser change never moves it: strand count, roots on the scalp, clumping and the blend.
stage=interpolate
produce() {
  "$hairgen" interpolate "$src/configs/default/setup.txt" --guides "$src/golden/fixtures/guides-default.hair" \
    -o "$out/coupe.hair" --quiet --set Hairstyle.HairDensity=1
}
cache="$out/coupe.hair"
check() { "$invariants" roots-on-mesh "$cache" "$src/configs/assets/wick.obj"; }
