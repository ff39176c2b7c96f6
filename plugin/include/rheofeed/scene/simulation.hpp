// SPDX-License-Identifier: MIT
/// @file simulation.hpp
/// A running scene, whatever the method: ODE + plugin, ODE full vibration, or the reference
/// solver in either mode. All four are built from the same Scene, spawn the same parts (same
/// seed) and report the same part states, so their results can be compared directly.
#pragma once

#include <memory>
#include <vector>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// State of one part (world frame).
struct PartState {
  Vec3 position;                                     ///< centre of mass (m)
  Vec3 velocity;                                     ///< (m/s)
  Vec3 angular_velocity;                             ///< (rad/s)
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< body to world, row-major
  /// False once the part fell below Scene::removal_height and was taken out of the simulation
  /// (its state is then frozen where it was removed).
  bool active = true;
};

/// Contact totals of the last step: sums over all contacts.
struct ContactTotals {
  int count = 0;
  double normal_impulse = 0;  ///< sum of normal impulses (N s)
  Vec3 impulse;               ///< sum of impulse vectors on the first geom's body (N s, world)
};

class Simulation {
 public:
  virtual ~Simulation() = default;
  /// Advance one time step of scene.solver.time_step (s), spawning the parts that are due and
  /// removing those below Scene::removal_height. Throws std::runtime_error naming the part if
  /// a part's state becomes non-finite or flies out of the scene (|x| > 1e4 m), which only an
  /// unstable step causes, before the collision engine sees it.
  virtual void step() = 0;
  /// Simulated time (s).
  virtual double time() const = 0;
  /// Parts spawned so far.
  virtual int numParts() const = 0;
  virtual PartState part(int index) const = 0;
  /// Mass of a part (kg).
  virtual double partMass(int index) const = 0;
  /// Contact totals of the last step (impulses of the contacts touching parts).
  virtual ContactTotals contactTotals() const = 0;
  virtual Method method() const = 0;
};

/// Builds the scene for `method`. Throws std::invalid_argument for an invalid scene or a
/// rheonomic method on a vibrating feeder without calibrated drift.
std::unique_ptr<Simulation> makeSimulation(const Scene& scene, Method method);

}  // namespace rheofeed::scene
