#!/usr/bin/env bash
# The render checks on a lent GPU machine (issue 34): no package registry, no network there, so a
# Release build travels with its libraries.
#
#   scripts/device-check.sh pack DIR [BUILD]
#       Here: hairgen, libhairgen_images.so and hairgen_bench from BUILD (default build/, a Release build),
#       stripped, with every shared library they need (ldd) but the C library's and OpenGL's (libGL*,
#       libEGL*, libGLdispatch, libOpenGL, libGLX: the machine's glvnd loaders, from the .gl debs the
#       device README names, dispatch to its driver), into DIR/hairgen-pack.tar.xz. libstdc++ and
#       libgcc_s go in as a fallback, used only where the machine's own are older. The image module's
#       OpenImageIO libraries (~360 MB) stay behind: only `diff` and `info` of non-EXR images need them.
#       This script goes into DIR too, for a checkout that lacks it: `bash DIR/device-check.sh run DIR OUT`
#       from the repository's root.
#   scripts/device-check.sh run DIR OUT
#       There, from the repository's root (golden/, configs/, tests/golden_test.sh): unpacks DIR's
#       archive into a temporary folder, then
#         1. hairgen render --list-devices                                   -> OUT/devices.txt
#        1b. the unit tests that compare the device's rasteriser with the CPU's -> OUT/unit_tests.txt
#         2. every golden case (tests/golden_test.sh with the packed hairgen); the failures' sheets
#            (reference | rendered | 10 x difference) and diff reports       -> OUT/golden.tar
#         3. issue 34's render figures through the command line (any hairgen build): 150,000 strands of
#            65 points at 1920x1080, Samples 1 with shadows: the whole `hairgen render` (median of 5
#            runs), its passes and peak memory from --stats, and a 48-frame `render --frames` sequence
#         4. the render benchmarks of hairgen_bench (medians of 5; the sequence once, its median frame;
#            the device's start in a process of its own)
#                                                                            -> OUT/bench.txt
#       and writes OUT/summary.txt. Under 5 minutes on a 16-core machine with a GPU. The NVIDIA EGL vendor
#       file is used where it exists (/usr/local/nvidia/...), so the same command runs on llvmpipe here.
#       DEVICE_CHECK_FRAMES (48; 0 skips the sequences), DEVICE_CHECK_STRANDS (150000) and
#       DEVICE_CHECK_BENCH (the benchmarks' filter) shrink the work for a trial on a slow machine.
set -uo pipefail

die() {
  echo "device-check: $*" >&2
  exit 2
}

