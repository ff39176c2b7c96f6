// SPDX-License-Identifier: MIT
#include "cli/calibrate_scene.hpp"

#include <sstream>

#include "rheofeed/scene/calibration.hpp"

namespace rheofeed::cli {

using namespace rheofeed::scene;

bool needsCalibration(const Scene& scene) {
  for (const Fixture& f : scene.fixtures) {
    if (f.law.kind == FeederLaw::Kind::Vibration && !f.law.has_calibrated_drift) return true;
  }
  return false;
}

CalibrateReport calibrateScene(Scene& scene, const CalibrateOptions& options,
                               const std::string& label, std::FILE* log) {
  CalibrateReport report;
  for (std::size_t i = 0; i < scene.fixtures.size(); ++i) {
    const FeederLaw law = scene.fixtures[i].law;
    if (law.kind != FeederLaw::Kind::Vibration) continue;
    if (law.has_calibrated_drift && !options.force) {
      ++report.given;
      continue;
    }
    const int fixture = static_cast<int>(i);
    const std::string& name = scene.fixtures[i].name;
    std::fprintf(
        log, "%s: calibrating fixture '%s' (%s)...\n", label.c_str(), name.c_str(),
        options.classical ? "classical single-part model" : "short full-vibration sample run");
    std::fflush(log);
    const Calibration c = options.classical ? calibrateClassical(scene, fixture)
                                            : calibrateBySampling(scene, fixture);
    std::ostringstream line;
    line << "fixture '" << name << "': ";
    if (law.vibration.torsion_amplitude > 0) {
      line << "angular drift " << c.value << " +- " << c.ci95 << " rad/s";
    } else {
      line << "drift " << c.value << " +- " << c.ci95 << " m/s (efficiency " << c.efficiency << ")";
    }
    line << ", " << c.how << ", " << c.cpu_seconds << " s CPU";
    std::fprintf(log, "%s: %s\n", label.c_str(), line.str().c_str());
    report.summary += line.str() + "\n";
    report.cpu_seconds += c.cpu_seconds;
    ++report.calibrated;
    scene = withCalibration(scene, c);
  }
  return report;
}

}  // namespace rheofeed::cli
