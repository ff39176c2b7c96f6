#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A failed job is recorded, listed by collect with its error and the command that reruns it, and
# run again (alone) by the next sweep. The failure: one job's generated scene file is changed
# after the sweep folder was written, so its hash no longer matches the manifest (a job must not
# record parameters its scene does not have).
#   bash sweep_failed_job_test.sh RHEOFEED SPEC WORK_DIR
set -euo pipefail
bin=$1 spec=$2 work=$3
# shellcheck source=test_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"
dir="$work/sweep"
# The folder written, nothing run (the Slurm scripts are only written).
"$bin" sweep "$spec" --backend slurm --out "$dir" > "$work/prepare.log" 2>&1 || fail "prepare: $?"
sed -i 's/"seed": 2/"seed": 3/' "$dir/jobs/0001/scene.json"
set +e
"$bin" sweep job "$dir" 0000 0001 0002 0003 > "$work/jobs.log" 2>&1
code=$?
set -e
[ "$code" -eq 1 ] || fail "sweep job exited with $code, expected 1 (a job failed)"
grep -q '"status": "failed"' "$dir/records/0001.json" || fail "record 0001 is not failed"
grep -q 'has hash fnv1a64:.*the sweep generated fnv1a64:' "$dir/records/0001.json" ||
  fail "record 0001 does not say why"
set +e
"$bin" sweep collect "$dir" > "$work/collect.log" 2>&1
code=$?
set -e
[ "$code" -eq 1 ] || fail "collect exited with $code, expected 1 (a job unfinished)"
grep -q "job 0001 failed: the job's scene file .* has hash" "$work/collect.log" || fail "collect does not list job 0001's error"
grep -q "rerun: rheofeed sweep job '.*/sweep' 0001" "$work/collect.log" || fail "collect does not give the rerun command"
grep -q "rerun: rheofeed sweep job" "$dir/results/unfinished.txt" || fail "no results/unfinished.txt"
grep -q '^0,0.2,ode_rheonomic,1,1,0,' "$dir/results/sweep.csv" || fail "point 0 is not 1 ok + 1 failed in sweep.csv"
# The sweep again: the scene file rewritten, only job 0001 run.
"$bin" sweep "$spec" --out "$dir" > "$work/again.log" 2>&1 || fail "the sweep again exited with $?"
grep -q '^local: 1 of 4 jobs to run' "$work/again.log" || fail "the sweep again does not run exactly 1 job"
grep -q '^job 0001 ok' "$work/again.log" || fail "job 0001 did not run again"
[ ! -e "$dir/results/unfinished.txt" ] || fail "unfinished.txt left after every job finished"
echo "failed job recorded, listed with its rerun command, and rerun alone by the next sweep"
