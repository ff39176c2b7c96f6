// SPDX-License-Identifier: MIT
/// @file compare.hpp
/// Runs one scene with two methods and compares their end states part by part.
#pragma once

#include <string>
#include <vector>

#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {

/// End state of one run, averaged where noted.
struct RunSummary {
  Method method;
  int parts = 0;
  Vec3 mean_velocity;             ///< mean over parts at the end (m/s)
  Vec3 mean_position;             ///< mean over parts at the end (m)
  double mean_angular_speed = 0;  ///< mean |w| over parts at the end (rad/s)
  /// Normal impulse from fixtures on parts per step, averaged over the last
  /// `impulse_window` steps (N s).
  double normal_impulse = 0;
  Vec3 impulse;                   ///< same, full impulse vector (N s, world)
  std::vector<PartState> states;  ///< end state of every part
  double cpu_seconds = 0;
};

/// Differences between two runs of the same scene.
struct Comparison {
  std::string scene;
  RunSummary a, b;
  double max_velocity_difference = 0;    ///< max over parts of |v_a - v_b| (m/s)
  double max_position_difference = 0;    ///< max over parts of |x_a - x_b| (m)
  double mean_velocity_difference = 0;   ///< |mean v_a - mean v_b| (m/s)
  double normal_impulse_difference = 0;  ///< |J_a - J_b| / max(J_a, J_b) (relative)
};

/// Runs `scene` for its duration with `method` (progress on stderr when `progress`).
RunSummary runScene(const Scene& scene, Method method, int impulse_window = 50);

/// Runs both methods and compares them.
Comparison compare(const Scene& scene, Method a, Method b, int impulse_window = 50);

}  // namespace rheofeed::scene
