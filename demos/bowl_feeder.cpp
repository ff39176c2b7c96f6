// SPDX-License-Identifier: MIT
// Vibratory bowl feeder: the scene file demos/scenes/bowl_feeder.json (built in; --scene loads
// another). A bowl of inner radius 150 mm with a helical ramp on its wall (20 mm wide, 30 mm pitch,
// 2 turns, rising counter-clockwise from the floor at azimuth 0 to z = 70 mm) and 12 M6 hex nut
// blanks, both CAD-like meshes read with assimp. The bowl vibrates in a screw motion at 50 Hz
// (0.15 mm vertical, 0.17 degrees torsion, in phase); a rheonomic run replaces it by its
// calibrated drift on the ramp, a rotation of 0.31 rad/s about the bowl axis. A 25 degree cone
// ring in the middle of the bowl sends the nuts to the wall just before the ramp start; they reach
// the ramp within 5-8 s and climb 1.5 mm/s (the scene file's comments derive these numbers).
//
// Metrics: the drift is the angular velocity of the nuts about the bowl axis (rad/s), and the
// mean height of the nuts (the paper's bowl plot): it first drops (they fall onto the floor from
// ~50 mm) and then rises steadily as they climb. Besides the runner's outputs (CSV, JSON and
// drift PNG per method), mean_height.png shows the height against time for every method run.
//
// Time step: the trimesh bowl (4 mm ramp, 10 mm floor) and 5 mm nuts need h <= 0.005 s in a
// rheonomic run; at 0.01 s some nuts tunnel through the floor. So this demo's rheonomic step is
// 0.005 s unless the command line gives --dt. The default run (40 s) costs about
// 22 s of CPU. Full-vibration runs use the scene's 0.2 ms (100 steps per cycle) and cost about
// 19 s of CPU per simulated second: compare the methods over a few seconds, e.g.
//   bowl_feeder --method ode_rheonomic,ode_full_vibration --duration 10
//
//   bowl_feeder [--scene FILE.json] [--duration s] [--dt s] [--out folder]
//               [--method ode_rheonomic,ode_full_vibration,...]
#include "common/demo_runner.hpp"

int main(int argc, char** argv) {
  rheofeed::demo::DemoOptions options;
  options.rheonomic_time_step = 0.005;  // s: see the header comment
  options.plot_height = true;
  return rheofeed::demo::runSceneFileDemo(
      argc, argv, "bowl_feeder",
      "rheofeed vibratory bowl feeder: helical ramp, CAD meshes (assimp), M6 nuts",
      "bowl_feeder.json", options);
}
