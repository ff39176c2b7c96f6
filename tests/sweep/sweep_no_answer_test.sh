#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A point whose run loses every part (`rheofeed run` exits 3, kNoAnswerExitCode) is a valid
# answer of the sweep: its job is ok, its record says "no_answer" and carries the run's health,
# and sweep.csv has the point with its seed ok and a null mean drift. The scene: two boxes
# spawned past the end of a belt, with nothing under them (tests/data/scenes/all_parts_fall.json).
#   bash sweep_no_answer_test.sh RHEOFEED SCENE WORK_DIR
set -euo pipefail
bin=$1 scene=$2 work=$3
# shellcheck source=test_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"
cat > "$work/spec.json" <<SPEC
{
  "name": "no_answer",
  "scene": "$scene",
  "parameters": [{"name": "speed_mps", "pointer": "/fixtures/0/law/belt/speed", "values": [0.3]}],
  "seeds": 1,
  "metrics": [{"name": "mean_drift_mps", "pointer": "/mean_drift"},
              {"name": "lost", "pointer": "/health/parts_lost"}]
}
SPEC
"$bin" sweep "$work/spec.json" --out "$work/sweep" > "$work/sweep.log" 2>&1 ||
  fail "the sweep exited with $?, expected 0 (a run with no answer is a done job)"
record="$work/sweep/records/0000.json"
grep -q '"status": "ok"' "$record" || fail "job 0000 is not ok"
grep -q '"exit_code": 3' "$record" || fail "job 0000 does not record exit code 3"
grep -q '"no_answer": ".*lost all 2 parts' "$record" || fail "job 0000 does not say why it has no answer"
grep -q '"parts_lost": 2' "$record" || fail "job 0000's health is not recorded"
grep -q '^0,0.3,ode_rheonomic,1,0,' "$work/sweep/results/sweep.csv" ||
  fail "point 0 is not 1 seed ok, 0 failed in sweep.csv: $(cat "$work/sweep/results/sweep.csv")"
echo "a run with no answer is a done job of the sweep, with its health"
