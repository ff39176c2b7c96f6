// SPDX-License-Identifier: MIT
/// @file simulation.hpp
/// A running scene, whatever the method: ODE + plugin, ODE full vibration, or the reference
/// solver in either mode. All four are built from the same Scene, spawn the same parts (same
/// seed) and report the same part states, so their results can be compared directly.
#pragma once

#include <memory>
#include <string>
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

/// What a run lost, could not trust or ignored, counted since the start (issue 7: no silent
/// failure). Every count is also reported on stderr when it first becomes non-zero and written
/// into the run's JSON and CSV outputs.
struct RunHealth {
  long steps = 0;  ///< steps taken
  /// Parts removed below Scene::removal_height after crossing the exit plane: normal flow.
  int parts_exited = 0;
  /// Parts removed below Scene::removal_height without crossing the exit plane (fell off an
  /// edge, or over a wall or rim).
  int parts_fell = 0;
  /// Parts whose centre crossed a fixture surface within one step (tunnelling: through a floor
  /// or a wall). They stay in the simulation; each part is counted once.
  int parts_through_fixture = 0;
  /// Parts removed because they left the scene bounds (far beyond the fixtures) sideways or up.
  int parts_out_of_bounds = 0;
  /// Parts whose state (position, velocity, angular velocity, orientation) became NaN or
  /// infinite; they are removed at once.
  int parts_nonfinite = 0;
  /// Parts that went faster than the scene's physical speed bound (energy blow-up); counted
  /// once each, then removed.
  int parts_too_fast = 0;
  /// Reference engine: steps whose true-Coulomb fixed point did not settle and that used the
  /// fallback (0 for ODE), and steps whose contact solve stopped at the iteration limit.
  long coulomb_fallback_steps = 0;
  long solver_unconverged_steps = 0;
  /// Settings of the scene this engine does not use (e.g. "solver.coulomb_iterations = 10:
  /// ignored by ODE"), reported once at the start.
  std::vector<std::string> ignored_settings;
  /// Parts lost in any way but the exit: fell + through_fixture + out_of_bounds + nonfinite +
  /// too_fast.
  int partsLost() const {
    return parts_fell + parts_through_fixture + parts_out_of_bounds + parts_nonfinite +
           parts_too_fast;
  }
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
  /// What the run lost, could not trust or ignored so far.
  virtual const RunHealth& health() const = 0;
};

/// Builds the scene for `method`. Throws std::invalid_argument for an invalid scene or a
/// rheonomic method on a vibrating feeder without calibrated drift.
std::unique_ptr<Simulation> makeSimulation(const Scene& scene, Method method);

}  // namespace rheofeed::scene
