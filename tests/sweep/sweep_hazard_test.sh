#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A point whose runs warn in the scene check (here an amplitude given in metres that was meant
# in millimetres: 0.25 m at 50 Hz, 2500 g, the extreme_vibration hazard) is not silent in the
# sweep: sweep.csv's scene_check column counts the warnings and collect names the point on
# stderr; the point without a hazard has 0.
#   bash sweep_hazard_test.sh RHEOFEED WORK_DIR
set -euo pipefail
bin=$1 work=$2
# shellcheck source=test_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/test_lib.sh"
cat > "$work/spec.json" <<SPEC
{
  "name": "hazard",
  "scene": "linear_trough",
  "parameters": [{"name": "amplitude", "pointer": "/fixtures/0/law/vibration/amplitude",
                  "values": [0.00025, 0.25]},
                 {"name": "duration_s", "pointer": "/duration", "values": [0.5]},
                 {"name": "warmup_s", "pointer": "/outputs/warmup", "values": [0]}],
  "seeds": 1,
  "metrics": [{"name": "mean_drift_mps", "pointer": "/mean_drift"}]
}
SPEC
"$bin" sweep "$work/spec.json" --out "$work/sweep" > "$work/sweep.log" 2> "$work/sweep_stderr.log" ||
  fail "the sweep exited with $?, expected 0: $(cat "$work/sweep_stderr.log")"
csv="$work/sweep/results/sweep.csv"
head -1 "$csv" | grep -q ',scene_check$' || fail "sweep.csv has no scene_check column last: $(head -1 "$csv")"
# The main demo warns of its mass ratio at both points; the unit slip adds one at point 1.
hazards0=$(awk -F, '$1 == "0" {print $NF}' "$csv") hazards1=$(awk -F, '$1 == "1" {print $NF}' "$csv")
[ "$hazards1" = $((hazards0 + 1)) ] ||
  fail "point 1 (0.25 m) does not count one hazard more than point 0 (0.25 mm): $(cat "$csv")"
grep -q 'ran with scene-check hazards' "$work/sweep_stderr.log" ||
  fail "collect does not say on stderr that a point ran with hazards: $(cat "$work/sweep_stderr.log")"
grep -q 'point 1 (amplitude 0.25, duration_s 0.5, warmup_s 0), ode_rheonomic' "$work/sweep_stderr.log" ||
  fail "collect does not name point 1: $(cat "$work/sweep_stderr.log")"
grep -q 'extreme_vibration' "$work/sweep/jobs/0001/run/ode_rheonomic.json" ||
  fail "the run JSON of point 1 has no extreme_vibration warning"
! grep -q 'extreme_vibration' "$work/sweep/jobs/0000/run/ode_rheonomic.json" ||
  fail "the run JSON of point 0 (0.25 mm) has an extreme_vibration warning"
# Parameters held at one value (the duration, the warm-up) get no curve, and gnuplot no warning.
[ ! -e "$work/sweep/results/mean_drift_mps_vs_duration_s.png" ] ||
  fail "a parameter held at one value was plotted"
! grep -q 'empty x range' "$work/sweep_stderr.log" || fail "gnuplot warned of an empty x range"
echo "a point whose runs warn in the scene check is counted and named by the sweep"
