// SPDX-License-Identifier: MIT
// Internal: the one adapter between ODE's arrays and rheofeed's math (Vec3, Pose). ODE's
// dMatrix3 is 3x4 row-major with a padding column; rheofeed's rotations are 3x3 row-major, body
// to world. Every conversion copies values, so nothing is rounded.
#pragma once

#include <ode/ode.h>

#include "rheofeed/vec3.hpp"

namespace rheofeed {

inline Vec3 toVec3(const dReal* a) {
  return {a[0], a[1], a[2]};
}

/// A row-major 3x3 rotation (body to world) as ODE's dMatrix3 (padding column 0).
inline void toOdeMatrix(const double rotation[9], dMatrix3 r) {
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) r[4 * row + col] = rotation[3 * row + col];
    r[4 * row + 3] = 0;
  }
}

/// ODE's 3x4 rotation `r` (dBodyGetRotation, dGeomGetRotation) as a row-major 3x3 rotation.
inline void fromOdeMatrix(const dReal* r, double rotation[9]) {
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) rotation[3 * row + col] = r[4 * row + col];
  }
}

/// Pose of an ODE body (position m, world frame; rotation body to world).
inline Pose poseOf(dBodyID body) {
  Pose pose;
  pose.position = toVec3(dBodyGetPosition(body));
  fromOdeMatrix(dBodyGetRotation(body), pose.rotation);
  return pose;
}

/// Sets a placeable geom's world pose (position m, rotation body to world).
inline void setGeomPose(dGeomID geom, const Pose& pose) {
  dGeomSetPosition(geom, pose.position.x, pose.position.y, pose.position.z);
  dMatrix3 r;
  toOdeMatrix(pose.rotation, r);
  dGeomSetRotation(geom, r);
}

/// Velocity (m/s, world) of the material point of `body` at world point `p`; 0 for no body.
inline Vec3 pointVelocity(dBodyID body, const Vec3& p) {
  if (!body) return {};
  dVector3 v;
  dBodyGetPointVel(body, p.x, p.y, p.z, v);
  return toVec3(v);
}

}  // namespace rheofeed
