#!/usr/bin/env bash
# Benchmarks, one group or all: scripts/bench.sh [grow|cantilever|interpolate|shade|render|simulate|cache|all] [Google Benchmark flags]
# scripts/bench.sh farm: a shot in one process and through a local Slurm (scripts/bench-farm.sh).
# Builds Release first. Speed targets are checked here, never by timed unit tests: each benchmark with a
# target (issues 15, 16 and 20) prints `of_target`, its figure over the target (1 or more meets it), and
# the run ends with a table of them: figure, target, ratio, met or not (medians with repetitions).
# Medians: add --benchmark_repetitions=5 --benchmark_report_aggregates_only=true.
set -euo pipefail
cd "$(dirname "$0")/.."
group="${1:-all}"
[[ $# -gt 0 ]] && shift
bash scripts/setup.sh --no-build
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DHAIRGEN_BUILD_TESTS=ON >/dev/null  # hairgen_bench is a test target
if [ "$group" = farm ]; then
  cmake --build build --target hairgen
  exec bash scripts/bench-farm.sh "$@"
fi
cmake --build build --target hairgen_bench hairgen
case "$group" in
  grow) filter='EnergyEvaluation|GrowCoupe3|GrowDefault' ;;  # and their Bfgs forms
  cantilever) filter='CantileverStyling' ;;
  interpolate) filter='InterpolateCoupe3' ;;
  shade) filter='ShadeCoupe3' ;;
  render) filter='Render|DeviceStart' ;;  # Render, RenderCommand, RenderSequence (issue 34's figures)
  simulate) filter='SimulateAnjyo|SimulateSprings' ;;
  cache) filter='ReadCache|WriteCache' ;;
  all) filter='.' ;;
  *) echo "bench.sh: unknown group '$group' (grow, cantilever, interpolate, shade, render, simulate, cache, farm, all)" >&2; exit 2 ;;
esac
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
exec build/tests/hairgen_bench --benchmark_filter="$filter" "$@"
