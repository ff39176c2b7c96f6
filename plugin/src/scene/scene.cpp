// SPDX-License-Identifier: MIT
#include "rheofeed/scene/scene.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "rheofeed/number_format.hpp"
#include "rheofeed/scene/mesh.hpp"
#include "scene_limits.hpp"

namespace rheofeed::scene {
namespace {

// Truncated normal sizes are redrawn this many times before the value is clamped.
constexpr int kRedraws = 100;
// Attempts to place a part spawned at t = 0 without overlapping earlier ones.
constexpr int kPlacementTries = 200;

[[noreturn]] void bad(const std::string& path, double value, const std::string& why) {
  std::ostringstream out;
  out << path << " = " << value << ": " << why;
  throw std::invalid_argument(out.str());
}
// An integer setting (a count) in full: 1000000, not 1e+06.
[[noreturn]] void bad(const std::string& path, int value, const std::string& why) {
  throw std::invalid_argument(path + " = " + std::to_string(value) + ": " + why);
}

std::string show(double v) {
  return formatNumber(v);
}

void positive(const std::string& path, double v) {
  if (!std::isfinite(v) || !(v > 0)) bad(path, v, "must be a finite number > 0");
}
void nonNegative(const std::string& path, double v) {
  if (!std::isfinite(v) || !(v >= 0)) bad(path, v, "must be a finite number >= 0");
}
// v in [lo, hi] (unit for the message, e.g. "m"); `why` says where the limit comes from.
void within(const std::string& path, double v, double lo, double hi, const std::string& unit,
            const std::string& why = "") {
  if (std::isfinite(v) && v >= lo && v <= hi) return;
  bad(path, v,
      "must be a finite number in [" + show(lo) + ", " + show(hi) + "]" +
          (unit.empty() ? "" : " " + unit) + (why.empty() ? "" : " (" + why + ")"));
}
void finite(const std::string& path, double v) {
  if (!std::isfinite(v)) bad(path, v, "must be finite");
}
void finite(const std::string& path, const Vec3& v) {
  finite(path + ".x", v.x);
  finite(path + ".y", v.y);
  finite(path + ".z", v.z);
}
void unit(const std::string& path, const Vec3& v) {
  finite(path, v);
  if (std::abs(norm(v) - 1.0) > 1e-6) bad(path + " length", norm(v), "must be a unit vector");
}
// A coordinate (m) within ODE's representable world.
void coordinate(const std::string& path, double v) {
  within(path, v, -limits::kMaxCoordinate, limits::kMaxCoordinate, "m",
         "positions beyond this break ODE's hash space");
}
void position(const std::string& path, const Vec3& v) {
  coordinate(path + ".x", v.x);
  coordinate(path + ".y", v.y);
  coordinate(path + ".z", v.z);
}
void size(const std::string& path, double v) {
  within(path, v, limits::kMinSize, limits::kMaxSize, "m",
         "mass and inertia must stay representable");
}
// |v| of a vector of finite components, with `what` naming the bound ("m/s").
void magnitude(const std::string& path, const Vec3& v, double max, const std::string& unit) {
  finite(path, v);
  // |v| scaled by its largest component, so that a magnitude beyond sqrt(DBL_MAX) (1e300) is
  // computed as a number, not as inf.
  const double big = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  const double n = big > 0 ? big * norm((1.0 / big) * v) : 0.0;
  if (!(n <= max)) {
    bad(path + " magnitude", n, "must be <= " + show(max) + " " + unit);
  }
}

void validateShape(const std::string& path, const Shape& s, bool static_geom) {
  switch (s.kind) {
    case Shape::Kind::Box:
      size(path + ".size.x", s.size.x);
      size(path + ".size.y", s.size.y);
      size(path + ".size.z", s.size.z);
      break;
    case Shape::Kind::Sphere:
      size(path + ".radius", s.radius);
      break;
    case Shape::Kind::Cylinder:
    case Shape::Kind::Capsule:
      size(path + ".radius", s.radius);
      size(path + ".length", s.length);
      break;
    case Shape::Kind::Plane:
      if (!static_geom) throw std::invalid_argument(path + ".shape: a plane can only be static");
      unit(path + ".normal", s.plane_normal);
      coordinate(path + ".offset", s.plane_offset);
      break;
    case Shape::Kind::Mesh:
      if (s.mesh.empty()) throw std::invalid_argument(path + ".mesh: empty file name");
      // The scaled mesh's extent is checked against the size limits when it is loaded.
      positive(path + ".scale", s.mesh_scale);
      break;
  }
}

void validateTwist(const std::string& path, const Twist& t) {
  magnitude(path + ".linear", t.linear, limits::kMaxSpeed, "m/s");
  magnitude(path + ".angular", t.angular, limits::kMaxAngularSpeed, "rad/s");
  position(path + ".origin", t.origin);
}

// A size distribution; `lo` and `hi` bound the mean (the size limits, or the scale of a mesh).
void validateDistribution(const std::string& path, const Distribution& d, bool mesh_scale) {
  if (mesh_scale) {
    positive(path + ".mean", d.mean);  // the scaled extent is checked when the mesh is loaded
  } else {
    size(path + ".mean", d.mean);
  }
  nonNegative(path + ".stddev", d.stddev);
  if (!mesh_scale && d.stddev > limits::kMaxSize) {
    bad(path + ".stddev", d.stddev, "must be <= " + show(limits::kMaxSize) + " m");
  }
  nonNegative(path + ".min", d.min);
  if (std::isnan(d.max) || !(d.max >= d.min)) {
    bad(path + ".max", d.max, "must be >= min (" + show(d.min) + ")");
  }
  if (!(d.mean >= d.min && d.mean <= d.max)) {
    bad(path + ".mean", d.mean,
        "must lie in [min, max] = [" + show(d.min) + ", " + show(d.max) + "]");
  }
}

// Whether a vibrating feeder's rheonomic law is the local law.
bool usesLocalLaw(const FeederLaw& law) {
  return law.kind == FeederLaw::Kind::Vibration && law.drift_model != DriftModel::CalibratedDrift;
}

// The factor of each part family on the local-law feeders (1 where none is given); throws
// naming both fixtures when two of them disagree (FeederSet's factor is per body).
std::vector<double> localEfficiencies(const std::vector<Fixture>& fixtures, std::size_t families,
                                      const std::vector<PartSpec>& parts) {
  std::vector<double> factor(families, 1.0);
  std::vector<int> from(families, -1);  // the fixture that set factor[k]
  for (std::size_t i = 0; i < fixtures.size(); ++i) {
    const FeederLaw& law = fixtures[i].law;
    if (!usesLocalLaw(law)) continue;
    for (std::size_t k = 0; k < families; ++k) {
      const double e = k < law.efficiency.size() ? law.efficiency[k] : 1.0;
      if (from[k] >= 0 && e != factor[k]) {
        std::ostringstream out;
        out << "fixtures[" << i << "].law.efficiency[" << k << "] = " << e << ": part family '"
            << parts[k].name << "' has factor " << factor[k] << " on fixtures[" << from[k]
            << "] (a local feeder without factors counts as 1); a part's efficiency applies to "
               "all its contacts with local-law feeders (FeederSet::setPartEfficiency is per "
               "body), so the local feeders of a scene must agree on each family's factor";
        throw std::invalid_argument(out.str());
      }
      factor[k] = e;
      from[k] = static_cast<int>(i);
    }
  }
  return factor;
}

}  // namespace

const char* toString(DriftModel model) {
  switch (model) {
    case DriftModel::Local:
      return "local";
    case DriftModel::LocalSampled:
      return "local_sampled";
    case DriftModel::CalibratedDrift:
      return "calibrated_drift";
  }
  return "?";
}

bool parseDriftModel(const std::string& name, DriftModel& model) {
  for (DriftModel m : {DriftModel::Local, DriftModel::LocalSampled, DriftModel::CalibratedDrift}) {
    if (name == toString(m)) {
      model = m;
      return true;
    }
  }
  return false;
}

const char* toString(Shape::Kind kind) {
  switch (kind) {
    case Shape::Kind::Box:
      return "box";
    case Shape::Kind::Sphere:
      return "sphere";
    case Shape::Kind::Cylinder:
      return "cylinder";
    case Shape::Kind::Capsule:
      return "capsule";
    case Shape::Kind::Plane:
      return "plane";
    case Shape::Kind::Mesh:
      return "mesh";
  }
  return "unknown";
}

int partSizeCount(Shape::Kind kind) {
  switch (kind) {
    case Shape::Kind::Box:
      return 3;
    case Shape::Kind::Cylinder:
    case Shape::Kind::Capsule:
      return 2;
    default:
      return 1;
  }
}

const char* toString(Method method) {
  switch (method) {
    case Method::OdeRheonomic:
      return "ode_rheonomic";
    case Method::OdeFullVibration:
      return "ode_full_vibration";
    case Method::ReferenceRheonomic:
      return "reference_rheonomic";
    case Method::ReferenceFullVibration:
      return "reference_full_vibration";
  }
  return "unknown";
}

bool isFullVibration(Method method) {
  return method == Method::OdeFullVibration || method == Method::ReferenceFullVibration;
}

Pose Vibration::displacement(double t) const {
  const double s = std::sin(2 * kPi * frequency * t + phase);
  Pose pose;
  const Vec3 shift = (amplitude * s) * direction;
  if (torsion_amplitude == 0) {
    pose.position = shift;
    return pose;
  }
  // Rotation by theta about axis_direction, about the point axis_origin.
  pose = Pose::axisAngle(axis_direction, torsion_amplitude * s);
  pose.position = axis_origin - pose.rotate(axis_origin) + shift;
  return pose;
}

void Scene::validate() const {
  magnitude("gravity", gravity, limits::kMaxGravity, "m/s^2");
  within("solver.time_step", solver.time_step, limits::kMinTimeStep, limits::kMaxTimeStep, "s");
  positive("duration", duration);
  if (duration < solver.time_step) {
    bad("duration", duration,
        "must be >= solver.time_step (" + show(solver.time_step) +
            " s): the run would take no step");
  }
  if (const double steps = duration / solver.time_step; !(steps <= limits::kMaxSteps)) {
    bad("duration", duration,
        "with solver.time_step = " + show(solver.time_step) + " s would take " + show(steps) +
            " steps; at most " + show(limits::kMaxSteps) + " steps are allowed");
  }
  if (solver.rheonomic_time_step != 0) {
    within("solver.rheonomic_time_step", solver.rheonomic_time_step, limits::kMinTimeStep,
           limits::kMaxTimeStep, "s");
    if (const double steps = duration / solver.rheonomic_time_step; !(steps <= limits::kMaxSteps)) {
      bad("duration", duration,
          "with solver.rheonomic_time_step = " + show(solver.rheonomic_time_step) +
              " s would take " + show(steps) + " steps; at most " + show(limits::kMaxSteps) +
              " steps are allowed");
    }
  }
  if (solver.iterations < 1 || solver.iterations > limits::kMaxIterations) {
    bad("solver.iterations", solver.iterations,
        "must be in [1, " + std::to_string(limits::kMaxIterations) + "]");
  }
  if (!(solver.erp >= 0 && solver.erp <= 1)) bad("solver.erp", solver.erp, "must be in [0, 1]");
  if (solver.friction == FrictionModel::Cone && !solver.ode_quickstep) {
    throw std::invalid_argument(
        "solver.friction = \"cone\" needs solver.ode_quickstep = true: dWorldStep (the Dantzig "
        "LCP) cannot express a friction cone; use \"pyramid\" or quickstep");
  }
  nonNegative("solver.cfm", solver.cfm);
  positive("solver.max_correcting_velocity", solver.max_correcting_velocity);
  within("solver.max_correcting_velocity", solver.max_correcting_velocity, 0, limits::kMaxSpeed,
         "m/s");
  within("solver.surface_layer", solver.surface_layer, 0, limits::kMaxSize, "m");
  coordinate("removal_height", removal_height);
  if (solver.coulomb_iterations < 0 || solver.coulomb_iterations > limits::kMaxIterations) {
    bad("solver.coulomb_iterations", solver.coulomb_iterations,
        "must be in [0, " + std::to_string(limits::kMaxIterations) + "]");
  }
  positive("solver.tolerance", solver.tolerance);
  within("material.mu", material.mu, 0, limits::kMaxMu, "");
  if (!(material.restitution >= 0 && material.restitution <= 1)) {
    bad("material.restitution", material.restitution, "must be in [0, 1]");
  }
  unit("outputs.conveying_direction", outputs.conveying_direction);
  positive("outputs.sample_interval", outputs.sample_interval);
  if (outputs.sample_interval < solver.time_step) {
    bad("outputs.sample_interval", outputs.sample_interval,
        "must be >= solver.time_step (" + show(solver.time_step) +
            " s): a run samples at most once per step");
  }
  if (outputs.sample_interval > duration) {
    bad("outputs.sample_interval", outputs.sample_interval,
        "must be <= duration (" + show(duration) + " s): the run would take no sample");
  }
  nonNegative("outputs.warmup", outputs.warmup);
  if (outputs.warmup > duration - solver.time_step) {
    bad("outputs.warmup", outputs.warmup,
        "must be <= duration - solver.time_step (" + show(duration - solver.time_step) +
            " s): no drift would be measured after it");
  }
  if (outputs.angular_drift) {
    position("outputs.axis_origin", outputs.axis_origin);
    unit("outputs.axis_direction", outputs.axis_direction);
  }
  if (outputs.exit_plane) {
    position("outputs.exit_point", outputs.exit_point);
    unit("outputs.exit_normal", outputs.exit_normal);
  }
  long geoms = 0;
  for (std::size_t i = 0; i < fixtures.size(); ++i) {
    const Fixture& f = fixtures[i];
    const std::string path = "fixtures[" + std::to_string(i) + "]";
    if (f.geoms.empty()) throw std::invalid_argument(path + ".geoms: a fixture needs a geom");
    geoms += static_cast<long>(f.geoms.size());
    if (geoms > limits::kMaxGeoms) {
      throw std::invalid_argument(
          path + ".geoms: " + std::to_string(geoms) + " fixture geoms up to this fixture; a " +
          "scene holds at most " + std::to_string(limits::kMaxGeoms) +
          " geoms (fixture geoms plus parts: ODE's hash space keeps an n x n bit matrix on the "
          "stack)");
    }
    for (std::size_t g = 0; g < f.geoms.size(); ++g) {
      const std::string gp = path + ".geoms[" + std::to_string(g) + "]";
      validateShape(gp, f.geoms[g].shape, true);
      position(gp + ".position", f.geoms[g].pose.position);
      if (f.geoms[g].shape.kind == Shape::Kind::Plane && f.law.kind == FeederLaw::Kind::Vibration) {
        throw std::invalid_argument(gp + ".shape: a plane cannot vibrate (use a box)");
      }
    }
    const FeederLaw& law = f.law;
    switch (law.kind) {
      case FeederLaw::Kind::None:
        break;
      case FeederLaw::Kind::Drift:
        validateTwist(path + ".law.drift", law.drift);
        break;
      case FeederLaw::Kind::Belt:
        unit(path + ".law.belt.direction", law.belt_direction);
        within(path + ".law.belt.speed", law.belt_speed, -limits::kMaxSpeed, limits::kMaxSpeed,
               "m/s");
        break;
      case FeederLaw::Kind::Vibration: {
        const Vibration& v = law.vibration;
        const std::string vp = path + ".law.vibration";
        within(vp + ".amplitude", v.amplitude, 0, limits::kMaxSize, "m");
        positive(vp + ".frequency", v.frequency);
        within(vp + ".frequency", v.frequency, 0, limits::kMaxFrequency, "Hz");
        unit(vp + ".direction", v.direction);
        within(vp + ".phase", v.phase, -limits::kMaxAngle, limits::kMaxAngle, "rad",
               "1e6 degrees: beyond, a double no longer resolves the angle to a degree's 1e-10");
        within(vp + ".torsion_amplitude", v.torsion_amplitude, 0, limits::kMaxTorsion, "rad");
        position(vp + ".axis_origin", v.axis_origin);
        unit(vp + ".axis_direction", v.axis_direction);
        if (v.isZero()) bad(vp + ".amplitude", 0, "a vibration needs an amplitude");
        const double omega = 2 * kPi * v.frequency;
        if (omega * v.amplitude > limits::kMaxSpeed) {
          bad(vp + ".amplitude", v.amplitude,
              "peak speed 2 pi frequency amplitude = " + show(omega * v.amplitude) +
                  " m/s must be <= " + show(limits::kMaxSpeed) + " m/s");
        }
        if (omega * v.torsion_amplitude > limits::kMaxAngularSpeed) {
          bad(vp + ".torsion_amplitude", v.torsion_amplitude,
              "peak angular speed 2 pi frequency torsion_amplitude = " +
                  show(omega * v.torsion_amplitude) +
                  " rad/s must be <= " + show(limits::kMaxAngularSpeed) + " rad/s");
        }
        if (law.has_calibrated_drift)
          validateTwist(path + ".law.calibrated_drift", law.calibrated_drift);
        if (!law.efficiency.empty()) {
          const std::string ep = path + ".law.efficiency";
          if (law.drift_model != DriftModel::LocalSampled) {
            throw std::invalid_argument(ep +
                                        ": efficiency factors apply to drift_model "
                                        "local_sampled only; this feeder's drift_model is " +
                                        toString(law.drift_model));
          }
          if (law.efficiency.size() != parts.size()) {
            bad(ep + " size", static_cast<double>(law.efficiency.size()),
                "must equal the number of part families (" + std::to_string(parts.size()) +
                    "): one factor per family, in the order of parts");
          }
          for (std::size_t k = 0; k < law.efficiency.size(); ++k) {
            within(ep + "[" + std::to_string(k) + "]", law.efficiency[k], 0, kMaxPartEfficiency, "",
                   "a part family's own efficiency under the local law, 1 = a point mass");
          }
        }
        break;
      }
    }
    if (law.kind != FeederLaw::Kind::Vibration && !law.efficiency.empty()) {
      throw std::invalid_argument(path +
                                  ".law.efficiency: only a vibrating feeder has efficiency "
                                  "factors");
    }
  }
  if (parts.empty()) throw std::invalid_argument("parts: a scene needs at least one part family");
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const PartSpec& p = parts[i];
    const std::string path = "parts[" + std::to_string(i) + "]";
    const int dims = partSizeCount(p.shape);
    if (p.shape == Shape::Kind::Plane)
      throw std::invalid_argument(path + ".shape: a part cannot be a plane");
    if (p.shape == Shape::Kind::Mesh && p.mesh.empty())
      throw std::invalid_argument(path + ".mesh: empty file name");
    if (p.shape != Shape::Kind::Mesh && p.collision != PartSpec::Collision::Mesh) {
      throw std::invalid_argument(path +
                                  ".collision: only mesh parts collide as their convex "
                                  "hull (a " +
                                  toString(p.shape) + " part collides as itself)");
    }
    for (int d = 0; d < dims; ++d) {
      validateDistribution(path + ".size[" + std::to_string(d) + "]", p.size[d],
                           p.shape == Shape::Kind::Mesh);
    }
    within(path + ".density", p.density, limits::kMinDensity, limits::kMaxDensity, "kg/m^3");
    position(path + ".spawn_min", p.spawn_min);
    position(path + ".spawn_max", p.spawn_max);
    const double lo[3] = {p.spawn_min.x, p.spawn_min.y, p.spawn_min.z};
    const double hi[3] = {p.spawn_max.x, p.spawn_max.y, p.spawn_max.z};
    for (int k = 0; k < 3; ++k) {
      if (hi[k] < lo[k]) {
        bad(path + ".spawn_max." + "xyz"[k], hi[k],
            "must be >= spawn_min." + std::string(1, "xyz"[k]) + " (" + show(lo[k]) + ")");
      }
    }
    if (p.count < 1 || p.count > limits::kMaxGeoms) {
      bad(path + ".count", p.count, "must be in [1, " + std::to_string(limits::kMaxGeoms) + "]");
    }
    geoms += p.count;
    if (geoms > limits::kMaxGeoms) {
      bad(path + ".count", p.count,
          "brings the scene to " + std::to_string(geoms) +
              " geoms (fixture geoms plus parts); "
              "at most " +
              std::to_string(limits::kMaxGeoms) +
              " are allowed (ODE's hash space keeps an n x n bit matrix on the stack)");
    }
    nonNegative(path + ".rate", p.rate);
    magnitude(path + ".initial_velocity", p.initial_velocity, limits::kMaxSpeed, "m/s");
  }
  double highest_spawn = -HUGE_VAL;  // removal_height is a world z (simulation.hpp)
  for (const PartSpec& p : parts) highest_spawn = std::max(highest_spawn, p.spawn_max.z);
  if (highest_spawn < removal_height) {
    bad("removal_height", removal_height,
        "is above every spawn point (the highest, parts[].spawn_max.z, is at z = " +
            show(highest_spawn) +
            " m): every part would be removed as it spawns and nothing would be simulated");
  }
  (void)localEfficiencies(fixtures, parts.size(), parts);  // local feeders agree per family
}

