// SPDX-License-Identifier: MIT
// The error-vs-run-time study: does a stationary feeder with rheonomic contacts reproduce the
// transport of a really vibrating feeder, and at what cost? Used by `rheofeed study` and the
// feeder_study binary.
//
// For a scene with a vibrating feeder it
//  1. runs the converged reference: ODE full vibration at the finest step, over several seeds;
//  2. calibrates the vibration into a drift field (a short full-vibration run of a sample);
//  3. sweeps the time step of each method (ODE and reference solver, full vibration and
//     rheonomic), measuring CPU time and the error of the mean drift against the reference;
//  4. writes study.csv, study.md (table + speed-up at equal error) and study.png (log-log error
//     vs CPU time, one curve per method) into the output folder.
#pragma once

#include <string>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::demo {

/// How the study runs.
struct StudyOptions {
  std::string out_dir = "out/study";  ///< folder of study.csv, study.md, study.png
  int seeds = 3;                      ///< seeds of the converged reference (>= 1)
  bool quick = false;                 ///< coarser sweeps and a shorter reference (smoke run)
  /// > 0: also measure the real-time factor of the rheonomic ODE run of the hopper-fed linear
  /// trough (linearTroughScene) with this many parts, at h = 0.01 s.
  int rtf_parts = 0;
};

/// Runs the study of `scene` (which must have a vibrating feeder; validated here) and writes its
/// outputs; progress on stderr. Returns study.md's text. Throws std::invalid_argument for a
/// scene without a vibrating feeder or an invalid scene, std::runtime_error when the reference
/// drift is zero or a file cannot be written.
std::string runStudy(const rheofeed::scene::Scene& scene, const StudyOptions& options);

}  // namespace rheofeed::demo
