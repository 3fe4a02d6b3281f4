# The one end-to-end case: the default coupe, as the README's first command renders it, at 160x160 and a
# quarter of its density; every stage of `run` in one process.
stage=run
produce() {
  "$hairgen" run "$src/configs/default/setup.txt" -o "$out" --quiet --set "Render.Resolution=160 160" \
    --set Hairstyle.HairDensity=25
}
image="$out/beauty.exr"