bool Scene::hasMeshes() const {
  for (const Fixture& f : fixtures) {
    for (const Fixture::Geom& g : f.geoms) {
      if (g.shape.kind == Shape::Kind::Mesh) return true;
    }
  }
  for (const PartSpec& p : parts) {
    if (p.shape == Shape::Kind::Mesh) return true;
  }
  return false;
}

bool Scene::hasVibration() const {
  for (const Fixture& f : fixtures) {
    if (f.law.kind == FeederLaw::Kind::Vibration) return true;
  }
  return false;
}

LocalVibration localVibration(const Vibration& vibration, const Vec3& gravity, double mu) {
  LocalVibration v;
  v.frequency = vibration.frequency;
  v.amplitude = vibration.amplitude * vibration.direction;
  v.torsion_amplitude = vibration.torsion_amplitude;
  v.axis_origin = vibration.axis_origin;
  v.axis_direction = vibration.axis_direction;
  v.gravity = gravity;
  v.efficiency = 1;
  v.mu = mu;
  return v;
}

MotionLaw rheonomicLaw(const Scene& scene, int fixture) {
  if (fixture < 0 || fixture >= static_cast<int>(scene.fixtures.size())) {
    throw std::invalid_argument("rheonomicLaw: fixture index " + std::to_string(fixture) +
                                " is not in [0, " + std::to_string(scene.fixtures.size()) + ")");
  }
  const Fixture& f = scene.fixtures[static_cast<std::size_t>(fixture)];
  const FeederLaw& law = f.law;
  const std::string where = "fixtures[" + std::to_string(fixture) + "] ('" + f.name + "')";
  if (const std::string stale = staleCalibration(scene, fixture); !stale.empty()) {
    throw std::invalid_argument(where + ": " + stale +
                                " (calibrate again: `rheofeed calibrate`, calibrateScene; or use "
                                "drift_model local)");
  }
  switch (law.kind) {
    case FeederLaw::Kind::None:
      return MotionLaw{};
    case FeederLaw::Kind::Drift:
      return MotionLaw::twist(law.drift);
    case FeederLaw::Kind::Belt:
      return MotionLaw::belt(law.belt_direction, law.belt_speed);
    case FeederLaw::Kind::Vibration:
      switch (law.drift_model) {
        case DriftModel::CalibratedDrift:
          if (lacksCalibration(law)) {
            throw std::invalid_argument(
                where +
                ": drift_model calibrated_drift needs a calibrated drift for a rheonomic method "
                "(run the calibration first, or use drift_model local)");
          }
          return MotionLaw::twist(law.calibrated_drift);
        case DriftModel::LocalSampled:
          if (lacksCalibration(law)) {
            throw std::invalid_argument(
                where +
                ": drift_model local_sampled needs the part families' efficiency factors for a "
                "rheonomic method (run calibrateEfficiency first, or use drift_model local)");
          }
          [[fallthrough]];
        case DriftModel::Local: {
          const LocalVibration v = localVibration(law.vibration, scene.gravity, scene.material.mu);
          v.validate(where + ".law.vibration");
          const std::shared_ptr<LocalDriftTable> table = LocalDriftTable::shared();
          if (scene.drift_table_corners) table->addCorners(*scene.drift_table_corners);
          return MotionLaw::localVibration(v, table);
        }
      }
  }
  return MotionLaw{};
}

