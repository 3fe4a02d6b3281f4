# Thesis coupe 1 at 160x160 and density 20, as the README gallery shows it, from its fixed guides
# (golden/fixtures/guides-coupe1.hair): interpolated and rendered, the image `run` makes.
stage=render
produce() {
  "$hairgen" interpolate "$src/configs/thesis/coupe1/setup.txt" --guides "$src/golden/fixtures/guides-coupe1.hair" \
    -o "$out/coupe.hair" --quiet --set Hairstyle.HairDensity=20 &&
    "$hairgen" render "$src/configs/thesis/coupe1/setup.txt" --hair "$out/coupe.hair" -o "$out/beauty.exr" \
      --preview "$out/beauty.png" --quiet --set "Render.Resolution=160 160"
}
image="$out/beauty.exr"
