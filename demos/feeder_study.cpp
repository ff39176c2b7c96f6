// SPDX-License-Identifier: MIT
// The error-vs-run-time study: does a stationary feeder with rheonomic contacts reproduce the
// transport of a really vibrating feeder, and at what cost?
//
// The study itself is demos/common/study.cpp (also `rheofeed study SCENE`); this binary adds the
// built-in scenes of the study (track, trough, heap, hopper) that have no scene file.
//
//   feeder_study [--scene track|trough|heap|hopper|FILE.json] [--out out/study] [--seeds 3]
//   [--quick]
//                [--rtf-parts 500]
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "common/builtin_scenes.hpp"
#include "common/study.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "study/drift_models.hpp"

int main(int argc, char** argv) {
  using namespace rheofeed::scene;
  std::string scene_arg = "track";
  rheofeed::demo::StudyOptions options;
  CLI::App app{"rheofeed error-vs-run-time study: rheonomic vs full vibration"};
  app.add_option("--scene", scene_arg,
                 "built-in scene (track: one part; trough: 40 parts in a layer; heap: 40 "
                 "parts in a heap; hopper: the linear_trough scene) or a scene file (.json)")
      ->capture_default_str();
  app.add_option("--out", options.out_dir, "output folder")->capture_default_str();
  app.add_option("--seeds", options.seeds, "seeds of the converged reference")
      ->check(CLI::Range(1, 50))
      ->capture_default_str();
  app.add_flag("--quick", options.quick,
               "coarser sweeps and a shorter reference (for a smoke run)");
  app.add_option("--rtf-parts", options.rtf_parts,
                 "also measure the real-time factor of the rheonomic ODE run with this many "
                 "parts (trough scene)")
      ->capture_default_str();
  bool drift_models = false;
  rheofeed::demo::DriftModelStudyOptions dm;
  app.add_flag("--drift-models", drift_models,
               "compare the drift models (local, local + sampled efficiency, sampled constant, "
               "classical constant) against full vibration on the study's scenes; writes "
               "drift_models.{csv,md,png} into --out");
  app.add_option("--only", dm.scenes, "--drift-models: only these scenes")
      ->delimiter(',')
      ->check(CLI::IsMember(rheofeed::demo::driftModelStudyScenes()));
  app.add_option("--ref-steps-per-cycle", dm.reference_steps_per_cycle,
                 "--drift-models: steps per vibration cycle of the full-vibration judge (not for "
                 "bowl_primitives, whose judge steps with its scene file's solver.time_step, nor "
                 "for scenes with a judge step of their own: each says so on stderr)")
      ->capture_default_str()
      ->check(CLI::Range(100, 100000));
  app.add_option("--bowl-scene", dm.bowl_scene, "--drift-models: the bowl's scene file")
      ->capture_default_str();
  app.add_option("--bowl-primitives-scene", dm.bowl_primitives_scene,
                 "--drift-models: the bowl of primitives' scene file (scene bowl_primitives)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (drift_models) {
    dm.out_dir = options.out_dir;
    dm.quick = options.quick;
    return rheofeed::demo::runDriftModelStudy(dm);
  }
  try {
    const Scene scene = scene_arg == "track"    ? vibratingTrackScene()
                        : scene_arg == "trough" ? troughScene()
                        : scene_arg == "heap"   ? troughScene(40, true)
                        : scene_arg == "hopper" ? linearTroughScene()
                                                : loadScene(scene_arg);
    const std::string md = rheofeed::demo::runStudy(scene, options);
    std::printf("%s\nwrote %s/study.{csv,md,png}\n", md.c_str(), options.out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "feeder_study: %s\n", e.what());
    return 2;
  }
  return 0;
}