bool lacksCalibration(const FeederLaw& law) {
  if (law.kind != FeederLaw::Kind::Vibration) return false;
  switch (law.drift_model) {
    case DriftModel::Local:
      return false;
    case DriftModel::LocalSampled:
      return law.efficiency.empty();
    case DriftModel::CalibratedDrift:
      return !law.has_calibrated_drift;
  }
  return false;
}

bool needsCalibration(const Scene& scene) {
  for (std::size_t i = 0; i < scene.fixtures.size(); ++i) {
    if (lacksCalibration(scene.fixtures[i].law) ||
        !staleCalibration(scene, static_cast<int>(i)).empty()) {
      return true;
    }
  }
  return false;
}

void overrideDriftModel(Scene& scene, DriftModel model) {
  for (Fixture& f : scene.fixtures) {
    if (f.law.kind != FeederLaw::Kind::Vibration || f.law.drift_model == model) continue;
    f.law.drift_model = model;
    f.law.efficiency.clear();  // the scene's factors belong to its own local_sampled
  }
}

std::vector<double> partEfficiencies(const Scene& scene) {
  return localEfficiencies(scene.fixtures, scene.parts.size(), scene.parts);
}

std::vector<std::string> uniqueNames(const std::vector<std::string>& names) {
  std::vector<std::string> keys;
  std::set<std::string> seen;
  for (std::size_t k = 0; k < names.size(); ++k) {
    std::string key = names[k];
    // taken (by an earlier name, or by a suffixed one): suffix the index, again while taken
    while (!seen.insert(key).second) key += "[" + std::to_string(k) + "]";
    keys.push_back(key);
  }
  return keys;
}

