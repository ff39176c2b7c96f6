// SPDX-License-Identifier: MIT
// Internal: ODE geoms from scene shapes, shared by the ODE and the reference simulations (both
// use ODE's collision module, so both must build the very same geoms).
#pragma once

#include <ode/ode.h>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// Creates the geom of `shape` in `space` (no body, identity pose). Planes use their world
/// equation. Meshes need a loaded mesh: throws std::invalid_argument (not supported here).
dGeomID createGeom(dSpaceID space, const Shape& shape);

/// Sets a placeable geom's world pose.
void setGeomPose(dGeomID geom, const Pose& pose);

}  // namespace rheofeed::scene
