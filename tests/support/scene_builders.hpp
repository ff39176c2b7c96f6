// SPDX-License-Identifier: MIT
// Test support: the scene pieces the scene, validation and view tests build again and again - a
// box fixture whose top face sits at a given point, the same box vibrating, a cube at rest on a
// floor - so that each test states only its own numbers. Header-only; needs rheofeed::scene.
#pragma once

#include <string>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::test {

/// A static ground plane fixture named `name`: the half-space z <= height (m, world frame).
inline scene::Fixture groundPlane(const std::string& name, double height) {
  scene::Fixture ground;
  ground.name = name;
  scene::Fixture::Geom plane;
  plane.shape.kind = scene::Shape::Kind::Plane;
  plane.shape.plane_normal = {0, 0, 1};
  plane.shape.plane_offset = height;
  ground.geoms.push_back(plane);
  return ground;
}

/// A static box fixture named `name` of edge lengths `size` (m), axis-aligned, whose top face
/// is centred at `top_centre` (m, world frame): the box centre is top_centre - (0, 0, size.z / 2).
inline scene::Fixture boxFixture(const std::string& name, const Vec3& size,
                                 const Vec3& top_centre = {}) {
  scene::Fixture f;
  f.name = name;
  scene::Fixture::Geom g;
  g.shape.kind = scene::Shape::Kind::Box;
  g.shape.size = size;
  g.pose.position = top_centre - Vec3{0, 0, 0.5 * size.z};
  f.geoms.push_back(g);
  return f;
}

/// boxFixture vibrating in translation: displacement `amplitude` (m) along the unit `direction`
/// (world frame) at `frequency` (Hz), sinusoidal (scene.hpp Vibration; its other settings at
/// their defaults).
inline scene::Fixture vibratingBox(const std::string& name, const Vec3& size,
                                   const Vec3& top_centre, double amplitude, double frequency,
                                   const Vec3& direction) {
  scene::Fixture f = boxFixture(name, size, top_centre);
  f.law.kind = scene::FeederLaw::Kind::Vibration;
  f.law.vibration.amplitude = amplitude;
  f.law.vibration.frequency = frequency;
  f.law.vibration.direction = direction;
  return f;
}

/// A 2 cm cube (steel, the PartSpec defaults) resting with its bottom face on a static 1 m x
/// 1 m x 2 cm floor whose top is at z = 0, named `name`; steps of `time_step` (s) for
/// `duration` (s).
inline scene::Scene cubeOnFloor(const std::string& name, double time_step, double duration) {
  scene::Scene s;
  s.name = name;
  s.fixtures.push_back(boxFixture("floor", {1, 1, 0.02}));
  scene::PartSpec p;
  for (auto& d : p.size) d.mean = 0.02;
  p.spawn_min = p.spawn_max = {0, 0, 0.01};
  s.parts.push_back(p);
  s.solver.time_step = time_step;
  s.duration = duration;
  return s;
}

}  // namespace rheofeed::test
