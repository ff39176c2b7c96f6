// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// A reference simulation whose world reports every step: for solver comparisons and problem
/// dumps from whole scenes (lastContactProblem in rheofeed/reference/contact_problem.hpp).

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

}  // namespace rheofeed::scene