std::vector<std::string> familyKeys(const std::vector<PartSpec>& parts) {
  std::vector<std::string> names;
  for (const PartSpec& p : parts) names.push_back(p.name);
  return uniqueNames(names);
}

std::vector<PartInstance> drawParts(const Scene& scene) {
  std::mt19937_64 rng(scene.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  // A size from d truncated to [min, max] and to [lo, hi] (the size limits of scene.hpp).
  auto draw = [&](const Distribution& d, double lo = limits::kMinSize,
                  double hi = limits::kMaxSize) {
    const double a = std::max(d.min, lo), b = std::min(d.max, hi);
    for (int k = 0; k < kRedraws; ++k) {
      const double v = d.mean + d.stddev * normal(rng);
      if (v >= a && v <= b) return v;
    }
    return std::min(std::max(d.mean, a), b);
  };
  std::vector<PartInstance> out;
  std::vector<std::pair<Vec3, double>> placed;  // t = 0 parts: centre and bounding radius
  for (std::size_t s = 0; s < scene.parts.size(); ++s) {
    const PartSpec& spec = scene.parts[s];
    // Mesh parts: mass properties at scale 1 (mesh.hpp), and one scaled mesh per drawn scale.
    MassProperties unit_mesh;
    double unit_radius = 0;
    std::map<double, std::shared_ptr<const TriangleMesh>> scaled_meshes, scaled_hulls;
    if (spec.shape == Shape::Kind::Mesh) {
      if (!spec.mesh_data) {
        throw std::invalid_argument("parts[" + std::to_string(s) + "].mesh: '" + spec.mesh +
                                    "' is not loaded (use loadScene or loadSceneMeshes)");
      }
      if (spec.collision == PartSpec::Collision::ConvexHull && !spec.collision_mesh_data) {
        throw std::invalid_argument("parts[" + std::to_string(s) +
                                    "].collision: the convex hull of '" + spec.mesh +
                                    "' is not built (use loadScene or loadSceneMeshes)");
      }
      unit_mesh = massProperties(*spec.mesh_data, spec.density);
      unit_radius = boundingRadius(*spec.mesh_data);
      const double extent = spec.size[0].mean * unit_radius;
      if (!(extent >= limits::kMinSize && extent <= limits::kMaxSize)) {
        bad("parts[" + std::to_string(s) + "].size[0].mean", spec.size[0].mean,
            "scales the mesh's bounding radius " + show(unit_radius) + " (the file's units) to " +
                show(extent) + " m, which must be in [" + show(limits::kMinSize) + ", " +
                show(limits::kMaxSize) + "] m (mass and inertia must stay representable)");
      }
    }
    for (int i = 0; i < spec.count; ++i) {
      PartInstance p;
      p.spec = static_cast<int>(s);
      p.shape.kind = spec.shape;
      dMass m;
      double bound = 0;
      switch (spec.shape) {
        case Shape::Kind::Box:
          p.shape.size = {draw(spec.size[0]), draw(spec.size[1]), draw(spec.size[2])};
          dMassSetBox(&m, spec.density, p.shape.size.x, p.shape.size.y, p.shape.size.z);
          bound = 0.5 * norm(p.shape.size);
          break;
        case Shape::Kind::Sphere:
          p.shape.radius = draw(spec.size[0]);
          dMassSetSphere(&m, spec.density, p.shape.radius);
          bound = p.shape.radius;
          break;
        case Shape::Kind::Cylinder:
          p.shape.radius = draw(spec.size[0]);
          p.shape.length = draw(spec.size[1]);
          dMassSetCylinder(&m, spec.density, 3, p.shape.radius, p.shape.length);
          bound = std::hypot(p.shape.radius, 0.5 * p.shape.length);
          break;
        case Shape::Kind::Capsule:
          p.shape.radius = draw(spec.size[0]);
          p.shape.length = draw(spec.size[1]);
          dMassSetCapsule(&m, spec.density, 3, p.shape.radius, p.shape.length);
          bound = p.shape.radius + 0.5 * p.shape.length;
          break;
        case Shape::Kind::Mesh: {
          // size[0] scales the mesh (centred on its centre of mass): m ~ s^3, I ~ s^5.
          const double scale =
              draw(spec.size[0], limits::kMinSize / unit_radius, limits::kMaxSize / unit_radius);
          std::shared_ptr<const TriangleMesh>& mesh = scaled_meshes[scale];
          if (!mesh) mesh = std::make_shared<const TriangleMesh>(scaleMesh(*spec.mesh_data, scale));
          p.shape.mesh = spec.mesh;
          p.shape.mesh_scale = scale;
          p.shape.mesh_data = mesh;
          if (spec.collision == PartSpec::Collision::ConvexHull) {
            std::shared_ptr<const TriangleMesh>& hull = scaled_hulls[scale];
            if (!hull) {
              hull =
                  std::make_shared<const TriangleMesh>(scaleMesh(*spec.collision_mesh_data, scale));
            }
            p.shape.collision_mesh_data = hull;
          }
          const MassProperties mp = scaleMassProperties(unit_mesh, scale);
          const double* in = mp.inertia;
          dMassSetParameters(&m, mp.mass, 0, 0, 0, in[0], in[4], in[8], in[1], in[2], in[5]);
          bound = scale * unit_radius;
          break;
        }
        default:
          throw std::invalid_argument("parts[" + std::to_string(s) + "].shape: " +
                                      toString(spec.shape) + " parts are not supported here");
      }
      p.mass = m.mass;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) p.inertia[3 * r + c] = m.I[4 * r + c];
      }
      p.spawn_time = spec.rate > 0 ? i / spec.rate : 0.0;
      p.velocity = spec.initial_velocity;
      for (int tries = 0;; ++tries) {
        const Vec3 pos{spec.spawn_min.x + (spec.spawn_max.x - spec.spawn_min.x) * uniform(rng),
                       spec.spawn_min.y + (spec.spawn_max.y - spec.spawn_min.y) * uniform(rng),
                       spec.spawn_min.z + (spec.spawn_max.z - spec.spawn_min.z) * uniform(rng)};
        bool free = true;
        if (p.spawn_time == 0) {
          for (const auto& [c, r] : placed) free = free && norm(c - pos) > r + bound;
        }
        if (free || tries >= kPlacementTries) {
          if (!free) {
            throw std::invalid_argument("parts[" + std::to_string(s) +
                                        "].spawn_min/spawn_max: "
                                        "region too small for " +
                                        std::to_string(spec.count) +
                                        " parts spawned at t = 0 without overlap (rate = 0 "
                                        "spawns them all at once; a rate > 0, parts/s, spawns "
                                        "them one after another)");
          }
          p.pose.position = pos;
          if (p.spawn_time == 0) placed.emplace_back(pos, bound);
          break;
        }
      }
      if (spec.random_orientation) {
        // Uniform random rotation (Shoemake).
        const double u1 = uniform(rng), u2 = uniform(rng), u3 = uniform(rng);
        const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
        const double qx = a * std::sin(2 * kPi * u2), qy = a * std::cos(2 * kPi * u2);
        const double qz = b * std::sin(2 * kPi * u3), qw = b * std::cos(2 * kPi * u3);
        double* r = p.pose.rotation;
        r[0] = 1 - 2 * (qy * qy + qz * qz);
        r[1] = 2 * (qx * qy - qz * qw);
        r[2] = 2 * (qx * qz + qy * qw);
        r[3] = 2 * (qx * qy + qz * qw);
        r[4] = 1 - 2 * (qx * qx + qz * qz);
        r[5] = 2 * (qy * qz - qx * qw);
        r[6] = 2 * (qx * qz - qy * qw);
        r[7] = 2 * (qy * qz + qx * qw);
        r[8] = 1 - 2 * (qx * qx + qy * qy);
      }
      out.push_back(p);
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const PartInstance& a, const PartInstance& b) {
    return a.spawn_time < b.spawn_time;
  });
  return out;
}

}  // namespace rheofeed::scene
