# Grow alone: thesis coupe 3's guides (the thesis' Rosenbrock search, collision ellipsoid and sphere) on
# the first eighth of the follicles.
stage=grow
produce() { "$hairgen" grow "$src/configs/thesis/coupe3/setup.txt" --shard 1/8 -o "$out/guides.hair" --quiet; }
cache="$out/guides.hair"
check() { "$invariants" roots-on-mesh "$cache" "$src/configs/assets/wick.obj"; }
