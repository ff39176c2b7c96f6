#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `rheofeed sweep` end to end with one backend (local or parallel) on a tiny spec (4 jobs):
#   1. a whole sweep: every job has an "ok" record with the fields the issue asks for, collect
#      wrote sweep.csv (one row per point) and the plots; with REFERENCE_CSV, the CSV is
#      byte-identical to it (the same spec on another backend);
#   2. a sweep interrupted after its first record (SIGINT for local, as Ctrl-C; SIGTERM for
#      parallel) exits 130 leaving only whole records; run again, it runs only the jobs without
#      a record (counted from its output) and leaves the earlier records untouched (same inode and
#      modification time: never rewritten), and its CSV equals the whole sweep's.
#   3. a job already running (a shell holding the job's lock as `sweep job` does) is not started
#      a second time (exit 1, the line names the process); with GNU parallel, an interrupted
#      sweep stops such a stray job before it returns, so no record appears after it said it was
#      interrupted.
#   bash sweep_backend_test.sh RHEOFEED SPEC WORK_DIR BACKEND [REFERENCE_CSV]
set -euo pipefail
bin=$1 spec=$2 work=$3 backend=$4 reference=${5:-}
# shellcheck source=test_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"
jobs_total=4

# 1. The whole sweep.
"$bin" sweep "$spec" --backend "$backend" --jobs 2 --out "$work/full" > "$work/full.log" 2>&1 ||
  fail "the sweep exited with $?"
records=$(ls "$work/full/records" | wc -l)
[ "$records" -eq "$jobs_total" ] || fail "$records records, expected $jobs_total"
for r in "$work/full/records/"*.json; do
  grep -q '"status": "ok"' "$r" || fail "$r is not ok"
  for key in parameters metrics health status cpu_seconds rheofeed_version scene_hash seed; do
    grep -q "\"$key\":" "$r" || fail "$r has no \"$key\""
  done
done
[ "$(wc -l < "$work/full/results/sweep.csv")" -eq 3 ] || fail "sweep.csv has not 1 + 2 rows"
head -1 "$work/full/results/sweep.csv" | grep -q '^point,amplitude_mm,method,seeds_ok,.*mean_drift_mps_mean,mean_drift_mps_ci95,mean_drift_mps_n' ||
  fail "sweep.csv header: $(head -1 "$work/full/results/sweep.csv")"
[ -s "$work/full/results/mean_drift_mps_vs_amplitude_mm.png" ] || fail "no plot of the drift"
if [ -n "$reference" ]; then
  cmp "$reference" "$work/full/results/sweep.csv" ||
    fail "sweep.csv differs from $reference (the same spec on another backend)"
  echo "sweep.csv identical to $reference"
fi

# 2. Interrupted after the first record, then resumed.
signal=INT
[ "$backend" = parallel ] && signal=TERM
"$bin" sweep "$spec" --backend "$backend" --jobs 1 --out "$work/resumed" > "$work/first.log" 2>&1 &
pid=$!
# Until the first record exists (the bound only keeps a broken sweep from hanging the test).
for _ in $(seq 1 6000); do
  [ -n "$(ls "$work/resumed/records" 2>/dev/null)" ] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.05
done
kill -"$signal" "$pid" 2>/dev/null || true
set +e
wait "$pid"
code=$?
set -e
[ "$code" -eq 130 ] || fail "the interrupted sweep exited with $code, expected 130"
done_before=$(ls "$work/resumed/records" | wc -l)
if [ "$done_before" -lt 1 ] || [ "$done_before" -ge "$jobs_total" ]; then
  fail "$done_before of $jobs_total records after the interruption; expected some, not all"
fi
! ls -a "$work/resumed/records" | grep -q partial || fail "a partial record was left"
stat -c '%n %i %y' "$work/resumed/records/"*.json > "$work/before.txt"
echo "interrupted with SIG$signal after $done_before of $jobs_total jobs:"
cat "$work/before.txt"

"$bin" sweep "$spec" --backend "$backend" --jobs 2 --out "$work/resumed" > "$work/resume.log" 2>&1 ||
  fail "the resumed sweep exited with $?"
ran=$(grep -c '^job [0-9]* ok' "$work/resume.log" || true)
[ "$ran" -eq $((jobs_total - done_before)) ] ||
  fail "the resumed sweep ran $ran jobs, expected $((jobs_total - done_before))"
while read -r name inode mtime; do
  now=$(stat -c '%n %i %y' "$name")
  [ "$now" = "$name $inode $mtime" ] || fail "record rewritten by the resumed sweep: was '$name $inode $mtime', now '$now'"
done < "$work/before.txt"
[ "$(grep -l '"status": "ok"' "$work/resumed/records/"*.json | wc -l)" -eq "$jobs_total" ] ||
  fail "not every job has an ok record after the resume"
cmp "$work/full/results/sweep.csv" "$work/resumed/results/sweep.csv" ||
  fail "the resumed sweep's CSV differs from the whole sweep's"
echo "resumed: ran the $ran unfinished jobs; the $done_before earlier records untouched; CSV identical"

# 3. A job that is already running: a shell holds job 0003's lock the way `sweep job` does
#    (flock on jobs/0003/job.lock, its pid and host written in it) for as long as the test wants.
stray_dir=$work/stray
# The folder without running any job: the Slurm backend only writes its scripts.
"$bin" sweep "$spec" --backend slurm --out "$stray_dir" > "$work/stray_prepare.log" 2>&1 ||
  fail "preparing $stray_dir (Slurm scripts, no job run) exited with $?"
lock=$stray_dir/jobs/0003/job.lock
(
  exec 9<> "$lock"
  flock -x 9
  echo "$BASHPID $(hostname)" > "$lock"
  exec sleep 1000
) &
holder=$!
until [ -s "$lock" ]; do
  kill -0 "$holder" 2> /dev/null || fail "the shell holding job 0003's lock ended"
  sleep 0.01
done
set +e
"$bin" sweep job "$stray_dir" 0003 > "$work/second_job.log" 2>&1
code=$?
set -e
[ "$code" -eq 1 ] || fail "a second process for the running job 0003 exited with $code, expected 1"
grep -q "job 0003: not started: process $holder on .* is running it" "$work/second_job.log" ||
  fail "the second process did not name the running one ($holder)"
if [ "$backend" = parallel ]; then
  # Interrupted once its signal handlers are in place (the line it prints before it starts GNU
  # parallel), whatever GNU parallel has done by then, the sweep stops the job it cannot signal.
  "$bin" sweep "$spec" --backend "$backend" --jobs 1 --out "$stray_dir" > "$work/stray_sweep.log" 2>&1 &
  pid=$!
  until grep -q '^parallel: [0-9]* of [0-9]* jobs to run' "$work/stray_sweep.log"; do
    kill -0 "$pid" 2> /dev/null || fail "the sweep ended before it started GNU parallel"
    sleep 0.01
  done
  kill -TERM "$pid"
  set +e
  wait "$pid"
  code=$?
  set -e
  [ "$code" -eq 130 ] || fail "the interrupted sweep exited with $code, expected 130"
  grep -q "parallel: job 0003 still running (process $holder) after the backend stopped: stopping it" "$work/stray_sweep.log" ||
    fail "the interrupted sweep did not stop the stray job 0003 (process $holder)"
  kill -0 "$holder" 2> /dev/null && fail "the stray job 0003 (process $holder) still runs after the sweep returned"
  echo "a stray job was stopped by the interrupted GNU parallel sweep before it returned"
else
  kill -TERM "$holder"
fi
wait "$holder" || true
echo "a running job is not started a second time"
