# The renderer alone: a stored coupe (golden/fixtures) with Kajiya-Kay and deep opacity shadows on the head.
stage=render
produce() {
  "$hairgen" render "$src/configs/thesis/coupe3/setup.txt" --hair "$src/golden/fixtures/coupe3-shaded.hair" \
    -o "$out/image.exr" --preview "$out/image.png" --quiet --set "Render.Resolution=160 160"
}
image="$out/image.exr"
