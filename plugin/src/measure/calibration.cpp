// SPDX-License-Identifier: MIT
#include "rheofeed/measure/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <sstream>
#include <stdexcept>

#include "rheofeed/measure/classical_model.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/number_format.hpp"

namespace rheofeed::scene {
namespace {

// calibrateEfficiency refuses a local drift below this fraction of the peak vibration speed:
// there the point-mass drift is near a reversal, the ratio amplifies the sample's noise and
// its sign is arbitrary.
constexpr double kMinLocalDriftFraction = 0.01;

// The sampling scene of part family `family` on vibrating fixture `fixture`: `parts` parts of
// that family alone at t = 0, a time step of 1 / (f steps_per_cycle), the drift measured over
// whole cycles after the warm-up (angular about the axis for a screw). Efficiency factors are
// dropped (the sample has one family).
Scene sampleScene(const Scene& scene, int fixture, int family, int parts, int steps_per_cycle,
                  double warmup_cycles, double measure_cycles) {
  const Vibration& v = scene.fixtures[static_cast<std::size_t>(fixture)].law.vibration;
  Scene sample = scene;
  sample.name = scene.name + "_calibration";
  sample.parts = {scene.parts[static_cast<std::size_t>(family)]};
  sample.parts[0].count = std::min(parts, sample.parts[0].count);
  sample.parts[0].rate = 0;
  // A spawn region made for parts poured one at a time (the bowl of primitives) may not hold
  // them all at t = 0: as many as it holds are sampled (the count is in the calibration's `how`).
  while (sample.parts[0].count > 1) {
    try {
      (void)drawParts(sample);
      break;
    } catch (const std::invalid_argument&) {
      --sample.parts[0].count;
    }
  }
  for (Fixture& f : sample.fixtures) f.law.efficiency.clear();
  sample.solver.time_step = 1.0 / (v.frequency * steps_per_cycle);
  sample.duration = (warmup_cycles + measure_cycles) / v.frequency;
  sample.outputs.warmup = warmup_cycles / v.frequency;
  sample.outputs.sample_interval = 1.0 / v.frequency;
  sample.outputs.exit_plane = false;
  if (v.torsion_amplitude != 0) {  // a screw drives parts round its axis: the angular drift
    sample.outputs.angular_drift = true;
    sample.outputs.axis_origin = v.axis_origin;
    sample.outputs.axis_direction = v.axis_direction;
  }
  return sample;
}

}  // namespace

Calibration calibrateBySampling(const Scene& scene, int fixture,
                                const CalibrationSettings& settings) {
  scene.validate();
  if (fixture < 0 || fixture >= static_cast<int>(scene.fixtures.size()) ||
      scene.fixtures[static_cast<std::size_t>(fixture)].law.kind != FeederLaw::Kind::Vibration) {
    throw std::invalid_argument("calibrateBySampling: fixtures[" + std::to_string(fixture) +
                                "] is not a vibrating feeder");
  }
  if (settings.sample_parts < 1 || settings.steps_per_cycle < 4 || !(settings.warmup_cycles >= 0) ||
      !(settings.measure_cycles > 0)) {
    throw std::invalid_argument(
        "calibrateBySampling: settings need sample_parts >= 1, "
        "steps_per_cycle >= 4, warmup_cycles >= 0, measure_cycles > 0");
  }
  const Vibration& v = scene.fixtures[static_cast<std::size_t>(fixture)].law.vibration;

  // The sample: the scene's first part family, a few parts at t = 0, small steps.
  const Scene sample =
      sampleScene(scene, fixture, 0, settings.sample_parts, settings.steps_per_cycle,
                  settings.warmup_cycles, settings.measure_cycles);
  const Method method =
      settings.use_reference_solver ? Method::ReferenceFullVibration : Method::OdeFullVibration;

  Calibration c;
  c.fixture = fixture;
  c.how = std::string("full-vibration sample (") +
          (settings.use_reference_solver ? "reference" : "ODE") + ", " +
          std::to_string(sample.parts[0].count) + " parts, " +
          std::to_string(settings.steps_per_cycle) + " steps per cycle, " +
          formatNumber(settings.warmup_cycles) + " cycles of warm-up, " +
          formatNumber(settings.measure_cycles) + " measured)";
  const std::clock_t start = std::clock();
  const bool screw = v.torsion_amplitude != 0;
  const RunMetrics m = measureRun(sample, method);
  c.value = m.mean_drift;
  c.ci95 = m.mean_drift_ci95;
  if (screw) {
    c.drift.angular = c.value * v.axis_direction;
    c.drift.origin = v.axis_origin;
  } else {
    c.drift.linear = c.value * scene.outputs.conveying_direction;
    const double cos_beta = dot(v.direction, scene.outputs.conveying_direction);
    const double peak = v.amplitude * 2 * kPi * v.frequency * cos_beta;
    c.efficiency = peak != 0 ? c.value / peak : 0;
  }
  c.cpu_seconds = double(std::clock() - start) / CLOCKS_PER_SEC;
  return c;
}

Calibration calibrateClassical(const Scene& scene, int fixture) {
  scene.validate();
  if (fixture < 0 || fixture >= static_cast<int>(scene.fixtures.size()) ||
      scene.fixtures[static_cast<std::size_t>(fixture)].law.kind != FeederLaw::Kind::Vibration) {
    throw std::invalid_argument("calibrateClassical: fixtures[" + std::to_string(fixture) +
                                "] is not a vibrating feeder");
  }
  const Vibration& v = scene.fixtures[static_cast<std::size_t>(fixture)].law.vibration;
  const PartSpec& parts = scene.parts[0];
  const Vec3 point = 0.5 * (parts.spawn_min + parts.spawn_max);
  const Vec3 up = (-1.0 / norm(scene.gravity)) * scene.gravity;
  const bool screw = v.torsion_amplitude != 0;
  Vec3 along = scene.outputs.conveying_direction;
  Vec3 radial;
  if (screw) {  // the track runs round the axis at the point's radius
    radial = tangentialPart(point - v.axis_origin, v.axis_direction);
    if (norm(radial) == 0) {
      throw std::invalid_argument("calibrateClassical: the spawn region's centre is on the axis");
    }
    along = cross(v.axis_direction, radial);
    along = (1.0 / norm(along)) * along;
  }
  Vec3 normal = tangentialPart(up, along);
  normal = (1.0 / norm(normal)) * normal;
  const ClassicalTrack track =
      classicalTrack(v, point, along, normal, scene.gravity, scene.material.mu);
  const std::clock_t start = std::clock();
  const ClassicalDrift drift = classicalDrift(track.params);
  Calibration c;
  c.fixture = fixture;
  c.how = "classical single-part model";
  c.method = "classical";
  const Vec3 velocity = drift.mean_speed * track.conveying_direction;
  if (screw) {
    c.value = dot(velocity, along) / norm(radial);
    c.drift.angular = c.value * v.axis_direction;
    c.drift.origin = v.axis_origin;
  } else {
    c.value = dot(velocity, scene.outputs.conveying_direction);
    c.drift.linear = c.value * scene.outputs.conveying_direction;
    c.efficiency = drift.efficiency;
  }
  c.cpu_seconds = double(std::clock() - start) / CLOCKS_PER_SEC;
  return c;
}

Scene withCalibration(Scene scene, const Calibration& calibration) {
  if (calibration.fixture < 0 || calibration.fixture >= static_cast<int>(scene.fixtures.size())) {
    throw std::invalid_argument("withCalibration: no fixture " +
                                std::to_string(calibration.fixture));
  }
  FeederLaw& law = scene.fixtures[static_cast<std::size_t>(calibration.fixture)].law;
  law.has_calibrated_drift = true;
  law.calibrated_drift = calibration.drift;
  law.drift_model = DriftModel::CalibratedDrift;
  law.efficiency.clear();
  law.calibrated_for = calibrationBasis(scene, calibration.fixture, calibration.method);
  return scene;
}

EfficiencyCalibration calibrateEfficiency(const Scene& scene, int fixture, int family,
                                          const EfficiencySettings& settings) {
  scene.validate();
  const std::string where = "calibrateEfficiency: ";
  if (fixture < 0 || fixture >= static_cast<int>(scene.fixtures.size()) ||
      scene.fixtures[static_cast<std::size_t>(fixture)].law.kind != FeederLaw::Kind::Vibration) {
    throw std::invalid_argument(where + "fixtures[" + std::to_string(fixture) +
                                "] is not a vibrating feeder");
  }
  if (family < 0 || family >= static_cast<int>(scene.parts.size())) {
    throw std::invalid_argument(where + "part family " + std::to_string(family) +
                                " is not in [0, " + std::to_string(scene.parts.size()) + ")");
  }
  if (settings.sample_parts < 1 || settings.steps_per_cycle < 4 || !(settings.warmup_cycles >= 0) ||
      !(settings.measure_cycles > 0) ||
      !(settings.rheonomic_time_step >= 1e-6 && settings.rheonomic_time_step <= 1)) {
    throw std::invalid_argument(
        where + "settings need sample_parts >= 1 (got " + std::to_string(settings.sample_parts) +
        "), steps_per_cycle >= 4 (got " + std::to_string(settings.steps_per_cycle) +
        "), warmup_cycles >= 0 (got " + formatNumber(settings.warmup_cycles) +
        "), measure_cycles > 0 (got " + formatNumber(settings.measure_cycles) +
        "), rheonomic_time_step in [1e-6, 1] s (got " + formatNumber(settings.rheonomic_time_step) +
        ")");
  }
  const Vibration& v = scene.fixtures[static_cast<std::size_t>(fixture)].law.vibration;
  const bool reference = settings.use_reference_solver;
  const Scene full =
      sampleScene(scene, fixture, family, settings.sample_parts, settings.steps_per_cycle,
                  settings.warmup_cycles, settings.measure_cycles);
  Scene local = full;  // the same sample, stationary feeders with the local law
  for (Fixture& f : local.fixtures) {
    if (f.law.kind == FeederLaw::Kind::Vibration) f.law.drift_model = DriftModel::Local;
  }
  local.solver.time_step = settings.rheonomic_time_step;
  local.outputs.sample_interval = std::max(local.outputs.sample_interval, local.solver.time_step);

  EfficiencyCalibration c;
  c.fixture = fixture;
  c.family = family;
  c.how = std::string("full vibration (") + (reference ? "reference" : "ODE") + ", " +
          std::to_string(settings.steps_per_cycle) + " steps/cycle, " +
          std::to_string(full.parts[0].count) + " parts of '" + full.parts[0].name +
          "') / local law (h = " + formatNumber(settings.rheonomic_time_step) + " s)";
  const std::clock_t start = std::clock();
  const RunMetrics sampled =
      measureRun(full, reference ? Method::ReferenceFullVibration : Method::OdeFullVibration);
  const RunMetrics law =
      measureRun(local, reference ? Method::ReferenceRheonomic : Method::OdeRheonomic);
  c.cpu_seconds = double(std::clock() - start) / CLOCKS_PER_SEC;
  c.sampled = sampled.mean_drift;
  c.sampled_ci95 = sampled.mean_drift_ci95;
  c.local = law.mean_drift;
  c.local_ci95 = law.mean_drift_ci95;

  const double w = 2 * kPi * v.frequency;
  const bool screw = v.torsion_amplitude != 0;
  const double peak = screw ? w * v.torsion_amplitude : w * v.amplitude;
  const std::string unit = screw ? " rad/s" : " m/s";
  const double floor = std::max(c.local_ci95, kMinLocalDriftFraction * peak);
  if (!(std::abs(c.local) > floor)) {
    throw std::invalid_argument(
        where + "fixtures[" + std::to_string(fixture) + "], part family '" + full.parts[0].name +
        "': the local law's drift " + formatNumber(c.local) + " +- " + formatNumber(c.local_ci95) +
        unit + " is too close to zero (must exceed " + formatNumber(floor) + unit +
        ", the larger of its 95 % half-width and 1 % of the peak vibration speed " +
        formatNumber(peak) + unit +
        ") for the ratio sampled / local (sampled: " + formatNumber(c.sampled) + unit +
        ") to mean anything; use drift_model local or calibrated_drift here");
  }
  c.efficiency = c.sampled / c.local;
  const double rs = c.sampled != 0 ? c.sampled_ci95 / c.sampled : 0;
  const double rl = c.local_ci95 / c.local;
  c.ci95 = std::abs(c.efficiency) * std::sqrt(rs * rs + rl * rl);
  if (!(c.efficiency >= 0 && c.efficiency <= kMaxPartEfficiency)) {
    throw std::invalid_argument(
        where + "fixtures[" + std::to_string(fixture) + "], part family '" + full.parts[0].name +
        "': efficiency = sampled / local = " + formatNumber(c.sampled) + " / " +
        formatNumber(c.local) + " = " + formatNumber(c.efficiency) + " must be in [0, " +
        formatNumber(kMaxPartEfficiency) +
        "] (a negative ratio: the sample and the local law drift in opposite directions)");
  }
  return c;
}

std::string driftCannotShareFactorsRecord(const Scene& scene, int fixture) {
  const FeederLaw& law = scene.fixtures.at(static_cast<std::size_t>(fixture)).law;
  if (!law.has_calibrated_drift) return "";
  if (!law.calibrated_for) return "it records no calibrated_for (given by hand, or an older file)";
  // A classical drift would also lose its own record, and be redone by sampling.
  if (law.calibrated_for->method != "sampling") {
    return "it was not measured by sampling (" +
           (law.calibrated_for->method.empty() ? std::string("method not recorded")
                                               : law.calibrated_for->method) +
           ")";
  }
  Scene as_drift = scene;
  as_drift.fixtures[static_cast<std::size_t>(fixture)].law.drift_model =
      DriftModel::CalibratedDrift;
  const std::string stale = staleCalibration(as_drift, fixture);
  const std::string prefix = "its calibrated drift was ";
  return stale.rfind(prefix, 0) == 0 ? "it was " + stale.substr(prefix.size()) : stale;
}

Scene withEfficiency(Scene scene, const EfficiencyCalibration& calibration) {
  if (calibration.fixture < 0 || calibration.fixture >= static_cast<int>(scene.fixtures.size())) {
    throw std::invalid_argument("withEfficiency: no fixture " +
                                std::to_string(calibration.fixture));
  }
  if (calibration.family < 0 || calibration.family >= static_cast<int>(scene.parts.size())) {
    throw std::invalid_argument("withEfficiency: no part family " +
                                std::to_string(calibration.family));
  }
  FeederLaw& law = scene.fixtures[static_cast<std::size_t>(calibration.fixture)].law;
  if (law.has_calibrated_drift &&
      !driftCannotShareFactorsRecord(scene, calibration.fixture).empty()) {
    law.has_calibrated_drift = false;
  }
  // The new record vouches only for what was measured under it: the other families keep their
  // digests where the old record holds one for each family and fits this feeder apart from the
  // parts (a later change of a family then shows as a different digest); otherwise (a first
  // calibration, a pre-digest record, families added or removed, another feeder) they are
  // marked not measured (""), and staleCalibration asks for them.
  CalibrationBasis next = calibrationBasis(scene, calibration.fixture, "sampling");
  bool keep = law.drift_model == DriftModel::LocalSampled && law.calibrated_for &&
              law.efficiency.size() == scene.parts.size() &&
              law.calibrated_for->part_digests.size() == next.part_digests.size();
  if (keep) {
    Scene apart_from_parts = scene;
    apart_from_parts.fixtures[static_cast<std::size_t>(calibration.fixture)]
        .law.calibrated_for->part_digests.clear();
    keep = staleCalibration(apart_from_parts, calibration.fixture).empty();
  }
  for (std::size_t j = 0; j < next.part_digests.size(); ++j) {
    if (j == static_cast<std::size_t>(calibration.family)) continue;
    next.part_digests[j] = keep ? law.calibrated_for->part_digests[j] : std::string();
  }
  law.drift_model = DriftModel::LocalSampled;
  if (law.efficiency.size() != scene.parts.size()) law.efficiency.assign(scene.parts.size(), 1.0);
  law.efficiency[static_cast<std::size_t>(calibration.family)] = calibration.efficiency;
  law.calibrated_for = next;
  return scene;
}

}  // namespace rheofeed::scene
