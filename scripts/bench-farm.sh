#!/usr/bin/env bash
# scripts/bench.sh farm: a shot run in one process and through Slurm on this machine (a one-node cluster
# from scripts/slurm-local.sh), both timed, and the scheduler's overhead per task: the time from a task
# being ready (its dependencies done, or the plan submitted) to it starting, and the submission itself.
# Sizes: FARM_SETUP (default configs/anjyo/gust/setup.txt), FARM_FRAMES (1-24), FARM_CHUNK (5),
# FARM_SHARDS (4), FARM_SETS (--set arguments, default a density of 20 strands/cm² at 320x240; a
# resolution written WxH).
set -euo pipefail
cd "$(dirname "$0")/.."
hairgen=$PWD/build/hairgen
setup=${FARM_SETUP:-configs/anjyo/gust/setup.txt}
frames=${FARM_FRAMES:-1-24}
chunk=${FARM_CHUNK:-5}
shards=${FARM_SHARDS:-4}
read -r -a sets <<<"${FARM_SETS:---set Hairstyle.HairDensity=20 --set Render.Resolution=320x240}"
# A resolution is written WxH in FARM_SETS (one word); the config wants "W H".
for i in "${!sets[@]}"; do [[ ${sets[$i]} == Render.Resolution=*x* ]] && sets[$i]=${sets[$i]/x/ }; done
out=$(mktemp -d /tmp/hairgen-bench-farm.XXXXXX)
trap 'rm -rf "$out"' EXIT

was_up=0
bash scripts/slurm-local.sh status && was_up=1
if ! bash scripts/slurm-local.sh start; then
  echo "bench farm: no local Slurm (see above); only the single-process time is measured" >&2
  slurm=0
else
  slurm=1
  [ "$was_up" -eq 1 ] || trap 'bash scripts/slurm-local.sh stop >/dev/null; rm -rf "$out"' EXIT
fi
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "shot: $setup, frames $frames, chunks of $chunk, $shards shards, ${sets[*]}"
first=${frames%-*} last=${frames#*-}

now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }
t0=$(now)
"$hairgen" run "$setup" -o "$out/run" -q "${sets[@]}" --set "Dynamics.Frames=$first $last" --stats "$out/run.json"
t1=$(now)
echo "single process (hairgen run): $(since "$t0" "$t1") s"
[ "$slurm" -eq 1 ] || exit 0

"$hairgen" farm plan "$setup" -o "$out/farm" -q "${sets[@]}" --frames "$frames" --chunk "$chunk" --shards "$shards"
t2=$(now)
"$hairgen" farm submit "$out/farm/plan.json" --scheduler slurm --wait -q >"$out/submit.txt"
t3=$(now)
submitted=$(grep -c ': job ' "$out/submit.txt")
echo "Slurm, one node (farm submit --wait): $(since "$t2" "$t3") s for $(grep -c '"id"' "$out/farm/plan.json") tasks in $submitted job arrays"
for f in "$out"/run/beauty.*.exr; do
  cmp -s "$f" "$out/farm/$(basename "$f")" || { echo "bench farm: $(basename "$f") differs from the single run's" >&2; exit 1; }
done
echo "every frame identical to the single run's"

# Per task: its run time (the start and end lines the task scripts log) and its wait once ready.
node - "$out/farm/plan.json" "$out/farm/logs" "$t2" <<'JS'
const fs = require('fs');
const [plan, logs, submitted] = [JSON.parse(fs.readFileSync(process.argv[2])), process.argv[3], +process.argv[4]];
const start = {}, end = {};
for (const f of fs.readdirSync(logs))
  for (const line of fs.readFileSync(`${logs}/${f}`, 'utf8').split('\n')) {
    const m = line.match(/^hairgen-farm: (start|end) (\S+) (\S+)/);
    if (m) (m[1] === 'start' ? start : end)[m[2]] = +m[3];
  }
let work = 0, n = 0;
const waits = [], groups = {};
for (const t of plan.tasks) {
  if (!(t.id in start)) continue;
  const ready = Math.max(submitted, ...t.deps.map(d => end[d] ?? submitted));
  waits.push(start[t.id] - ready);
  work += end[t.id] - start[t.id];
  (groups[t.group] ??= []).push(end[t.id] - start[t.id]);
  n++;
}
waits.sort((a, b) => a - b);
const mean = waits.reduce((a, b) => a + b, 0) / n;
console.log(`tasks: ${n}, their run time summed ${work.toFixed(1)} s; per task:`);
for (const [g, times] of Object.entries(groups))
  console.log(`  ${g}: ${times.length} x ${(times.reduce((a, b) => a + b, 0) / times.length).toFixed(2)} s`);
// The wait of a ready task is the scheduler's latency plus, on a busy node, the wait for free cores;
// the smallest waits are the latency alone.
console.log(`wait from ready to started per task: min ${waits[0].toFixed(2)} s, median ` +
            `${waits[n >> 1].toFixed(2)} s, mean ${mean.toFixed(2)} s, max ${waits[n - 1].toFixed(2)} s`);
JS
