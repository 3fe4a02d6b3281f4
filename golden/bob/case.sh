# Anjyo's bob (cantilever styling, force-field parting, cuts, per-strand ambient, his specular) at
# 160x160 and density 30.
args=(run "$src/configs/anjyo/bob/setup.txt" -o "$out" --quiet
      --set "Render.Resolution=160 160" --set Hairstyle.HairDensity=30)
image="$out/beauty.exr"
