#!/usr/bin/env bash
# The farm under attack (issue 32): plans whose paths, ids or groups would reach a shell or leave the
# plan's folder are refused; the scripts quote every path; a plan's size and its done check are bounded;
# the scheduler's own errors reach the user. A fake Slurm (sinfo, sbatch, squeue, scancel on PATH)
# runs every generated script at once, so no cluster is needed.
# Usage: attack_farm_test.sh HAIRGEN SOURCE_DIR CASE
source "$(dirname "$0")/cli_lib.sh" "$@"

setup="$src/configs/default/setup.txt"
small=(--quiet --set Hairstyle.HairDensity=5 --set "Render.Resolution=32 24")
nl=$'\n'

# A one-node fake Slurm with 2 CPUs in $tmp/bin: sbatch checks the script with sh -n, records its
# arguments (one per line) in $tmp/sbatch.log and runs each array task of it now, in order, with
# SLURM_ARRAY_TASK_ID and SLURM_CPUS_PER_TASK set and its output in --output (%a replaced).
fake_slurm() {
  mkdir -p "$tmp/bin"
  cat >"$tmp/bin/sbatch" <<'FAKE'
#!/usr/bin/env bash
printf '%s\n' "$@" >>"$FAKE_SLURM/sbatch.log"
array= cpus=1 output=/dev/null script=
for a in "$@"; do
  case $a in
  --array=*) array=${a#--array=} ;;
  --cpus-per-task=*) cpus=${a#*=} ;;
  --output=*) output=${a#*=} ;;
  -*) ;;
  *) script=$a ;;
  esac
done
sh -n "$script" || { echo "sbatch: error: $script is not valid shell" >&2; exit 1; }
job=$(($(cat "$FAKE_SLURM/jobs" 2>/dev/null || echo 100) + 1))
echo "$job" >"$FAKE_SLURM/jobs"
IFS=, read -ra indices <<<"$array"
for i in "${indices[@]}"; do
  SLURM_ARRAY_TASK_ID=$i SLURM_CPUS_PER_TASK=$cpus sh "$script" >"${output//%a/$i}" 2>&1
