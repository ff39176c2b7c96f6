// SPDX-License-Identifier: MIT
// Writes a short run with its animation and viewer into the folder given as the only argument
// (for View.PlaywrightPlaysTheAnimation): run.csv, run.json, run.png (when gnuplot is there),
// run.glb, run.glb.js, three/ and view.html. A vibrating plate in full vibration, two part
// families (cubes at t = 0, cylinders at a rate) and a capsule; 0.3 s, sampled every 0.01 s.
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/output/animation.hpp"
#include "rheofeed/output/output.hpp"
#include "scene_builders.hpp"

using namespace rheofeed;
using namespace rheofeed::scene;

namespace {

Scene viewScene() {
  Scene s;
  s.name = "view_test";
  s.fixtures.push_back(test::vibratingBox("plate", {0.3, 0.1, 0.01}, {0, 0, 0}, 0.5e-3, 50,
                                          {std::cos(kPi / 6), 0, std::sin(kPi / 6)}));

  PartSpec cubes;
  cubes.name = "cubes";
  cubes.shape = Shape::Kind::Box;
  for (auto& d : cubes.size) d.mean = 0.012;
  cubes.density = 1000;
  cubes.count = 4;
  cubes.spawn_min = {-0.12, -0.035, 0.007};
  cubes.spawn_max = {0.12, 0.035, 0.007};
  s.parts.push_back(cubes);
  PartSpec rods;
  rods.name = "rods";
  rods.shape = Shape::Kind::Cylinder;
  rods.size[0].mean = 0.005;
  rods.size[1].mean = 0.02;
  rods.density = 1000;
  rods.count = 3;
  rods.rate = 10;  // at 0, 0.1 and 0.2 s
  rods.spawn_min = rods.spawn_max = {-0.1, 0, 0.03};
  rods.random_orientation = true;
  s.parts.push_back(rods);
  PartSpec pins;
  pins.name = "pins";
  pins.shape = Shape::Kind::Capsule;
  pins.size[0].mean = 0.004;
  pins.size[1].mean = 0.015;
  pins.density = 1000;
  pins.spawn_min = pins.spawn_max = {0.05, 0, 0.03};
  s.parts.push_back(pins);
  s.solver.time_step = 1e-3;
  s.duration = 0.3;
  s.outputs.sample_interval = 0.01;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FOLDER\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path folder = argv[1];
    const Scene scene = viewScene();
    const Method method = Method::OdeFullVibration;
    AnimationRecorder animation(scene, method);
    const RunMetrics run = measureRun(scene, method, {}, {&animation});
    std::vector<std::string> plots;
    for (const std::string& path : writeRunOutputs(run, folder.string(), "run")) {
      const std::filesystem::path p = path;
      if (p.extension() == ".png" || p.extension() == ".svg")
        plots.push_back(p.filename().string());
    }
    animation.write(folder / "run.glb");
    const std::filesystem::path page = writeViewer(folder, "run.glb", plots);
    std::printf("%d parts, %.3f s simulated, %d samples; open %s\n", run.parts,
                run.simulated_seconds, animation.samples(), page.string().c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_view_run: %s\n", e.what());
    return 1;
  }
}
