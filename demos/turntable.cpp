// SPDX-License-Identifier: MIT
// Turntable: a disc of radius 0.4 m turning at 1 rad/s about +z (a stationary cylinder with a
// rheonomic rotation twist, surface velocity w x r), a static rim of 36 boxes, and a static
// fence across the disc that stops the parts and makes them slide outward along it onto the
// rim. 40 boxes are dropped on the disc at t = 0. The drift metric is the parts' angular
// velocity about the axis (rad/s): parts riding the disc turn at w, parts held by the fence do
// not, so the mean drift shows how many are held.
//
//   turntable [--scene FILE.json] [--duration s] [--dt s] [--out folder] [--method ...]
#include <cmath>

#include "common/demo_runner.hpp"
#include "rheofeed/scene/builtin_scenes.hpp"

namespace {

using namespace rheofeed;
using namespace rheofeed::scene;

Scene turntable() {
  constexpr double kRadius = 0.4, kOmega = 1.0;  // m, rad/s
  Scene s;
  s.name = "turntable";
  Fixture disc;
  disc.name = "disc";
  Fixture::Geom g;
  g.shape.kind = Shape::Kind::Cylinder;  // along z
  g.shape.radius = kRadius;
  g.shape.length = 0.02;
  g.pose.position = {0, 0, -0.01};
  disc.geoms.push_back(g);
  disc.law.kind = FeederLaw::Kind::Drift;
  disc.law.drift.angular = {0, 0, kOmega};
  s.fixtures.push_back(disc);

  // 36 static boxes around the disc, 2 cm thick and 6 cm tall, 1 cm clear of its edge.
  s.fixtures.push_back(boxRing("rim", 36, kRadius + 0.02, kRadius + 0.01, 0.02, 0.06, 0.02));

  Fixture fence;  // a static bar across the disc along the +y axis, just above the surface
  fence.name = "fence";
  Fixture::Geom f;
  f.shape.kind = Shape::Kind::Box;
  f.shape.size = {0.01, 0.3, 0.04};
  f.pose.position = {0, 0.2, 0.021};
  fence.geoms.push_back(f);
  s.fixtures.push_back(fence);

  PartSpec p;
  p.name = "boxes";
  p.shape = Shape::Kind::Box;
  for (auto& d : p.size) {
    d.mean = 0.03;
    d.stddev = 0.003;
    d.min = 0.02;
    d.max = 0.04;
  }
  p.density = 1200;
  p.spawn_min = {0.03, -0.25, 0.03};  // clear of the fence (x = 0, y = 0.05..0.35)
  p.spawn_max = {0.25, 0.10, 0.20};
  p.random_orientation = true;
  p.count = 40;
  s.parts.push_back(p);
  s.material.mu = 0.5;
  s.solver.time_step = 0.01;
  s.solver.iterations = 40;
  s.duration = 10;
  s.outputs.angular_drift = true;
  s.outputs.sample_interval = 0.1;
  s.outputs.warmup = 1.0;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  return rheofeed::demo::runDemo(argc, argv, "turntable",
                                 "rheofeed turntable: a rotating disc, a rim and a fence",
                                 turntable());
}