pack() {
  local dir=$1 build=${2:-build}
  [ -x "$build/hairgen" ] || die "$build/hairgen: no hairgen built there (cmake --build $build --target hairgen hairgen_bench hairgen_images)"
  grep -q '^CMAKE_BUILD_TYPE:STRING=Release' "$build/CMakeCache.txt" 2>/dev/null ||
    die "$build is not a Release build: figures from it would mislead"
  local stage
  stage=$(mktemp -d)
  mkdir -p "$stage/bin" "$stage/lib/fallback" "$dir"
  local binaries=("$build/hairgen" "$build/libhairgen_images.so")
  if [ -x "$build/tests/hairgen_bench" ]; then
    binaries+=("$build/tests/hairgen_bench")
  else
    echo "device-check: no $build/tests/hairgen_bench; the benchmarks will be skipped there" >&2
  fi
  # The stage goldens' invariant checker (tests/stage_invariants.cpp), and the unit tests (for the
  # rasteriser's device-against-CPU comparisons), where this build has them.
  [ -x "$build/tests/stage_invariants" ] && binaries+=("$build/tests/stage_invariants")
  [ -x "$build/tests/unit_tests" ] && binaries+=("$build/tests/unit_tests")
  for b in "${binaries[@]}"; do
    [ -e "$b" ] || die "$b is missing"
    cp "$b" "$stage/bin/" && strip --strip-unneeded "$stage/bin/$(basename "$b")"
  done
  # The libraries of hairgen and hairgen_bench (not the image module's: see above), less the C
  # library's and OpenGL's.
  local skip='/(libc|libm|libdl|libpthread|librt|libresolv)\.so|/ld-linux|/libGL|/libEGL|/libOpenGL|/libGLX|/libGLdispatch'
  local lib
  for b in "$stage/bin/hairgen" "$stage/bin/hairgen_bench" "$stage/bin/stage_invariants" "$stage/bin/unit_tests"; do
    [ -e "$b" ] || continue
    ldd "$b" | awk '$2 == "=>" && $3 ~ /^\// {print $3}'
  done | sort -u | grep -vE "$skip" | while read -r lib; do
    case "$(basename "$lib")" in
      libstdc++.so.* | libgcc_s.so.*) cp -L "$lib" "$stage/lib/fallback/" ;;
      *) cp -L "$lib" "$stage/lib/" ;;
    esac
  done
  # Which hairgen this is, for the summary.
  {
    echo "packed $(date -u +%FT%TZ) from $(cd "$build" && pwd)"
    local home
    home=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$build/CMakeCache.txt")
    git -C "$home" log -1 --format="commit %h %s (checkout $home)" 2>/dev/null
    echo "$("$build/hairgen" --version 2>/dev/null)"
  } >"$stage/PACKED"
  # The script itself, so a checkout without it (main before this change) runs it from DIR.
  cp "$0" "$dir/device-check.sh"
  rm -f "$dir/hairgen-pack.tar.xz"
  tar -C "$stage" -cf - . | xz -T0 -6 >"$dir/hairgen-pack.tar.xz" || die "could not write $dir/hairgen-pack.tar.xz"
  rm -rf "$stage"
  echo "device-check: packed $(du -sh "$dir" | cut -f1) into $dir ($(du -b "$dir/hairgen-pack.tar.xz" | cut -f1) bytes)"
  local bytes
  bytes=$(du -sb "$dir" | cut -f1)
  [ "$bytes" -lt $((50 * 1024 * 1024)) ] || echo "device-check: $dir is over 50 MiB" >&2
}

