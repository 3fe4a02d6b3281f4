# Thesis coupe 4 at 160x160 and density 20, as the README gallery shows it.
args=(run "$src/configs/thesis/coupe4/setup.txt" -o "$out" --quiet
      --set "Render.Resolution=160 160" --set Hairstyle.HairDensity=20)
image="$out/beauty.exr"
