# Anjyo's bob (his shading model: per-strand ambient, his specular) at 160x160 and density 30, from its
# fixed guides (golden/fixtures/guides-bob.hair): interpolated, shaded and rendered, the image `run` makes.
stage=render
produce() {
  local setup="$src/configs/anjyo/bob/setup.txt"
  "$hairgen" interpolate "$setup" --guides "$src/golden/fixtures/guides-bob.hair" -o "$out/coupe.hair" --quiet \
    --set Hairstyle.HairDensity=30 &&
    "$hairgen" shade "$setup" --hair "$out/coupe.hair" -o "$out/shaded.hair" --quiet &&
    "$hairgen" render "$setup" --hair "$out/shaded.hair" -o "$out/beauty.exr" --preview "$out/beauty.png" --quiet \
      --set "Render.Resolution=160 160"
}
image="$out/beauty.exr"
