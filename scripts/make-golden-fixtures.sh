#!/usr/bin/env bash
# Makes the fixed inputs of the golden cases (golden/fixtures/, golden/README.md) from the bundled configs:
# scripts/make-golden-fixtures.sh NAME... (or `all`). They are made once and committed; a fixture remade
# moves every case that reads it, so the script lists those cases, whose references are then remade with
# scripts/update-golden.sh in the same commit as the fixture (and in no other).
# Uses build/hairgen as it is (build it first).
set -euo pipefail
cd "$(dirname "$0")/.."
hairgen=./build/hairgen
fixtures=golden/fixtures
[ -x "$hairgen" ] || { echo "make-golden-fixtures: build $hairgen first" >&2; exit 2; }

# Each fixture: the command that makes it into $1 (the file's name is the fixture's).
make_fixture() {
  local name=$1 file=$2
  case "$name" in
    # Stage inputs. The default coupe's guides sampled every 2 cm (one point per Super-Helix element
    # end), for interpolate; a quarter of the follicles of the same, and of Anjyo's bob, for simulate.
    guides-default.hair)
      "$hairgen" grow configs/default/setup.txt -o "$file" --quiet --set Hairstyle.VisualityStep=0.02 ;;
    guides-default-quarter.hair)
      "$hairgen" grow configs/default/setup.txt -o "$file" --quiet --set Hairstyle.VisualityStep=0.02 --shard 1/4 ;;
    guides-bob-quarter.hair)
      "$hairgen" grow configs/anjyo/bob/setup.txt -o "$file" --quiet --shard 1/4 ;;
    # The default coupe interpolated from guides-default.hair at 1 strand/cm², for shade.
    coupe-default.hair)
      "$hairgen" interpolate configs/default/setup.txt --guides "$fixtures/guides-default.hair" -o "$file" \
        --quiet --set Hairstyle.HairDensity=1 ;;
    # Render inputs: the guides `run` grows for thesis coupes 1 and 2 and for Anjyo's bob, as the
    # bundled configs make them (grow does not depend on HairDensity).
    guides-coupe1.hair) "$hairgen" grow configs/thesis/coupe1/setup.txt -o "$file" --quiet ;;
    guides-coupe2.hair) "$hairgen" grow configs/thesis/coupe2/setup.txt -o "$file" --quiet ;;
    guides-bob.hair) "$hairgen" grow configs/anjyo/bob/setup.txt -o "$file" --quiet ;;
    # Thesis coupe 3, shaded, at 2 strands/cm² with a vertex every 5 mm, for render-kajiya-kay and
    # render-volumetric.
    coupe3-shaded.hair)
      local dir
      dir=$(mktemp -d)
      "$hairgen" run configs/thesis/coupe3/setup.txt -o "$dir" --no-render --quiet --set Hairstyle.HairDensity=2 \
        --set Hairstyle.VisualityStep=0.005 --set Render.ShadingModel=volumetric
      mv "$dir/shaded.hair" "$file" && rm -rf "$dir" ;;
    *) return 1 ;;
  esac
}

names=("$@")
[ ${#names[@]} -gt 0 ] || { echo "usage: scripts/make-golden-fixtures.sh NAME... | all" >&2; exit 2; }
if [ "${names[0]}" = all ]; then
  # In dependency order: coupe-default.hair is interpolated from guides-default.hair.
  names=(guides-default.hair guides-default-quarter.hair guides-bob-quarter.hair coupe-default.hair
         guides-coupe1.hair guides-coupe2.hair guides-bob.hair coupe3-shaded.hair)
fi
for name in "${names[@]}"; do
  make_fixture "$name" "$fixtures/$name" || { echo "make-golden-fixtures: no fixture $name" >&2; exit 2; }
  users=$( (grep -l -F "fixtures/$name" golden/*/case.sh || true) | xargs -r -n1 dirname | xargs -r -n1 basename | tr "\n" " ")
  echo "make-golden-fixtures: $fixtures/$name ($(stat -c %s "$fixtures/$name") bytes); read by: ${users:-no case}" >&2
done
