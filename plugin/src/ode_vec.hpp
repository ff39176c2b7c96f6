// SPDX-License-Identifier: MIT
// Internal: conversions between ODE's arrays and rheofeed::Vec3 / Pose.
#pragma once

#include <ode/ode.h>

#include "rheofeed/vec3.hpp"

namespace rheofeed {

inline Vec3 toVec3(const dReal* a) {
  return {a[0], a[1], a[2]};
}

/// Pose of an ODE body (ODE's dMatrix3 is 3x4 row-major with a padding column).
inline Pose poseOf(dBodyID body) {
  Pose pose;
  pose.position = toVec3(dBodyGetPosition(body));
  const dReal* r = dBodyGetRotation(body);
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) pose.rotation[row * 3 + col] = r[row * 4 + col];
  }
  return pose;
}

/// Velocity (m/s, world) of the material point of `body` at world point `p`; 0 for no body.
inline Vec3 pointVelocity(dBodyID body, const Vec3& p) {
  if (!body) return {};
  dVector3 v;
  dBodyGetPointVel(body, p.x, p.y, p.z, v);
  return toVec3(v);
}

}  // namespace rheofeed
