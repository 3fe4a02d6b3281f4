# Thesis coupe 3 (long brown hair with small waves, a sphere over the face) at 160x160, density 20.
args=(run "$src/configs/thesis/coupe3/setup.txt" -o "$out" --quiet
      --set "Render.Resolution=160 160" --set Hairstyle.HairDensity=20)
image="$out/beauty.exr"
