#!/usr/bin/env bash
# Builds the readers and their libFuzzer targets (tests/fuzz) with clang under ASan and UBSan in
# build-fuzz/, then fuzzes each target for SECONDS_PER_TARGET seconds (default 60), two at a time, on a
# copy of its committed corpus (tests/fuzz/corpus/TARGET), so the repository is never written to.
# Exits 1 on any finding (a crash, a sanitizer report, an untyped exception, a leak, a timeout, an
# allocation past the memory limit) and prints where the input was saved; reproduce it with
# build-fuzz/tests/fuzz/TARGET FILE.
#
# Usage: scripts/fuzz.sh           what CI runs (scripts/test.sh, after ctest)
#        scripts/fuzz.sh --grow    the same, then merges the inputs that reached new code into the
#                                  committed corpus (libFuzzer -merge=1), for a person to review and commit
set -euo pipefail
cd "$(dirname "$0")/.."

grow=false
case "${1:-}" in
  "") ;;
  --grow) grow=true ;;
  *) echo "usage: scripts/fuzz.sh [--grow]" >&2; exit 2 ;;
esac

seconds="${SECONDS_PER_TARGET:-60}"
parallel=2  # targets at a time: each fuzzer is one process on one core
# Per target, the longest input the fuzzer makes: a little above the largest seed, so a seed is never cut.
declare -A max_len=([fuzz_hair]=16384 [fuzz_gltf]=32768 [fuzz_obj]=4096 [fuzz_config]=4096 [fuzz_exr]=8192 [fuzz_ply]=8192 [fuzz_data]=8192 [fuzz_farm_plan]=12288 [fuzz_restart]=20480)
targets=(fuzz_hair fuzz_gltf fuzz_obj fuzz_config fuzz_exr fuzz_ply fuzz_data fuzz_farm_plan fuzz_restart)
# The readers take milliseconds; 10 s on one input is a hang. Memory: libFuzzer's default, made explicit
# (fuzz_exr gives readImage a quarter of it as its budget).
limits=(-timeout=10 -rss_limit_mb=2048)
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"

start=$(date +%s)
cmake -S . -B build-fuzz -G Ninja -DHAIRGEN_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build build-fuzz
built=$(date +%s)

runs=build-fuzz/runs
rm -rf "$runs"

# Fuzzes one target in runs/TARGET: corpus/ (the copy, which grows), artifacts/ (findings), log, rc.
fuzz() {
  local target=$1 dir="$runs/$1"
  mkdir -p "$dir/corpus" "$dir/artifacts"
  cp tests/fuzz/corpus/"$target"/* "$dir/corpus/"
  local rc=0
  build-fuzz/tests/fuzz/"$target" "$dir/corpus" -max_total_time="$seconds" -max_len="${max_len[$target]}" \
    "${limits[@]}" -artifact_prefix="$dir/artifacts/" -print_final_stats=1 >"$dir/log" 2>&1 || rc=$?
  echo "$rc" >"$dir/rc"
}

running=0
for target in "${targets[@]}"; do
  if ((running == parallel)); then
    wait -n
    running=$((running - 1))
  fi
  echo "fuzz: $target for ${seconds} s" >&2
  fuzz "$target" &
  running=$((running + 1))
done
wait

# One line per target: runs, speed, corpus growth, peak memory; the report of each finding.
stat() { sed -n "s/^stat::$1: *//p" "$2" | tail -n 1; }
failed=0
for target in "${targets[@]}"; do
  dir="$runs/$target"
  seeds=$(find tests/fuzz/corpus/"$target" -type f | wc -l)
  echo "$target: $(stat number_of_executed_units "$dir/log") runs, $(stat average_exec_per_sec "$dir/log")/s," \
    "corpus $seeds -> $(find "$dir/corpus" -type f | wc -l) inputs, peak RSS $(stat peak_rss_mb "$dir/log") MB"
  if [ "$(cat "$dir/rc")" != 0 ]; then
    failed=1
    echo "---- $target: FINDING (exit $(cat "$dir/rc")); the end of its log ($dir/log):"
    tail -n 60 "$dir/log"
    for input in "$dir"/artifacts/*; do
      [ -e "$input" ] || continue
      echo "---- $target: the input is saved as $input"
      echo "     reproduce: build-fuzz/tests/fuzz/$target $input"
    done
  fi
done
echo "fuzz: build $((built - start)) s, fuzzing $(($(date +%s) - built)) s"
if ((failed)); then
  echo "fuzz: FAILED; a fixed finding's input belongs in tests/fuzz/corpus/TARGET/ as a regression file" >&2
  exit 1
fi

if $grow; then
  for target in "${targets[@]}"; do
    before=$(find tests/fuzz/corpus/"$target" -type f | wc -l)
    build-fuzz/tests/fuzz/"$target" -merge=1 -max_len="${max_len[$target]}" "${limits[@]}" \
      tests/fuzz/corpus/"$target" "$runs/$target/corpus" >"$runs/$target/merge.log" 2>&1
    echo "$target: merged $(($(find tests/fuzz/corpus/"$target" -type f | wc -l) - before)) new inputs"
  done
  echo "fuzz: review the new files under tests/fuzz/corpus/ (git status), then commit them"
fi
