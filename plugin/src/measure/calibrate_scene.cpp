// SPDX-License-Identifier: MIT
// Calibrating what a scene's rheonomic runs need (calibration.hpp: calibrateScene), shared by
// `rheofeed run` (calibrates what the scene does not give, every launch) and `rheofeed
// calibrate` (calibrates once and writes the result into a copy of the scene).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "rheofeed/measure/calibration.hpp"
#include "rheofeed/number_format.hpp"

namespace rheofeed::scene {

namespace {

// The message of CalibrateReport::imprecise for a calibration of `what` = value +- ci95 (95 %),
// or "" when it is precise enough. A sampling run's interval narrows about as one over the
// square root of the cycles it measures where the parts' own fluctuation limits it (not where a
// few sampled parts differ for good, e.g. nuts lying flat and on edge).
std::string imprecision(const std::string& what, double value, double ci95,
                        const CalibrateOptions& options) {
  std::ostringstream m;
  if (ci95 == 0) {  // statistics.hpp: no interval over fewer than two measured parts
    m << what << " has no 95 % interval (fewer than two sampled parts were measured): how far "
      << "it can be trusted is unknown";
    return m.str();
  }
  if (value == 0) {
    m << what << " is 0: its interval is not a fraction of it, and the runs that use it carry "
      << "all of that uncertainty";
    return m.str();
  }
  const double relative = std::abs(ci95 / value);
  if (!(relative > kImpreciseCalibration)) return "";
  m << what << " is known to +-" << std::lround(std::min(100 * relative, 1e6))
    << " % (95 %), above " << std::lround(100 * kImpreciseCalibration)
    << " %: the runs that use it carry that uncertainty; more measured cycles narrow it "
       "(--measure-cycles, CalibrateOptions::measure_cycles: "
    << formatNumber(options.measure_cycles)
    << " now; four times as many about halve it where the parts' motion over time, not the "
       "few parts sampled, limits it)";
  return m.str();
}

}  // namespace

CalibrateReport calibrateScene(Scene& scene, const CalibrateOptions& options,
                               const std::string& label, std::FILE* log) {
  CalibrateReport report;
  const auto note_imprecision = [&](const std::string& message) {
    if (message.empty()) return;
    std::fprintf(log, "%s: warning: %s\n", label.c_str(), message.c_str());
    report.imprecise.push_back(message);
  };
  for (std::size_t i = 0; i < scene.fixtures.size(); ++i) {
    const FeederLaw law = scene.fixtures[i].law;
    if (law.kind != FeederLaw::Kind::Vibration) continue;
    const int fixture = static_cast<int>(i);
    const std::string& name = scene.fixtures[i].name;
    if (law.drift_model == DriftModel::Local) {
      std::fprintf(log,
                   "%s: fixture '%s': drift model local (the local vibration law), nothing "
                   "to calibrate\n",
                   label.c_str(), name.c_str());
      ++report.local;
      continue;
    }
    const std::string stale = staleCalibration(scene, fixture);
    if (!stale.empty()) {
      const std::string message = "fixture '" + name + "': " + stale;
      std::fprintf(log, "%s: warning: %s; calibrating it again\n", label.c_str(), message.c_str());
      report.stale.push_back(message);
    } else if (!lacksCalibration(scene.fixtures[i].law) && !options.force) {
      std::fprintf(log, "%s: fixture '%s': drift model %s, given by the scene\n", label.c_str(),
                   name.c_str(), toString(law.drift_model));
      ++report.given;
      continue;
    }
    std::ostringstream line;
    if (law.drift_model == DriftModel::CalibratedDrift) {
      // A stale drift from the classical model is redone by it, as the scene was calibrated.
      const bool as_before =
          !options.classical && !stale.empty() && law.calibrated_for->method == "classical";
      const bool classical = options.classical || as_before;
      std::fprintf(log, "%s: calibrating fixture '%s' (drift model calibrated_drift, %s%s)...\n",
                   label.c_str(), name.c_str(),
                   classical ? "classical single-part model" : "short full-vibration sample run",
                   as_before ? ", as the scene's stale drift was" : "");
      std::fflush(log);
      CalibrationSettings sampling;
      sampling.warmup_cycles = options.warmup_cycles;
      sampling.measure_cycles = options.measure_cycles;
      const Calibration c = classical ? calibrateClassical(scene, fixture)
                                      : calibrateBySampling(scene, fixture, sampling);
      line << "fixture '" << name << "': calibrated_drift ";
      if (law.vibration.torsion_amplitude > 0) {
        line << c.value << " +- " << c.ci95 << " rad/s";
      } else {
        line << c.value << " +- " << c.ci95 << " m/s (efficiency " << c.efficiency << ")";
      }
      line << ", " << c.how << ", " << c.cpu_seconds << " s CPU";
      report.cpu_seconds += c.cpu_seconds;
      if (!classical) {  // the classical model has no sampling interval to widen
        note_imprecision(imprecision("fixture '" + name + "': the calibrated drift " +
                                         formatNumber(c.value) + " +- " + formatNumber(c.ci95),
                                     c.value, c.ci95, options));
      }
      scene = withCalibration(scene, c);
    } else {  // local_sampled: each part family's own efficiency under the local law
      if (options.classical) {
        throw std::invalid_argument(
            "--classical: fixture '" + name +
            "' has drift model local_sampled, whose efficiency only a sampling run measures; "
            "drop --classical or use --drift-model calibrated_drift");
      }
      EfficiencySettings settings;
      settings.rheonomic_time_step = options.rheonomic_time_step;
      settings.warmup_cycles = options.warmup_cycles;
      settings.measure_cycles = options.measure_cycles;
      Scene sampled = scene;
      sampled.fixtures[i].law.efficiency.clear();
      const std::vector<std::string> families = familyKeys(scene.parts);  // "name[k]" if repeated
      for (std::size_t k = 0; k < scene.parts.size(); ++k) {
        std::fprintf(log,
                     "%s: calibrating fixture '%s', part family '%s' (drift model "
                     "local_sampled: full-vibration sample at %d steps per cycle against the "
                     "local law at h = %g s)...\n",
                     label.c_str(), name.c_str(), families[k].c_str(), settings.steps_per_cycle,
                     settings.rheonomic_time_step);
        std::fflush(log);
        const EfficiencyCalibration c =
            calibrateEfficiency(sampled, fixture, static_cast<int>(k), settings);
        line << (k ? "; " : "") << "fixture '" << name << "', family '" << families[k]
             << "': efficiency " << c.efficiency << " +- " << c.ci95 << " (" << c.how << ", "
             << c.cpu_seconds << " s CPU)";
        report.cpu_seconds += c.cpu_seconds;
        note_imprecision(imprecision("fixture '" + name + "', part family '" + families[k] +
                                         "': the efficiency " + formatNumber(c.efficiency) +
                                         " +- " + formatNumber(c.ci95),
                                     c.efficiency, c.ci95, options));
        sampled = withEfficiency(sampled, c);
      }
      if (law.has_calibrated_drift && !sampled.fixtures[i].law.has_calibrated_drift) {
        // withEfficiency: one calibrated_for serves both; a drift not known to fit this
        // feeder would pass for one
        const std::string why = driftCannotShareFactorsRecord(scene, fixture);
        std::fprintf(log,
                     "%s: fixture '%s': its calibrated drift is dropped (the efficiency factors' "
                     "calibrated_for, which it would share, cannot vouch for it): %s\n",
                     label.c_str(), name.c_str(), why.c_str());
      }
      scene = sampled;
    }
    std::fprintf(log, "%s: %s\n", label.c_str(), line.str().c_str());
    report.summary += line.str() + "\n";
    ++report.calibrated;
  }
  return report;
}

}  // namespace rheofeed::scene
