#!/usr/bin/env bash
# Remakes golden references on purpose, and only those asked for:
#   scripts/update-golden.sh STAGE|CASE ...   a stage (grow, interpolate, simulate, shade, render, run:
#                                             every case whose case.sh says `stage=STAGE`) or one case
#   scripts/update-golden.sh all              every case
# Each remade reference is compared with the one it replaces first (`hairgen diff`, printed: paste it in
# the commit message). Look at each new image (its PNG preview is beside it in the build tree) before
# committing, and commit references in a commit of their own. The fixtures they read (golden/fixtures) are
# made by scripts/make-golden-fixtures.sh. Builds build/hairgen first (configuring build/ when absent).
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
hairgen="$src/build/hairgen"
[ $# -gt 0 ] || { echo "usage: scripts/update-golden.sh STAGE|CASE ... | all" >&2; exit 2; }

mapfile -t every < <(find golden -mindepth 2 -maxdepth 2 -name case.sh -printf '%h\n' | xargs -n1 basename | sort)
stage_of() { (cache="" image="" out="" && source "golden/$1/case.sh" && echo "$stage"); }
cases=()
for asked in "$@"; do
  if [ "$asked" = all ]; then
    cases+=("${every[@]}")
  elif [ -f "golden/$asked/case.sh" ]; then
    cases+=("$asked")
  else
    found=0
    for case in "${every[@]}"; do
      [ "$(stage_of "$case")" = "$asked" ] && cases+=("$case") && found=1
    done
    [ "$found" = 1 ] || { echo "update-golden: no case or stage named $asked" >&2; exit 2; }
  fi
done

if [ -d build ]; then
  cmake --build build --target hairgen
else
  bash scripts/setup.sh
fi
for case in "${cases[@]}"; do
  out="$src/build/golden-update/$case"
  rm -rf "$out" && mkdir -p "$out"
  cache="" image=""
  # shellcheck source=/dev/null
  source "golden/$case/case.sh"
  produce
  if [ -n "$cache" ]; then made=$cache reference="golden/$case/reference.hair"; else made=$image reference="golden/$case/reference.exr"; fi
  if [ -f "$reference" ]; then
    echo "update-golden: $case, the new output against the reference it replaces:" >&2
    "$hairgen" diff "$reference" "$made" >&2 || true
  fi
  cp "$made" "$reference"
  echo "update-golden: $reference${image:+ (preview: ${image%.exr}.png)}" >&2
  unset -f produce check
done
