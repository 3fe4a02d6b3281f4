# Thesis coupe 3 at 160x160 and density 20, shaded volumetric (run shades it: the Setup asks for the
# volumetric model); golden/coupe3 is its Kajiya-Kay twin.
args=(run "$src/configs/thesis/coupe3/setup.txt" -o "$out" --quiet
      --set "Render.Resolution=160 160" --set Hairstyle.HairDensity=20 --set Render.ShadingModel=volumetric)
image="$out/beauty.exr"
