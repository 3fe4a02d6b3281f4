# Grow alone: the default coupe's guides (Super-Helix, BFGS minimiser) on the first eighth of the scalp's
# follicles (95 of 759), at the bundled sampling: catches a change to the energy or the minimiser.
stage=grow
produce() { "$hairgen" grow "$src/configs/default/setup.txt" --shard 1/8 -o "$out/guides.hair" --quiet; }
cache="$out/guides.hair"
check() { "$invariants" roots-on-mesh "$cache" "$src/configs/assets/wick.obj"; }
