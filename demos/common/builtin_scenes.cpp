// SPDX-License-Identifier: MIT
#include "common/builtin_scenes.hpp"

#include <cmath>

namespace rheofeed::scene {
namespace {

Fixture boxFixture(const std::string& name, const Vec3& size, const Pose& pose) {
  Fixture f;
  f.name = name;
  Fixture::Geom g;
  g.shape.kind = Shape::Kind::Box;
  g.shape.size = size;
  g.pose = pose;
  f.geoms.push_back(g);
  return f;
}

}  // namespace

Fixture boxRing(const std::string& name, int count, double centre_radius, double inner_radius,
                double thickness, double height, double z_centre) {
  constexpr double kOverlap = 0.005;  // m, between neighbouring boxes
  Fixture ring;
  ring.name = name;
  for (int i = 0; i < count; ++i) {
    const double a = 2 * kPi * i / count;
    Fixture::Geom b;
    b.shape.kind = Shape::Kind::Box;
    b.shape.size = {thickness, 2 * inner_radius * std::tan(kPi / count) + kOverlap, height};
    b.pose = Pose::axisAngle({0, 0, 1}, a,
                             {centre_radius * std::cos(a), centre_radius * std::sin(a), z_centre});
    ring.geoms.push_back(b);
  }
  return ring;
}

namespace {

PartSpec cube(double edge, const Vec3& at) {
  PartSpec p;
  p.shape = Shape::Kind::Box;
  for (auto& d : p.size) d.mean = edge;
  p.density = 1000;
  p.spawn_min = p.spawn_max = at;
  p.count = 1;
  return p;
}

}  // namespace

Scene beltScene(double speed) {
  Scene s;
  s.name = "belt";
  Pose pose;
  pose.position = {0, 0, -0.05};
  Fixture belt = boxFixture("belt", {2, 0.5, 0.1}, pose);
  belt.law.kind = FeederLaw::Kind::Belt;
  belt.law.belt_speed = speed;
  s.fixtures.push_back(belt);
  s.parts.push_back(cube(0.05, {-0.5, 0, 0.03}));
  s.material.mu = 0.5;
  s.duration = 1.0;
  s.solver.time_step = 0.01;
  s.solver.iterations = 100;
  return s;
}

Scene inclineBeltScene(double angle, double speed) {
  Scene s = beltScene(speed);
  s.name = "incline_belt";
  // Rotating about -y by `angle` lifts +x. The belt's top surface passes through the origin.
  const Vec3 axis{0, -1, 0};
  const Pose tilt = Pose::axisAngle(axis, angle, {0, 0, 0});
  s.fixtures[0].geoms[0].pose = Pose::axisAngle(axis, angle, tilt.rotate({0, 0, -0.05}));
  s.fixtures[0].law.belt_direction = {std::cos(angle), 0, std::sin(angle)};
  PartSpec& p = s.parts[0];
  p.spawn_min = p.spawn_max = tilt.rotate({-0.5, 0, 0.026});
  s.parts[0].random_orientation = false;
  s.duration = 1.0;
  return s;
}

Scene turntableScene(double omega) {
  Scene s;
  s.name = "turntable";
  Pose pose;
  pose.position = {0, 0, -0.05};
  Fixture table = boxFixture("table", {1, 1, 0.1}, pose);
  table.law.kind = FeederLaw::Kind::Drift;
  table.law.drift.angular = {0, 0, omega};
  s.fixtures.push_back(table);
  s.parts.push_back(cube(0.04, {0.15, 0, 0.021}));
  s.parts.push_back(cube(0.04, {0.30, 0, 0.021}));
  s.material.mu = 0.8;
  s.duration = 0.5;
  s.solver.time_step = 0.01;
  s.solver.iterations = 100;
  return s;
}

Scene helicalRampScene(double omega) {
  Scene s;
  s.name = omega >= 0 ? "helical_ramp_up" : "helical_ramp_down";
  HelicalTrack track;  // radius 0.3 m, pitch 0.1 m per turn, 0.1 m wide, 2 cm thick
  track.radius = 0.3;
  track.width = 0.1;
  track.thickness = 0.02;
  track.pitch = 0.1;
  track.turns = 1.5;
  track.segments_per_turn = 48;
  Fixture ramp;
  ramp.name = "ramp";
  ramp.geoms = helicalTrack(track);
  ramp.law.kind = FeederLaw::Kind::Drift;
  ramp.law.drift.angular = {0, 0, omega};
  s.fixtures.push_back(ramp);
  // A part on the first half turn.
  const double phi0 = kPi / 2;
  PartSpec part = cube(0.03, {track.radius * std::cos(phi0), track.radius * std::sin(phi0),
                              track.pitch * phi0 / (2 * kPi) + 0.017});
  part.density = 1000;
  s.parts.push_back(part);
  s.material.mu = 0.8;
  s.duration = 1.5;
  s.solver.time_step = 0.005;
  s.solver.iterations = 100;
  return s;
}

Scene pileOnBeltScene(int count, double speed) {
  Scene s = beltScene(speed);
  s.name = "pile_on_belt";
  PartSpec p;
  p.shape = Shape::Kind::Box;
  for (auto& d : p.size) {
    d.mean = 0.04;
    d.stddev = 0.004;
    d.min = 0.03;
    d.max = 0.05;
  }
  p.density = 1000;
  p.spawn_min = {-0.8, -0.15, 0.04};
  p.spawn_max = {-0.4, 0.15, 0.04 + 0.02 * count / 5.0};
  p.count = count;
  p.random_orientation = true;
  s.parts = {p};
  s.duration = 2.0;
  return s;
}

Scene vibratingTrackScene(double amplitude, double frequency, double angle, int parts) {
  Scene s;
  s.name = "vibrating_track";
  Pose pose;
  pose.position = {0, 0, -0.025};
  Fixture track = boxFixture("track", {2.0, 0.2, 0.05}, pose);
  track.law.kind = FeederLaw::Kind::Vibration;
  track.law.vibration.amplitude = amplitude;
  track.law.vibration.frequency = frequency;
  track.law.vibration.direction = {std::cos(angle), 0, std::sin(angle)};
  s.fixtures.push_back(track);
  PartSpec p;
  p.name = "plates";
  p.shape = Shape::Kind::Box;
  p.size[0].mean = 0.02;
  p.size[1].mean = 0.02;
  p.size[2].mean = 0.005;
  p.density = 7800;
  // One row of parts along y (they drift along x, side by side, never touching).
  p.spawn_min = {-0.5, -0.09, 0.0025};
  p.spawn_max = {-0.5, 0.09, 0.0025};
  p.count = parts;
  s.parts.push_back(p);
  s.material.mu = 0.4;
  s.solver.time_step = 1.0 / (200 * frequency);
  s.solver.iterations = 50;
  s.solver.ode_quickstep = false;
  s.duration = 2.0;
  s.outputs.warmup = 0.5;
  s.outputs.sample_interval = 10.0 / frequency;
  return s;
}

Scene linearTroughScene(int count, double rate, double amplitude, double frequency, double angle) {
  Scene s;
  s.name = "linear_trough";
  Fixture trough;
  trough.name = "trough";
  auto add = [&](Fixture& f, const Vec3& size, const Vec3& at) {
    Fixture::Geom g;
    g.shape.kind = Shape::Kind::Box;
    g.shape.size = size;
    g.pose.position = at;
    f.geoms.push_back(g);
  };
  add(trough, {0.7, 0.12, 0.02}, {0.25, 0, -0.01});     // base, x from -0.1 to 0.6
  add(trough, {0.7, 0.01, 0.06}, {0.25, 0.065, 0.02});  // side walls
  add(trough, {0.7, 0.01, 0.06}, {0.25, -0.065, 0.02});
  add(trough, {0.01, 0.14, 0.06}, {-0.105, 0, 0.02});  // back wall
  trough.law.kind = FeederLaw::Kind::Vibration;
  trough.law.vibration.amplitude = amplitude;
  trough.law.vibration.frequency = frequency;
  trough.law.vibration.direction = {std::cos(angle), 0, std::sin(angle)};
  s.fixtures.push_back(trough);

  Fixture hopper;
  hopper.name = "hopper";
  // Static walls of a square hopper above the trough start (inside x = -0.085 .. 0.105 m,
  // y = -0.06 .. 0.06 m), open 60 mm above the floor at the front and back. The walls are 30 mm
  // thick, grown outwards from the 10 mm they were: a heap of 1000-2000 parts pressed parts
  // through the 10 mm front wall near its lower edge. The side walls reach 5 mm down into the
  // trough's side walls (z = 0.045 to 0.21 m): with their bottom at z = 0.06, 10 mm above the
  // trough walls' top, the heap pressed parts (5 mm thick and up) out through that slot and over
  // the trough's side (demos/results/crowd_leaks.md, section 10). The back wall's bottom is
  // still 10 mm above the trough's back wall, behind the flow: no part was lost there.
  add(hopper, {0.03, 0.12, 0.15}, {-0.1, 0, 0.135});
  add(hopper, {0.03, 0.12, 0.15}, {0.12, 0, 0.135});
  add(hopper, {0.25, 0.03, 0.165}, {0.01, 0.075, 0.1275});
  add(hopper, {0.25, 0.03, 0.165}, {0.01, -0.075, 0.1275});
  s.fixtures.push_back(hopper);

  Fixture floor;  // catches the parts that leave the trough
  floor.name = "floor";
  add(floor, {1.0, 1.0, 0.02}, {1.0, 0, -0.3});
  s.fixtures.push_back(floor);

  PartSpec p;
  p.name = "boxes";
  p.shape = Shape::Kind::Box;
  for (auto& d : p.size) {
    d.mean = 0.015;
    d.stddev = 0.0022;
    d.min = 0.008;
    d.max = 0.025;
  }
  p.size[2].mean = 0.008;
  p.size[2].stddev = 0.001;
  p.size[2].min = 0.005;
  p.density = 2700;
  p.spawn_min = {-0.05, -0.03, 0.12};  // inside the hopper with room for a turned part
  p.spawn_max = {0.07, 0.03, 0.18};
  p.random_orientation = true;
  p.count = count;
  p.rate = rate;
  s.parts.push_back(p);
  s.material.mu = 0.4;
  s.solver.time_step = 1.0 / (200 * frequency);
  s.solver.iterations = 30;
  // Without a surface layer, the ERP push after a part's landing on the vibrating floor can lock
  // it into a chattering orbit of its own: in a layer of 10 parts, 3 drifted at 0.26x the
  // others (ERP 0.2) or 1.3x (max correcting velocity 0.05 m/s). 0.1 mm removes it.
  s.solver.surface_layer = 1e-4;
  s.duration = 6.0;
  s.outputs.warmup = 2.0;
  s.outputs.sample_interval = 10.0 / frequency;
  s.outputs.exit_plane = true;
  s.outputs.exit_point = {0.6, 0, 0};
  s.outputs.exit_normal = {1, 0, 0};
  return s;
}

Scene tiltedTrackScene(double incline_deg, double cross_deg, bool sideways, bool quick) {
  constexpr double kDeg = 3.14159265358979323846 / 180;
  Scene s = vibratingTrackScene(0.2e-3, 50, 20 * kDeg, 1);
  const double a = incline_deg * kDeg, c = cross_deg * kDeg;
  s.gravity = {-9.81 * std::sin(a), -9.81 * std::cos(a) * std::sin(c),
               -9.81 * std::cos(a) * std::cos(c)};
  s.name = "track";
  s.parts[0].spawn_min = s.parts[0].spawn_max = {-0.2, 0, 0.0025};
  s.duration = quick ? 1.5 : 4.0;
  s.outputs.warmup = quick ? 0.5 : 1.0;
  if (sideways) s.outputs.conveying_direction = {0, 1, 0};
  return s;
}

Scene troughScene(int count, bool heap) {
  Scene s = linearTroughScene(count, 0, 0.2e-3, 50, 20 * kPi / 180);
  s.name = heap ? "trough_heap" : "trough_layer";
  s.fixtures.erase(s.fixtures.begin() + 1);  // no hopper
  PartSpec& p = s.parts[0];
  if (heap) {
    p.spawn_min = {-0.07, -0.04, 0.012};
    p.spawn_max = {0.23, 0.04, 0.045};
  } else {
    p.random_orientation = false;
    p.spawn_min = {-0.07, -0.04, 0.008};  // flat, a few mm above the floor
    p.spawn_max = {0.43, 0.04, 0.008};
  }
  s.duration = 3.0;
  s.outputs.warmup = 0.5;
  s.outputs.exit_plane = false;
  return s;
}

}  // namespace rheofeed::scene
