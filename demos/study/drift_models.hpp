// SPDX-License-Identifier: MIT
// The drift-model comparison of the study (issue 8): on each scene, the drift error and the cost
// of the ways a rheonomic run can replace a feeder's vibration,
//   local            the local vibration law, no sampling run (vibration_drift.hpp)
//   local_sampled    the local law times the part family's own efficiency (one sampling run)
//   sampled_constant one constant drift twist from a full-vibration sampling run
//   classical        one constant drift twist from the classical single-part model
//   level_constant   (tracks) the sampled constant of the level track reused on this track
//   scene_constant   (the primitive bowl) the constant drift twist the scene file ships
// against the judge, ODE full vibration of the same scene at `reference_steps_per_cycle`. Every
// rheonomic run is ODE + plugin at h = `rheonomic_time_step`. Scenes: a single flat part on a
// track that is level, inclined by +-5 and +10 degrees, or tilted 5 degrees sideways (gravity
// turned: the same physics as a turned track), a heap in a trough, the hopper-fed trough of the
// main demo, and the bowl in its two phases (nuts on the floor, nuts on the ramp): the mesh bowl
// by time windows, the bowl of primitives by where each nut is (bowl_phases.hpp), judged by ODE
// with the friction cone, with its mean height against time (the paper's Fig. 3 metric).
#pragma once

#include <string>
#include <vector>

namespace rheofeed::demo {

struct DriftModelStudyOptions {
  std::string out_dir = "out/drift_models";
  std::string bowl_scene = "demos/scenes/bowl_feeder.json";  ///< the bowl's scene file
  /// The bowl of primitives (scene bowl_primitives; bowlFeederScene's geometry).
  std::string bowl_primitives_scene = "demos/scenes/bowl_feeder_primitives.json";
  int reference_steps_per_cycle = 1000;  ///< full-vibration judge (>= 100)
  double rheonomic_time_step = 0.01;     ///< (s)
  int seeds = 1;                         ///< seeds of the judge and of every rheonomic run
  bool quick = false;                    ///< short runs (smoke test of the study itself)
  std::vector<std::string> scenes;       ///< names to run (empty: all)
};

/// Runs the comparison and writes drift_models.{csv,md,png} into out_dir (the primitive bowl
/// also bowl_primitives_height.{csv,png}: mean height (m) against time (s) per method and model,
/// and bowl_primitives_trace_<run>.csv: every nut's centre and phase at every sample). Returns the
/// process exit code (0, or 2 with a message on stderr for bad options or a failed run).
int runDriftModelStudy(const DriftModelStudyOptions& options);

/// The scene names runDriftModelStudy knows, in the order it runs them.
std::vector<std::string> driftModelStudyScenes();

}  // namespace rheofeed::demo
