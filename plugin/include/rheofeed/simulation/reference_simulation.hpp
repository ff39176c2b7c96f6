// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// A reference simulation whose world reports every step: for solver comparisons and problem
/// dumps from whole scenes (lastContactProblem in rheofeed/reference/contact_problem.hpp).

#include <functional>
#include <memory>

#include "rheofeed/reference/world.hpp"
#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {

/// As makeSimulation(scene, method) for a reference method (ReferenceRheonomic,
/// ReferenceFullVibration), with `observer` called by the world at the end of each of its steps
/// (reference::StepObserver). Throws std::invalid_argument for another method or an invalid
/// scene.
std::unique_ptr<Simulation> makeObservedReferenceSimulation(const Scene& scene, Method method,
                                                            reference::StepObserver observer);

/// Adjusts the reference world's settings after they were derived from the scene and before the
/// world is made (e.g. its Coulomb solver, for a solver study). An invalid adjustment makes the
/// world's constructor throw std::invalid_argument naming the setting.
using ReferenceSettingsAdjust = std::function<void(reference::Settings& settings)>;

/// As makeObservedReferenceSimulation(scene, method, observer), with the world's settings
/// passed through `adjust` (empty: none) before the world is made.
std::unique_ptr<Simulation> makeObservedReferenceSimulation(const Scene& scene, Method method,
                                                            reference::StepObserver observer,
                                                            const ReferenceSettingsAdjust& adjust);

}  // namespace rheofeed::scene
