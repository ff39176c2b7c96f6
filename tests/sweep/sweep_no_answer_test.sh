#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A point whose run has no answer (`rheofeed run` exits 3, kNoAnswerExitCode: here it loses a
# quarter of its parts, more than the default --max-lost-fraction 0.1) is a finished job with
# status "no_answer": its record says why and carries the run's metrics and health, the next
# sweep does not run it again, and collect counts it in sweep.csv's seeds_no_answer, leaves it
# out of the means (its run measured a mean drift over the parts left), marks it in jobs.csv
# and lists it on stderr with why. The scene (tests/data/scenes/some_parts_fall.json): three
# boxes on a belt and one past its end that falls; at point 0 the removal height is too low for
# the fall to reach in the run (nothing lost: an answer), at point 1 it is the scene's.
#   bash sweep_no_answer_test.sh RHEOFEED SCENE WORK_DIR
set -euo pipefail
bin=$1 scene=$2 work=$3
# shellcheck source=test_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"
cat > "$work/spec.json" <<SPEC
{
  "name": "no_answer",
  "scene": "$scene",
  "parameters": [{"name": "removal_height_m", "pointer": "/removal_height", "values": [-2, -0.5]}],
  "seeds": 1,
  "metrics": [{"name": "mean_drift_mps", "pointer": "/mean_drift"},
              {"name": "trusted", "pointer": "/answer/trusted"}]
}
SPEC
"$bin" sweep "$work/spec.json" --out "$work/sweep" > "$work/sweep.log" 2> "$work/sweep_stderr.log" ||
  fail "the sweep exited with $?, expected 0 (a run with no answer is a finished job)"
ok="$work/sweep/records/0000.json" record="$work/sweep/records/0001.json"
grep -q '"status": "ok"' "$ok" || fail "job 0000 (nothing lost) is not ok"
grep -q '"status": "no_answer"' "$record" || fail "job 0001 is not no_answer"
grep -q '"exit_code": 3' "$record" || fail "job 0001 does not record exit code 3"
grep -q '"no_answer": "ode_rheonomic lost 1 of 4 parts (25 %), more than max_lost_fraction 0.1"' "$record" ||
  fail "job 0001 does not say why it has no answer"
grep -q '"parts_lost": 1' "$record" || fail "job 0001's health is not recorded"
grep -q '"mean_drift_mps": [0-9]' "$record" || fail "job 0001's run measured no mean drift (the test needs one to leave out)"
grep -q '"trusted": 0' "$record" || fail "job 0001's metric /answer/trusted is not 0"
# the verdict per method (a job with several methods answers for those whose runs have one)
grep -A1 '^  "trusted": {' "$record" | grep -q '"ode_rheonomic": false' ||
  fail "job 0001 does not record ode_rheonomic's verdict, untrusted"
csv="$work/sweep/results/sweep.csv"
head -1 "$csv" | grep -q '^point,removal_height_m,method,seeds_ok,seeds_failed,seeds_missing,seeds_no_answer,mean_drift_mps_mean,' ||
  fail "sweep.csv has no seeds_no_answer column: $(head -1 "$csv")"
grep -q '^0,-2,ode_rheonomic,1,0,0,0,[0-9]' "$csv" || fail "point 0 is not 1 seed ok with a mean: $(cat "$csv")"
# point 1: no seed ok, 1 with no answer, no mean (the no-answer seed is left out), n 0
grep -q '^1,-0.5,ode_rheonomic,0,0,0,1,,,0,' "$csv" ||
  fail "point 1 is not 1 seed with no answer and no mean in sweep.csv: $(cat "$csv")"
grep -q '^0001,1,1,-0.5,ode_rheonomic,no_answer,.*"ode_rheonomic lost 1 of 4 parts' "$work/sweep/results/jobs.csv" ||
  fail "jobs.csv does not mark job 0001 no_answer with why: $(cat "$work/sweep/results/jobs.csv")"
grep -q '1 of 2 jobs have no answer' "$work/sweep_stderr.log" || fail "collect does not say on stderr that a job has no answer"
grep -q 'job 0001 (point 1, seed 1): ode_rheonomic lost 1 of 4 parts' "$work/sweep_stderr.log" ||
  fail "collect does not list job 0001 with why on stderr"
[ ! -e "$work/sweep/results/unfinished.txt" ] || fail "a job with no answer is listed as unfinished"
# The sweep again runs nothing: a run with no answer would give none again.
"$bin" sweep "$work/spec.json" --out "$work/sweep" > "$work/again.log" 2>&1 ||
  fail "the sweep again exited with $?"
grep -q '^local: 0 of 2 jobs to run' "$work/again.log" || fail "the sweep again runs a job"
# A folder written before specs had max_lost_fraction (its manifest without the key) resumes.
grep -q '"max_lost_fraction": 0.1' "$work/sweep/sweep.json" || fail "the manifest has no max_lost_fraction"
sed -i '/"max_lost_fraction"/d' "$work/sweep/sweep.json"
"$bin" sweep "$work/spec.json" --out "$work/sweep" > "$work/older.log" 2>&1 ||
  fail "a folder of a manifest without max_lost_fraction is refused: $(cat "$work/older.log")"
grep -q '^local: 0 of 2 jobs to run' "$work/older.log" || fail "the older folder's sweep runs a job"
# The same folder with another bound is another sweep, and says which setting differs.
# (the same spec file: the jobs' scenes name the spec they came from)
sed -i 's/"seeds": 1,/"seeds": 1, "max_lost_fraction": 0.5,/' "$work/spec.json"
! "$bin" sweep "$work/spec.json" --out "$work/sweep" > "$work/half.log" 2>&1 ||
  fail "a folder of another max_lost_fraction is resumed"
grep -q 'its max_lost_fraction is 0.1, this spec.s 0.5' "$work/half.log" ||
  fail "the refusal does not name max_lost_fraction: $(cat "$work/half.log")"
# A spec that allows a quarter of the parts lost (a feeder with a reject slot): both jobs ok.
sed 's/"max_lost_fraction": 0.5,/"max_lost_fraction": 0.25,/' "$work/spec.json" > "$work/spec_quarter.json"
"$bin" sweep "$work/spec_quarter.json" --out "$work/quarter" > "$work/quarter.log" 2>&1 ||
  fail "the sweep with max_lost_fraction 0.25 exited with $?: $(cat "$work/quarter.log")"
grep -q '"status": "ok"' "$work/quarter/records/0001.json" ||
  fail "with max_lost_fraction 0.25, job 0001 (a quarter lost) is not ok"
grep -q -- '--max-lost-fraction' "$work/quarter/records/0001.json" ||
  fail "job 0001's recorded command does not pass --max-lost-fraction"
echo "a run with no answer is a finished job of the sweep, counted apart and left out of the means"
