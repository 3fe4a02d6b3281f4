# The renderer alone: a stored coupe (golden/fixtures) with Kajiya-Kay and deep opacity shadows on the head.
# Its 1,007 strands are drawn 1.5 mm wide, about a pixel here: at their real 80 µm they would be a faint
# veil (strands at their true width, docs/rendering.md), and this case checks how strands are shaded.
stage=render
produce() {
  "$hairgen" render "$src/configs/thesis/coupe3/setup.txt" --hair "$src/golden/fixtures/coupe3-shaded.hair" \
    -o "$out/image.exr" --preview "$out/image.png" --quiet --set "Render.Resolution=160 160" \
    --set Render.StrandWidth=0.0015
}
image="$out/image.exr"
