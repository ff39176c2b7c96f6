// SPDX-License-Identifier: MIT
// Belt-conveyor line: the scene file demos/scenes/belt_conveyor.json (built in; --scene loads
// another), run by the shared demo runner. A 2 m belt at 0.3 m/s between side rails; a hopper at
// its start drops 60 boxes (4 cm, 10 % size spread) at 4 parts/s; they leave through an exit
// plane at x = 0.9 m, 6 s of travel downstream. Expected: every box takes the belt speed within
// 0.06 s of landing (mu g t = 0.3 m/s at mu = 0.5), so the mean drift is 0.3 m/s (a little less
// while boxes are still dropping: a box in flight has no drift), and after the 7 s warm-up the
// flow through the exit is steady, so the throughput is the feed rate, 4 parts/s. The exit count
// against time is the `exited` column of the CSV.
//
// demos/belt_conveyor.cpp is the same kind of line written directly against the plugin API.
//
//   belt_line [--scene FILE.json] [--duration s] [--dt s] [--out folder] [--method ...]
#include "common/demo_runner.hpp"

int main(int argc, char** argv) {
  return rheofeed::demo::runSceneFileDemo(argc, argv, "belt_line",
                                          "rheofeed belt-conveyor line: hopper, belt, exit plane",
                                          "belt_conveyor.json");
}
