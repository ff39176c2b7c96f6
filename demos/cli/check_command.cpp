// SPDX-License-Identifier: MIT
// `rheofeed check SCENE`.
#include <cstdio>
#include <exception>

#include "cli/commands.hpp"
#include "rheofeed/number_format.hpp"
#include "rheofeed/simulation/check.hpp"

namespace rheofeed::cli {

using namespace rheofeed::scene;

int checkCommand(const SceneArgs& args) {
  Plan plan;
  try {
    // Without --method: the rheonomic run, and the full-vibration run when a feeder vibrates
    // (without vibration both step the same stationary scene).
    std::vector<std::string> methods = {"ode_rheonomic"};
    SceneArgs probe = args;
    plan = makePlan(probe, methods);
    if (args.methods.empty() && plan.scene.hasVibration()) {
      methods.push_back("ode_full_vibration");
      plan = makePlan(probe, methods);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rheofeed check: %s\n", e.what());
    return 2;
  }
  int hazards = 0;
  std::printf("scene %s (%s): valid\n", plan.file.string().c_str(), plan.scene.name.c_str());
  for (const PlannedRun& run : plan.runs) {
    const std::vector<Hazard> found = checkScene(run.scene, run.method);
    std::printf("%s at h = %s s (%s): %zu hazard%s\n", toString(run.method),
                formatNumber(run.scene.solver.time_step).c_str(), run.step_source.c_str(),
                found.size(), found.size() == 1 ? "" : "s");
    std::fputs(formatHazards(found, "  ").c_str(), stdout);
    hazards += static_cast<int>(found.size());
  }
  for (std::size_t i = 0; i < plan.scene.fixtures.size(); ++i) {
    const Fixture& f = plan.scene.fixtures[i];
    if (f.law.kind != FeederLaw::Kind::Vibration) continue;
    const std::string stale = staleCalibration(plan.scene, static_cast<int>(i));
    const std::string missing =
        !stale.empty() ? ", but " + stale +
                             ": `rheofeed run` calibrates it again at every launch, "
                             "`rheofeed calibrate " +
                             args.scene + " --drift-model " + toString(f.law.drift_model) +
                             " --out NEW.json` saves the new one"
        : lacksCalibration(f.law) ? ", which the scene does not give: `rheofeed run` calibrates it "
                                    "at every launch, `rheofeed calibrate " +
                                        args.scene + " --drift-model " +
                                        toString(f.law.drift_model) + " --out NEW.json` saves it"
                                  : std::string();
    std::printf("note: fixture '%s' vibrates; rheonomic runs use drift model %s%s\n",
                f.name.c_str(), toString(f.law.drift_model), missing.c_str());
    if (uncheckedCalibration(f.law)) {
      std::printf("note: %s\n", uncheckedCalibrationNote(f, args.scene).c_str());
    } else if (!missingDigests(f.law).empty()) {
      std::printf("note: %s\n", partlyCheckedCalibrationNote(f, args.scene).c_str());
    }
  }
  std::printf("%s\n",
              hazards == 0 ? "no hazards" : (std::to_string(hazards) + " hazard(s)").c_str());
  return hazards == 0 ? 0 : 1;
}

}  // namespace rheofeed::cli
