// SPDX-License-Identifier: MIT
#include "rheofeed/scene/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <stdexcept>

#include "rheofeed/scene/classical_model.hpp"
#include "rheofeed/scene/metrics.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;

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
  Scene sample = scene;
  sample.name = scene.name + "_calibration";
  sample.parts.resize(1);
  sample.parts[0].count = std::min(settings.sample_parts, scene.parts[0].count);
  sample.parts[0].rate = 0;
  sample.solver.time_step = 1.0 / (v.frequency * settings.steps_per_cycle);
  sample.duration = (settings.warmup_cycles + settings.measure_cycles) / v.frequency;
  sample.outputs.warmup = settings.warmup_cycles / v.frequency;
  sample.outputs.sample_interval = 1.0 / v.frequency;
  sample.outputs.exit_plane = false;
  const Method method =
      settings.use_reference_solver ? Method::ReferenceFullVibration : Method::OdeFullVibration;

  Calibration c;
  c.fixture = fixture;
  c.how = std::string("full-vibration sample (") +
          (settings.use_reference_solver ? "reference" : "ODE") + ", " +
          std::to_string(settings.sample_parts) + " parts)";
  const std::clock_t start = std::clock();
  const bool screw = v.torsion_amplitude != 0;
  if (screw) {  // a screw drives parts round its axis: measure the angular drift
    sample.outputs.angular_drift = true;
    sample.outputs.axis_origin = v.axis_origin;
    sample.outputs.axis_direction = v.axis_direction;
  }
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
  return scene;
}

}  // namespace rheofeed::scene