done
echo "$job"
FAKE
  printf '#!/bin/sh\necho "2 4000"\n' >"$tmp/bin/sinfo"
  printf '#!/bin/sh\nexit 0\n' >"$tmp/bin/squeue"
  printf '#!/bin/sh\nexit 0\n' >"$tmp/bin/scancel"
  chmod +x "$tmp/bin"/*
  export FAKE_SLURM="$tmp" PATH="$tmp/bin:$PATH"
}

# Rewrites plan.json $1 with the Python expression $2 applied to it as `p` (a dict).
edit_plan() {
  python3 -c 'import json,sys; p=json.load(open(sys.argv[1])); exec(sys.argv[2]); json.dump(p, open(sys.argv[1], "w"), indent=1)' "$1" "$2"
}

case "$case" in
newline_paths)
  # A newline in the plan's folder or the Setup's path would end a comment line of a script and run the
  # next line: refused when the plan is made, and when a plan that holds one is read.
  expect_rc 2 "$hairgen" farm plan "$setup" -o "$tmp/a${nl}touch $tmp/injected${nl}" "${small[@]}"
  expect_err "control character"
  [ ! -e "$tmp/a${nl}touch $tmp/injected${nl}/plan.json" ] || fail "a plan was written into a folder with a newline"
  mkdir -p "$tmp/s${nl}x"
  cp -r "$src/configs/default" "$src/configs/assets" "$tmp/s${nl}x/"
  expect_rc 2 "$hairgen" farm plan "$tmp/s${nl}x/default/setup.txt" -o "$tmp/plan" "${small[@]}"
  expect_err "control character"
  [ ! -e "$tmp/plan/plan.json" ] || fail "a plan of a Setup with a newline in its path was written"
  # A plan edited to hold one, read by submit: exit 2 naming the plan and the task, nothing run.
  fake_slurm
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/p" --shards 2 "${small[@]}"
  cp "$tmp/p/plan.json" "$tmp/p/good.json"
  edit_plan "$tmp/p/plan.json" "p['tasks'][0]['inputs'][0] += '\ntouch $tmp/injected\n'"
  for dry in --dry-run ""; do
    expect_rc 2 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm $dry
    expect_err "$tmp/p/plan.json: task \"grow.1\": input"
    expect_err "control character"
  done
  cp "$tmp/p/good.json" "$tmp/p/plan.json"
  edit_plan "$tmp/p/plan.json" "p['setup'] += '\ntouch $tmp/injected'"
  expect_rc 2 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm
  expect_err "control character"
  [ ! -e "$tmp/injected" ] || fail "a newline in a path ran a command"
  [ ! -e "$tmp/p/slurm" ] || fail "a refused plan wrote scripts"
  ;;
task_id_substitution)
  # A task id in "$(...)" would run in the script's echo lines: ids match GROUP or GROUP.N, or the plan is
  # refused.
  fake_slurm
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/p" --shards 2 "${small[@]}"
  edit_plan "$tmp/p/plan.json" "
bad = 'grow.1\$(touch $tmp/injected)'
p['tasks'][0]['id'] = bad
for t in p['tasks']: t['deps'] = [bad if d == 'grow.1' else d for d in t['deps']]"
  expect_rc 2 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm
  expect_err "$tmp/p/plan.json: task"
  expect_err "its id is neither"
  [ ! -e "$tmp/injected" ] || fail "a task id ran a command"
  [ ! -e "$tmp/p/slurm" ] || fail "a refused plan wrote scripts"
  ;;
group_escape)
  # A group named ../../escaped would write its script outside the plan's slurm/ folder.
  fake_slurm
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/d/p" --shards 2 "${small[@]}"
  edit_plan "$tmp/d/p/plan.json" "[t.update(group='../../escaped') for t in p['tasks'] if t['group'] == 'render']"
  expect_rc 2 "$hairgen" farm submit "$tmp/d/p/plan.json" --scheduler slurm
  expect_err "task \"render\": its group \"../../escaped\""
  [ ! -e "$tmp/d/escaped.sh" ] && [ ! -e "$tmp/escaped.sh" ] || fail "a group's script left the plan's folder"
  # Nor may an output, or a path in a command, leave the folder; nor the executable be another program.
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/d/p" --shards 2 "${small[@]}"
  cp "$tmp/d/p/plan.json" "$tmp/good.json"
  edit_plan "$tmp/d/p/plan.json" "p['tasks'][0]['outputs'] = ['$tmp/d/p/../x.hair']"
  expect_rc 2 "$hairgen" farm submit "$tmp/d/p/plan.json" --scheduler slurm --dry-run
  expect_err "task \"grow.1\": output"
  cp "$tmp/good.json" "$tmp/d/p/plan.json"
  edit_plan "$tmp/d/p/plan.json" "c = p['tasks'][0]['command']; c[c.index('-o') + 1] = '$tmp/elsewhere.hair'"
  expect_rc 2 "$hairgen" farm submit "$tmp/d/p/plan.json" --scheduler slurm --dry-run
  expect_err "task \"grow.1\": command path \"$tmp/elsewhere.hair\""
  cp "$tmp/good.json" "$tmp/d/p/plan.json"
  edit_plan "$tmp/d/p/plan.json" "p['tasks'][0]['command'][0] = '/bin/sh'"
  expect_rc 2 "$hairgen" farm submit "$tmp/d/p/plan.json" --scheduler slurm --dry-run
  expect_err "is not a hairgen executable"
  # A plan file read from another folder than the one it names.
  cp "$tmp/good.json" "$tmp/moved.json"
  expect_rc 2 "$hairgen" farm submit "$tmp/moved.json" --scheduler slurm --dry-run
  expect_err "not the folder it is in"
  ;;
quoted_scripts)
  # A folder whose name holds quotes, spaces and "$(...)" is legal: every script quotes it, passes sh -n,
  # and runs (on the fake Slurm) without running what the name holds; each task's log is logs/ID.log;
  # the tasks run with the CPUs the 2-CPU node gave them.
  fake_slurm
  dir="$tmp/it's \"a\" \$(touch $tmp/injected) \`touch $tmp/injected\` ; x"
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$dir" --shards 2 --cpus 8 "${small[@]}"
  expect_rc 0 "$hairgen" farm submit "$dir/plan.json" --scheduler slurm --wait
  grep -q "farm: the plan is done" "$tmp/out" || fail "the plan did not finish: $(cat "$tmp/out" "$tmp/err")"
  for script in "$dir"/slurm/*.sh; do
    sh -n "$script" && bash -n "$script" || fail "$script is not valid shell"
  done
  [ ! -e "$tmp/injected" ] || fail "a folder's name ran a command"
  expect_rc 0 "$hairgen" run "$setup" -o "$tmp/run" "${small[@]}"
  cmp "$tmp/run/beauty.exr" "$dir/beauty.exr" || fail "the farm's render differs from run's"
  for id in grow.1 grow.2 merge-guides interpolate.1 interpolate.2 merge-coupe render; do
    grep -q "^hairgen-farm: start $id " "$dir/logs/$id.log" || fail "logs/$id.log does not hold task $id"
  done
  ! ls "$dir/logs" | grep -q '\.0\.log' || fail "a log is named by an index, not a task: $(ls "$dir/logs")"
  grep -q "'--threads' \"\${SLURM_CPUS_PER_TASK:-" "$dir/slurm/render.sh" ||
    fail "the render's threads are not the node's: $(cat "$dir/slurm/render.sh")"
  ! grep -q -- '--cpus-per-task=[3-9]' "$tmp/sbatch.log" || fail "a task asked for more CPUs than the node has"
  ;;
provenance_bounds)
  # A 152-byte .hair output whose chunk length is 2^64-16 made the done check re-read one header 2^32
  # times: the provenance reader bounds every seek by the file's size.
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/p" --shards 2 "${small[@]}"
  mkdir -p "$tmp/p/shards"
  python3 - "$tmp/p/shards/guides.1.hair" <<'PY'
import struct, sys
header = b"HAIR" + struct.pack("<IIII", 0, 0, 2, 0) + bytes(128 - 20)
block = b"HGEN" + struct.pack("<II", 1, 0xFFFFFFFF) + b"XXXX" + struct.pack("<Q", 2**64 - 16)
open(sys.argv[1], "wb").write(header + block)
PY
  [ "$(stat -c %s "$tmp/p/shards/guides.1.hair")" -eq 152 ] || fail "the crafted file is not 152 bytes"
  SECONDS=0
  expect_rc 0 timeout 20 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm --dry-run
  ((SECONDS < 10)) || fail "the done check took $SECONDS s on a 152-byte file"
  grep -q "^job_grow=.*'--array=1,2'" "$tmp/out" || fail "the crafted output passed for done: $(cat "$tmp/out")"
  ;;
plan_limits)
  # Shards, frames and chunks are bounded, so a plan's size and the time to make it are.
  SECONDS=0
  expect_rc 2 timeout 20 "$hairgen" farm plan "$setup" -o "$tmp/p" --shards 100000 --quiet
  expect_err "--shards 100000: from 1 to 1000"
  gust="$src/configs/anjyo/gust/setup.txt"
  expect_rc 2 timeout 20 "$hairgen" farm plan "$gust" -o "$tmp/p" --frames 1-1000000 --chunk 1 --quiet
  expect_err "--frames 1-1000000: 1000000 frames; a farm plan holds at most 10000"
  expect_rc 2 timeout 20 "$hairgen" farm plan "$gust" -o "$tmp/p" --frames 1-5000 --chunk 1 --quiet
  expect_err "--chunk 1: the shot's 5000 frames make 5000 render tasks; a plan has at most 1000"
  expect_rc 2 timeout 20 "$hairgen" farm plan "$gust" -o "$tmp/p" --set "Dynamics.Frames=1 20000" --quiet
  expect_err "20000 frames"
  ((SECONDS < 15)) || fail "refusing took $SECONDS s"
  [ ! -e "$tmp/p" ] || fail "a refused plan left a folder"
  # A plan file is read only up to a size (a plan at the limits is about 20 MB).
  mkdir "$tmp/big" && truncate -s 70M "$tmp/big/plan.json"
  expect_rc 2 "$hairgen" farm submit "$tmp/big/plan.json" --scheduler slurm --dry-run
  expect_err "a farm plan is at most 67108864"
  ;;
dry_run_shell)
  # --dry-run prints a shell script: sh -n and bash -n pass, and run with a fake sbatch each job waits for
  # the job ids the lines before it set.
  expect_rc 0 "$hairgen" farm plan "$src/configs/anjyo/gust/setup.txt" -o "$tmp/shot" --frames 1-12 --chunk 5 --quiet
  expect_rc 0 "$hairgen" farm submit "$tmp/shot/plan.json" --scheduler slurm --dry-run --quiet
  cp "$tmp/out" "$tmp/dry.sh"
  sh -n "$tmp/dry.sh" && bash -n "$tmp/dry.sh" || fail "the dry run is not shell: $(cat "$tmp/dry.sh")"
  mkdir -p "$tmp/bin"
  printf '#!/bin/sh\nn=$(($(cat "$FAKE_SLURM/jobs" 2>/dev/null || echo 100) + 1)); echo $n > "$FAKE_SLURM/jobs"\nprintf "%%s\\n" "$@" >> "$FAKE_SLURM/sbatch.log"; echo $n\n' >"$tmp/bin/sbatch"
  chmod +x "$tmp/bin/sbatch"
  FAKE_SLURM="$tmp" PATH="$tmp/bin:$PATH" sh "$tmp/dry.sh" || fail "the dry run did not run"
  grep -qx -- "--dependency=afterok:101" "$tmp/sbatch.log" || fail "merge-guides does not wait for grow's job: $(cat "$tmp/sbatch.log")"
  grep -qx -- "--dependency=afterok:102,afterok:107" "$tmp/sbatch.log" ||
    fail "simulate.3 does not wait for its chunk before: $(cat "$tmp/sbatch.log")"
  grep -qx -- "--dependency=afterok:105,afterok:106,afterok:107,afterok:108" "$tmp/sbatch.log" ||
    fail "render does not wait for shade and the simulation: $(cat "$tmp/sbatch.log")"
  ;;
scheduler_down)
  # With Slurm down, the scheduler's own message reaches the user with what to do.
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/p" --shards 2 "${small[@]}"
  mkdir -p "$tmp/bin"
  printf '#!/bin/sh\necho "sinfo: error: Unable to contact slurm controller (connect failure)" >&2\nexit 1\n' >"$tmp/bin/sinfo"
  chmod +x "$tmp/bin/sinfo"
  PATH="$tmp/bin:$PATH" expect_rc 1 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm --quiet
  expect_err "Unable to contact slurm controller (connect failure)"
  expect_err "scripts/slurm-local.sh start"
  printf '#!/bin/sh\necho "2 4000"\n' >"$tmp/bin/sinfo"
  printf '#!/bin/sh\necho "sbatch: error: Batch job submission failed: Invalid account" >&2\nexit 1\n' >"$tmp/bin/sbatch"
  chmod +x "$tmp/bin"/*
  PATH="$tmp/bin:$PATH" expect_rc 1 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm --quiet
  expect_err "sbatch for grow failed (exit 1): sbatch: error: Batch job submission failed: Invalid account"
  [ "$(wc -l <"$tmp/err")" -eq 1 ] || fail "the error is not one line: $(cat "$tmp/err")"
  ;;
planted_files)
  # A plan from elsewhere may name a program called hairgen that it brought along, or hold links in its
  # folder that send submit's scripts or a task's outputs anywhere: refused, nothing written or run.
  fake_slurm
  expect_rc 0 "$hairgen" farm plan "$setup" -o "$tmp/p" --shards 2 "${small[@]}"
  cp "$tmp/p/plan.json" "$tmp/good.json"
  mkdir "$tmp/p/bin"
  printf '#!/bin/sh\ntouch %q\n' "$tmp/injected" >"$tmp/p/bin/hairgen"
  chmod +x "$tmp/p/bin/hairgen"
  edit_plan "$tmp/p/plan.json" "[t['command'].__setitem__(0, '$tmp/p/bin/hairgen') for t in p['tasks']]"
  for dry in --dry-run ""; do
    expect_rc 2 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm $dry
    expect_err "task \"grow.1\": its executable $tmp/p/bin/hairgen is not this hairgen"
  done
  [ ! -e "$tmp/injected" ] || fail "a plan ran the program it brought"
  [ ! -e "$tmp/p/slurm" ] || fail "a refused plan wrote scripts"
  # This hairgen by another name (a link to it) runs, as this hairgen.
  mkdir "$tmp/alias"
  ln -s "$hairgen" "$tmp/alias/hairgen"
  cp "$tmp/good.json" "$tmp/p/plan.json"
  edit_plan "$tmp/p/plan.json" "[t['command'].__setitem__(0, '$tmp/alias/hairgen') for t in p['tasks']]"
  expect_rc 0 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm --dry-run
  # Links in the plan's folder: slurm/ to a user's folder, shards/ to another.
  cp "$tmp/good.json" "$tmp/p/plan.json"
  mkdir "$tmp/victim" "$tmp/victim2"
  echo "the user's script" >"$tmp/victim/grow.sh"
  ln -s "$tmp/victim" "$tmp/p/slurm"
  expect_rc 2 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm
  expect_err "$tmp/p/slurm is a symbolic link"
  [ "$(cat "$tmp/victim/grow.sh")" = "the user's script" ] || fail "submit wrote through a link in the plan's folder"
  rm "$tmp/p/slurm"
  ln -s "$tmp/victim2" "$tmp/p/shards"
  expect_rc 2 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm
  expect_err "$tmp/p/shards is a symbolic link"
  [ -z "$(ls "$tmp/victim2")" ] || fail "a task wrote through a link in the plan's folder"
  rm "$tmp/p/shards"
  # A task's log named as a link to a user's file (Slurm opens it following links, and truncates it).
  mkdir "$tmp/p/logs"
  ln -s "$tmp/victim/grow.sh" "$tmp/p/logs/render.log"
  expect_rc 2 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm --dry-run
  expect_err "$tmp/p/logs/render.log is a symbolic link"
  rm "$tmp/p/logs/render.log"
  expect_rc 0 "$hairgen" farm submit "$tmp/p/plan.json" --scheduler slurm --wait
  [ -s "$tmp/p/beauty.exr" ] || fail "the plan without links did not run"
  ;;
*) fail "unknown case" ;;
esac
echo "ok ($case)"