# median of the numbers on stdin
median() { sort -g | awk '{v[NR] = $1} END {if (NR == 0) print "nan"; else if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

# json FILE EXPR: a value of a --stats file (python3 is on the machine: its image holds PyTorch).
json() { python3 -c "import json, sys; d = json.load(open(sys.argv[1])); print($2)" "$1"; }

run() {
  local dir=$1 out=$2
  # The repository: the current folder where it holds golden/ (the device runs commands in its root),
  # else the one this script is in.
  local src=$PWD
  [ -d "$src/golden" ] && [ -f "$src/tests/golden_test.sh" ] || src=$(cd "$(dirname "$0")/.." && pwd)
  [ -f "$dir/hairgen-pack.tar.xz" ] || die "$dir/hairgen-pack.tar.xz: pack it first (scripts/device-check.sh pack $dir)"
  mkdir -p "$out" || die "cannot write $out"
  local work
  work=$(mktemp -d /tmp/device-check.XXXXXX)
  tar -C "$work" -xJf "$dir/hairgen-pack.tar.xz" || die "could not unpack $dir/hairgen-pack.tar.xz"
  local bin="$work/bin" libs="$work/lib"
  # The machine's libstdc++ when it is as new as the one the build was linked with, else the packed one.
  local system need
  system=$(ldconfig -p 2>/dev/null | awk '/libstdc\+\+\.so\.6 .*x86-64/ {print $NF; exit}')
  need=$(grep -ao 'GLIBCXX_3\.4\.[0-9]*' "$bin/hairgen" | sort -t. -k3 -n | tail -1)
  if [ -z "$system" ] || ! grep -qa "$need" "$system"; then libs="$libs:$work/lib/fallback"; fi
  export LD_LIBRARY_PATH="$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  local vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
  [ -f "$vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$vendor
  local hairgen="$bin/hairgen" summary="$out/summary.txt"
  local frames=${DEVICE_CHECK_FRAMES:-48} strands=${DEVICE_CHECK_STRANDS:-150000}
  local bench=${DEVICE_CHECK_BENCH:-'^(Render/strands:150000/width:1920/height:1080/samples:1/|RenderCommand|Readback)'}
  : >"$summary"
  say() { echo "$*" | tee -a "$summary"; }

  say "== device-check $(date -u +%FT%TZ) on $(cat /proc/sys/kernel/hostname): $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
  say "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
  command -v nvidia-smi >/dev/null && say "$(nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>&1)"
  say "$(cat "$work/PACKED")"
  say "EGL vendor file: ${__EGL_VENDOR_LIBRARY_FILENAMES:-none, glvnd searches its own folders}; LD_LIBRARY_PATH=$LD_LIBRARY_PATH"

  say "== 1. hairgen render --list-devices"
  timeout 60 "$hairgen" render --list-devices >"$out/devices.txt" 2>&1
  say "$(cat "$out/devices.txt")"

  say "== 1b. the rasteriser on the device against the CPU's (unit tests)"
  if [ -x "$bin/unit_tests" ]; then
    HAIRGEN_SOURCE_DIR="$src" timeout 300 "$bin/unit_tests" --gtest_filter='ComputeRaster.*:CameraFragments.*:HairLightMaps.*' \
      >"$out/unit_tests.txt" 2>&1
    say "unit tests (exit $?): $(grep -E '^\[  (PASSED|FAILED|SKIPPED) ' "$out/unit_tests.txt" | tr '\n' ' ')"
    grep -E '^\[  FAILED  \]|^\[  SKIPPED \]' "$out/unit_tests.txt" | sed 's/^/    /' | tee -a "$summary"
  else
    say "no unit_tests in the pack"
  fi

  say "== 2. golden cases"
  local golden="$work/golden" failed=0 passed=0 case
  # A build without the stage goldens' checker (before they existed) checks no invariants.
  local invariants="$bin/stage_invariants"
  [ -x "$invariants" ] || invariants=true
  mkdir -p "$golden" "$work/sheets"
  for case_file in "$src"/golden/*/case.sh; do
    case=$(basename "$(dirname "$case_file")")
    local started=$SECONDS
    if timeout 120 bash "$src/tests/golden_test.sh" "$hairgen" "$src" "$case" "$golden" "$invariants" >"$work/sheets/$case.log" 2>&1; then
      passed=$((passed + 1))
      say "golden $case: ok ($((SECONDS - started)) s)"
    else
      failed=$((failed + 1))
      say "golden $case: FAILED ($((SECONDS - started)) s): $(tail -1 "$work/sheets/$case.log")"
      # hairgen diff's report, as golden_test.sh printed it.
      grep -E '^  [A-Za-z.]+: mean|differ by|^(PASS|FAIL)' "$work/sheets/$case.log" | head -12 | sed 's/^/    /' | tee -a "$summary"
      [ -f "$golden/$case/sheet.png" ] && cp "$golden/$case/sheet.png" "$work/sheets/$case.png"
    fi
  done
  say "golden: $passed passed, $failed failed"
  tar -C "$work/sheets" -cf "$out/golden.tar" . 2>/dev/null

  say "== 3. render figures through the command line: $strands strands of 65 points at 1920x1080, Samples 1"
  local setup="$src/configs/thesis/coupe3/setup.txt" figures="$work/figures"
  mkdir -p "$figures"
  # Coupe 3's wick holds ~490 cm2 of scalp: HairDensity in strands per cm2 (9,899 strands at 20).
  local density
  density=$(awk -v n="$strands" 'BEGIN {printf "%.3f", n / 9899 * 20}')
  if timeout 120 "$hairgen" grow "$setup" -o "$figures/guides.hair" -q &&
    timeout 120 "$hairgen" interpolate "$setup" --guides "$figures/guides.hair" -o "$figures/coupe.hair" -q \
      --set "Hairstyle.HairDensity=$density"; then
    say "$("$hairgen" info "$figures/coupe.hair" | sed -n 2p | sed 's/^ *//')"
    local size=(--set "Render.Resolution=1920 1080" --set Render.Samples=1 -q)
    local i
    for i in 1 2 3 4 5 6; do  # the first warms the file cache and the driver's shader cache
      local t0 t1
      t0=$(date +%s.%N)
      timeout 120 "$hairgen" render "$setup" --hair "$figures/coupe.hair" -o "$figures/image.exr" \
        "${size[@]}" --stats "$figures/stats.$i.json" || { say "render failed"; break; }
      t1=$(date +%s.%N)
      [ "$i" -gt 1 ] && awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.3f\n", b - a}' >>"$figures/wall"
    done
    if [ -f "$figures/stats.6.json" ]; then
      local wall passes upload readback device peak cache
      wall=$(median <"$figures/wall")
      passes=$(for i in 2 3 4 5 6; do json "$figures/stats.$i.json" "sum(d['seconds'].get(k, 0) for k in ('lightDepth', 'opacity', 'shading'))"; done | median)
      upload=$(for i in 2 3 4 5 6; do json "$figures/stats.$i.json" "d['seconds']['upload']"; done | median)
      readback=$(for i in 2 3 4 5 6; do json "$figures/stats.$i.json" "d['seconds']['readback']"; done | median)
      device=$(for i in 2 3 4 5 6; do json "$figures/stats.$i.json" "d['seconds']['device']"; done | median)
      peak=$(for i in 2 3 4 5 6; do json "$figures/stats.$i.json" "d['peakMemoryBytes']"; done | median)
      cache=$(stat -c %s "$figures/coupe.hair")
      say "renderer: $(json "$figures/stats.6.json" "d['device']['renderer'] + ' through EGL ' + d['device']['platform']")"
      say "(a) whole command: $wall s wall, median of 5 (target 0.3 s on a GPU, 2 s on llvmpipe)"
      say "    phases (medians): device wait $device s, upload $upload s, readback $readback s"
      say "    $(json "$figures/stats.6.json" "' '.join(f'{k} {v:.3f}' for k, v in d['seconds'].items())") (last run)"
      say "(b) passes (light depth + opacity + shading, each waited for): $passes s (target 5 ms on a GPU)"
      say "(d) peak memory $(awk -v p="$peak" -v c="$cache" 'BEGIN {printf "%.0f MB = %.2f x the cache'"'"'s %.0f MB", p / 1e6, p / c, c / 1e6}') (target 3 x)"
      say "    device start: $(json "$figures/stats.6.json" "d['device'].get('start', 'not recorded by this build')")"
      say "    rasteriser: $(json "$figures/stats.6.json" "d['device'].get('rasteriser', 'cpu (this build has only the CPU one)')"), the camera's fragments $(for i in 2 3 4 5 6; do json "$figures/stats.$i.json" "d['device'].get('hairFragmentSeconds', float('nan'))"; done | median) s of the shading (median)"
      # Where the rasteriser's time on the device goes: each compute pass (GL timestamps) and each
      # transfer (the host's time, waits included), medians of the 5 runs (docs/files.md, --stats).
      python3 - "$figures" <<'PY' 2>&1 | tee -a "$summary"
import json, statistics, sys
runs = [json.load(open(f"{sys.argv[1]}/stats.{i}.json"))["device"] for i in range(2, 7)]
for key, what in (("passes", "device"), ("transfers", "host")):
    last = runs[-1].get(key, {})
    if not last:
        print(f"    no device.{key} (a build before them, or the CPU's rasteriser ran)")
        continue
    median = {n: statistics.median(r[key][n]["seconds"] for r in runs if n in r.get(key, {})) for n in last}
    print(f"    device.{key} ({what} ms, median of 5): " + ", ".join(
        f"{n} {s * 1e3:.3f}" + (f" ({last[n]['bytes']:,} bytes)" if "bytes" in last[n] else "") +
        (f" x{last[n]['runs']}" if last[n]["runs"] > 1 else "") for n, s in median.items()))
    if key == "passes":
        print(f"    all passes: {sum(median.values()) * 1e3:.3f} ms (target for the GPU passes: 5 ms)")
PY
      # The same frame with the rasteriser on the CPU's threads: the same EXRs to the byte (issue 34:
      # one rasteriser, one answer), and what it costs here.
      local t0 t1
      t0=$(date +%s.%N)
      if timeout 120 "$hairgen" render "$setup" --hair "$figures/coupe.hair" -o "$figures/image-cpu.exr" \
        --dom "$figures/dom-cpu.exr" "${size[@]}" --rasteriser cpu --stats "$figures/stats-cpu.json" &&
        timeout 120 "$hairgen" render "$setup" --hair "$figures/coupe.hair" -o "$figures/image-auto.exr" \
          --dom "$figures/dom-auto.exr" "${size[@]}"; then
        t1=$(date +%s.%N)
        local same=no
        cmp -s "$figures/image-cpu.exr" "$figures/image-auto.exr" && cmp -s "$figures/dom-cpu.exr" "$figures/dom-auto.exr" && same=yes
        say "(e) --rasteriser cpu: $(json "$figures/stats-cpu.json" "' '.join(f'{k} {v:.3f}' for k, v in d['seconds'].items())"); the same EXRs (image and --dom) as the default's: $same"
        [ "$same" = yes ] || "$hairgen" diff "$figures/image-cpu.exr" "$figures/image-auto.exr" 2>&1 | head -12 | sed 's/^/    /' | tee -a "$summary"
      else
        say "(e) the --rasteriser cpu comparison failed"
      fi
    fi
    # A sequence: the same coupe as every frame (links), so a frame's cost is all that is measured.
    [ "$frames" -gt 0 ] || say "(c) no sequence (DEVICE_CHECK_FRAMES=0)"
    [ "$frames" -gt 0 ] && mkdir -p "$figures/seq"
    for ((i = 1; i <= frames; ++i)); do ln -sf ../coupe.hair "$figures/seq/coupe.$(printf %04d "$i").hair"; done
    if [ "$frames" -gt 0 ] && timeout 400 "$hairgen" render "$setup" --hair "$figures/seq/coupe.####.hair" --frames "1-$frames" \
      -o "$figures/seq/image.####.exr" "${size[@]}" --stats "$figures/seq.json"; then
      say "(c) a $frames-frame render --frames: $(json "$figures/seq.json" "'%.3f s a frame in all (total %.1f s), of which ' % (d['seconds']['total'] / $frames, d['seconds']['total']) + ', '.join(f'{k} {v / $frames:.4f}' for k, v in d['seconds'].items() if k != 'total') + ' a frame'")"
      say "    rendering alone (upload + passes + readback) a frame: $(json "$figures/seq.json" "'%.4f s' % (sum(d['seconds'].get(k, 0) for k in ('upload', 'lightDepth', 'opacity', 'shading', 'readback')) / $frames)") (target 0.1 s on an H100)"
    elif [ "$frames" -gt 0 ]; then
      say "(c) the sequence failed or timed out"
    fi
    rm -rf "$figures/seq"
  else
    say "could not make the coupe"
  fi

  say "== 4. hairgen_bench (render benchmarks)"
  if [ -x "$bin/hairgen_bench" ]; then
    export HAIRGEN_BENCH_BINARY="$hairgen" HAIRGEN_BENCH_SOURCE="$src"
    {
      # The device's start first, in a process of its own: no other context has initialised the display.
      timeout 60 "$bin/hairgen_bench" --benchmark_filter='^DeviceStart' \
        --benchmark_repetitions=5 --benchmark_report_aggregates_only=true 2>&1
      timeout 300 "$bin/hairgen_bench" --benchmark_filter="$bench" \
        --benchmark_repetitions=5 --benchmark_report_aggregates_only=true 2>&1
      # The 48-frame sequence once (its figure is the median frame), unless a trial names its own.
      [ -z "${DEVICE_CHECK_BENCH:-}" ] && timeout 300 "$bin/hairgen_bench" --benchmark_filter="^RenderSequence" 2>&1
    } | tee "$out/bench.txt" | grep -E '^\| |_median|^RenderSequence/' | tee -a "$summary"
  else
    say "no hairgen_bench in the pack"
  fi
  say "== done in $SECONDS s"
  rm -rf "$work"
}

case "${1:-}" in
  pack) [ $# -ge 2 ] || die "usage: device-check.sh pack DIR [BUILD]"; pack "$2" "${3:-build}" ;;
  run) [ $# -eq 3 ] || die "usage: device-check.sh run DIR OUT"; run "$2" "$3" ;;
  *) die "usage: device-check.sh pack DIR [BUILD] | run DIR OUT" ;;
esac
