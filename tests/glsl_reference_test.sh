#!/usr/bin/env bash
# Every shader stage and program hairgen compiles (tests/write_stages.cpp writes them as this machine's
# OpenGL is handed them) through the Khronos reference compiler, glslang: each stage must be valid GLSL
# 4.50 as the specification has it, not only as this machine's driver reads it, and each program's
# stages must link as the reference linker checks them (a name both stages declare, declared alike). A
# failure prints the compiler's messages.
# Usage: glsl_reference_test.sh WRITE_STAGES GLSLANG_VALIDATOR DIR   (GLSLANG_VALIDATOR empty: skipped)
set -uo pipefail
write=$1 glslang=$2 dir=$3
if [ -z "$glslang" ] || [ ! -x "$glslang" ]; then
  echo "SKIP (glsl reference compiler): no glslangValidator here (scripts/setup.sh installs glslang-tools)"
  exit 77
fi
rm -rf "$dir"
"$write" "$dir"
rc=$?
if [ "$rc" -eq 3 ]; then
  echo "SKIP (glsl reference compiler): this machine's OpenGL cannot build hairgen's programs (above)"
  exit 77
fi
[ "$rc" -eq 0 ] || { echo "glsl reference compiler: write_stages failed (exit $rc)"; exit 1; }
cd "$dir" || exit 1
refused=0 stages=0 programs=0
for stage in *.vert *.frag *.comp; do
  [ -f "$stage" ] || continue
  stages=$((stages + 1))
  if ! messages=$("$glslang" "$stage" 2>&1); then
    echo "glsl reference compiler: $dir/$stage is refused:"
    echo "$messages" | head -20
    refused=$((refused + 1))
  fi
done
# programs.txt: a program a line, its stages' files, then its name.
while read -ra words; do
  files=() name=""
  for word in "${words[@]}"; do
    if [ -n "$name" ] || ! [[ "$word" =~ ^[0-9]+\.(vert|frag|comp)$ ]]; then name+="${name:+ }$word"; else files+=("$word"); fi
  done
  programs=$((programs + 1))
  if ! messages=$("$glslang" -l "${files[@]}" 2>&1); then
    echo "glsl reference compiler: the $name program (${files[*]}) does not link:"
    echo "$messages" | head -20
    refused=$((refused + 1))
  fi
done < programs.txt
[ "$stages" -gt 0 ] && [ "$programs" -gt 0 ] || { echo "glsl reference compiler: nothing written in $dir"; exit 1; }
echo "glsl reference compiler: $stages stages and $programs programs, $refused refused"
[ "$refused" -eq 0 ]
