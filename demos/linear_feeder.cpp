// SPDX-License-Identifier: MIT
// Linear vibratory feeder: a hopper drops boxes of normally distributed sizes (mean 15 mm,
// 15 % spread) at 20 parts/s into a 0.7 m trough that vibrates at 50 Hz, 0.25 mm peak, 30 degrees
// to the track (throw number 1.26: the parts hop, as on industrial feeders). The trough is replaced
// by a stationary feeder whose drift field is calibrated once from a short full-vibration run of a
// few parts; the whole flow then runs at h = 0.01 s. Outputs: mean drift with its 95 % band,
// throughput through the exit at the trough's end (x = 0.6 m), CPU time and real-time factor; CSV +
// JSON + PNG per method.
//
//   linear_feeder [--scene FILE.json] [--duration s] [--dt s] [--out folder]
//                 [--method ode_rheonomic,ode_full_vibration,...]
#include "common/demo_runner.hpp"
#include "rheofeed/scene/builtin_scenes.hpp"

int main(int argc, char** argv) {
  rheofeed::scene::Scene scene = rheofeed::scene::linearTroughScene(/*count=*/120, /*rate=*/20);
  scene.duration = 30.0;  // parts need about 19 s from the hopper to the exit
  return rheofeed::demo::runDemo(argc, argv, "linear_feeder",
                                 "rheofeed linear vibratory feeder: hopper + trough", scene);
}
