# Grow alone: Anjyo's bob (cantilever styling, force-field parting, cuts) on the first quarter of the
# follicles.
stage=grow
produce() { "$hairgen" grow "$src/configs/anjyo/bob/setup.txt" --shard 1/4 -o "$out/guides.hair" --quiet; }
cache="$out/guides.hair"
check() { "$invariants" roots-on-mesh "$cache" "$src/configs/assets/wick.obj"; }
