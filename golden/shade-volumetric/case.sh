# Shade alone: Petrovic et al.'s volume normals (density grid, signed distance of the shell, N = grad S)
# on a fixed coupe (golden/fixtures/coupe-default.hair).
stage=shade
input="$src/golden/fixtures/coupe-default.hair"
produce() {
  "$hairgen" shade "$src/configs/default/setup.txt" --hair "$input" -o "$out/shaded.hair" --quiet \
    --set Render.ShadingModel=volumetric
}
cache="$out/shaded.hair"
check() { "$invariants" points-kept "$cache" "$input"; }
