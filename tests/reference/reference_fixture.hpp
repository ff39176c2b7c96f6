// SPDX-License-Identifier: MIT
// Shared helpers of the reference-world tests: ODE initialisation, geoms and bodies built the
// way world.hpp asks (ODE geoms without ODE bodies, attached with World::attachGeom), inertia
// tensors of textbook solids and default settings. Expected values are computed by the tests
// themselves from analytic mechanics; nothing here calls into the code under test except to
// build the scene.
#pragma once

#include <gtest/gtest.h>
#include <ode/ode.h>

#include <array>
#include <cmath>

#include "rheofeed/reference/world.hpp"

namespace rheofeed::reference::test {

constexpr double kGravity = 9.81;  // m/s^2, |Settings::gravity| of every test world (along -z)

/// Expects `needle` to be a substring of `haystack` (gtest shows both on failure).
#define RHEOFEED_EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

/// Calls dInitODE2(0) once per process (thread-safe static initialisation). Every test calls it
/// before creating geoms.
inline void initOdeOnce() {
  static const bool initialised = [] {
    dInitODE2(0);
    return true;
  }();
  (void)initialised;
}

/// Inertia tensor (kg m^2, row-major, body frame) of a solid box of mass m (kg) and side
/// lengths lx, ly, lz (m): m (b^2 + c^2) / 12 on the diagonal.
inline std::array<double, 9> boxInertia(double m, double lx, double ly, double lz) {
  return {m * (ly * ly + lz * lz) / 12, 0, 0, 0, m * (lx * lx + lz * lz) / 12, 0, 0, 0,
          m * (lx * lx + ly * ly) / 12};
}

/// Inertia tensor (kg m^2) of a solid sphere of mass m (kg) and radius r (m): 2/5 m r^2.
inline std::array<double, 9> sphereInertia(double m, double r) {
  const double i = 0.4 * m * r * r;
  return {i, 0, 0, 0, i, 0, 0, 0, i};
}

/// Row-major rotation matrix about +y by `angle` (rad): x -> (cos, 0, -sin), z -> (sin, 0, cos).
inline std::array<double, 9> rotationAboutY(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c, 0, s, 0, 1, 0, -s, 0, c};
}

/// Unit quaternion (w, x, y, z) of a rotation about +y by `angle` (rad).
inline Quat quaternionAboutY(double angle) {
  return {std::cos(angle / 2), 0, std::sin(angle / 2), 0};
}

/// A dynamic box body with its box geom attached (geom centred on the centre of mass).
struct BoxBody {
  BodyId id = kStatic;
  dGeomID geom = nullptr;
};

inline BoxBody addBox(World& world, double mass, const Vec3& size, const BodyState& state) {
  const auto inertia = boxInertia(mass, size.x, size.y, size.z);
  BoxBody b;
  b.id = world.addBody(mass, inertia.data(), state);
  b.geom = dCreateBox(world.space(), size.x, size.y, size.z);
  world.attachGeom(b.geom, b.id);
  return b;
}

/// A dynamic sphere body with its sphere geom attached; returns the body.
inline BodyId addSphere(World& world, double mass, double radius, const BodyState& state) {
  const auto inertia = sphereInertia(mass, radius);
  const BodyId id = world.addBody(mass, inertia.data(), state);
  world.attachGeom(dCreateSphere(world.space(), radius), id);
  return id;
}

/// The static ground: the plane z = 0 (normal +z), not attached to any body.
inline dGeomID addGround(World& world) {
  return dCreatePlane(world.space(), 0, 0, 1, 0);
}

/// A static box geom (not attached) at `position` (m) with row-major rotation `rotation`.
inline dGeomID addStaticBox(World& world, const Vec3& size, const Vec3& position,
                            const std::array<double, 9>& rotation) {
  dGeomID g = dCreateBox(world.space(), size.x, size.y, size.z);
  dGeomSetPosition(g, position.x, position.y, position.z);
  dMatrix3 m;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m[4 * i + j] = rotation[3 * i + j];
    m[4 * i + 3] = 0;
  }
  dGeomSetRotation(g, m);
  return g;
}

/// A body state at rest at `position` (m) with orientation `q`.
inline BodyState restingAt(const Vec3& position, const Quat& q = {}) {
  BodyState s;
  s.position = position;
  s.orientation = q;
  return s;
}

/// Settings of the test worlds: the defaults (ODE's ERP 0.2, CFM 1e-5) with gravity -kGravity z.
inline Settings defaultSettings() {
  Settings s;
  s.gravity = {0, 0, -kGravity};
  return s;
}

/// The same in true-Coulomb mode: the solver's outer fixed point on the normal shift.
inline Settings coulombSettings(int outer_iterations = 50) {
  Settings s = defaultSettings();
  s.solver.coulomb_outer_iterations = outer_iterations;
  return s;
}

}  // namespace rheofeed::reference::test
