# The renderer alone: the stored coupe's volume normals with ShadingModel volumetric.
stage=render
produce() {
  "$hairgen" render "$src/configs/thesis/coupe3/setup.txt" --hair "$src/golden/fixtures/coupe3-shaded.hair" \
    -o "$out/image.exr" --preview "$out/image.png" --quiet --set "Render.Resolution=160 160" \
    --set Render.ShadingModel=volumetric
}
image="$out/image.exr"
