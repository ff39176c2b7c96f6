// SPDX-License-Identifier: MIT
// Internal: the two engines' factories and helpers shared by them.
#pragma once

#include <memory>

#include "rheofeed/scene/simulation.hpp"

namespace rheofeed::scene {

std::unique_ptr<Simulation> makeOdeSimulation(const Scene& scene, Method method);
std::unique_ptr<Simulation> makeReferenceSimulation(const Scene& scene, Method method);

/// Throws std::runtime_error if part `index` at position `x` (m) is non-finite or beyond
/// 1e4 m: an unstable step, caught before ODE's collision asserts on it.
void checkPart(int index, const Vec3& x, Method method, double time);

/// Angular velocity (rad/s, world) that turns pose p0's rotation into p1's in h seconds.
Vec3 secantAngularVelocity(const Pose& p0, const Pose& p1, double h);

}  // namespace rheofeed::scene
