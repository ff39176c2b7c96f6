// SPDX-License-Identifier: MIT
#include "rheofeed/scene/scene.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>

#include "rheofeed/scene/mesh.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Truncated normal sizes are redrawn this many times before the value is clamped.
constexpr int kRedraws = 100;
// Attempts to place a part spawned at t = 0 without overlapping earlier ones.
constexpr int kPlacementTries = 200;

[[noreturn]] void bad(const std::string& path, double value, const std::string& why) {
  std::ostringstream out;
  out << path << " = " << value << ": " << why;
  throw std::invalid_argument(out.str());
}

void positive(const std::string& path, double v) {
  if (!std::isfinite(v) || !(v > 0)) bad(path, v, "must be a finite number > 0");
}
void nonNegative(const std::string& path, double v) {
  if (!std::isfinite(v) || !(v >= 0)) bad(path, v, "must be a finite number >= 0");
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

void validateShape(const std::string& path, const Shape& s, bool static_geom) {
  switch (s.kind) {
    case Shape::Kind::Box:
      positive(path + ".size.x", s.size.x);
      positive(path + ".size.y", s.size.y);
      positive(path + ".size.z", s.size.z);
      break;
    case Shape::Kind::Sphere:
      positive(path + ".radius", s.radius);
      break;
    case Shape::Kind::Cylinder:
    case Shape::Kind::Capsule:
      positive(path + ".radius", s.radius);
      positive(path + ".length", s.length);
      break;
    case Shape::Kind::Plane:
      if (!static_geom) throw std::invalid_argument(path + ".shape: a plane can only be static");
      unit(path + ".normal", s.plane_normal);
      finite(path + ".offset", s.plane_offset);
      break;
    case Shape::Kind::Mesh:
      if (s.mesh.empty()) throw std::invalid_argument(path + ".mesh: empty file name");
      positive(path + ".scale", s.mesh_scale);
      break;
  }
}

void validateTwist(const std::string& path, const Twist& t) {
  finite(path + ".linear", t.linear);
  finite(path + ".angular", t.angular);
  finite(path + ".origin", t.origin);
}

}  // namespace

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
  finite("gravity", gravity);
  positive("duration", duration);
  positive("solver.time_step", solver.time_step);
  if (solver.iterations < 1) bad("solver.iterations", solver.iterations, "must be >= 1");
  if (!(solver.erp >= 0 && solver.erp <= 1)) bad("solver.erp", solver.erp, "must be in [0, 1]");
  nonNegative("solver.cfm", solver.cfm);
  positive("solver.max_correcting_velocity", solver.max_correcting_velocity);
  nonNegative("solver.surface_layer", solver.surface_layer);
  finite("removal_height", removal_height);
  if (solver.coulomb_iterations < 0) {
    bad("solver.coulomb_iterations", solver.coulomb_iterations, "must be >= 0");
  }
  positive("solver.tolerance", solver.tolerance);
  nonNegative("material.mu", material.mu);
  if (!(material.restitution >= 0 && material.restitution <= 1)) {
    bad("material.restitution", material.restitution, "must be in [0, 1]");
  }
  unit("outputs.conveying_direction", outputs.conveying_direction);
  positive("outputs.sample_interval", outputs.sample_interval);
  nonNegative("outputs.warmup", outputs.warmup);
  if (outputs.angular_drift) {
    finite("outputs.axis_origin", outputs.axis_origin);
    unit("outputs.axis_direction", outputs.axis_direction);
  }
  if (outputs.exit_plane) {
    finite("outputs.exit_point", outputs.exit_point);
    unit("outputs.exit_normal", outputs.exit_normal);
  }
  for (std::size_t i = 0; i < fixtures.size(); ++i) {
    const Fixture& f = fixtures[i];
    const std::string path = "fixtures[" + std::to_string(i) + "]";
    if (f.geoms.empty()) throw std::invalid_argument(path + ".geoms: a fixture needs a geom");
    for (std::size_t g = 0; g < f.geoms.size(); ++g) {
      const std::string gp = path + ".geoms[" + std::to_string(g) + "]";
      validateShape(gp, f.geoms[g].shape, true);
      finite(gp + ".position", f.geoms[g].pose.position);
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
        finite(path + ".law.belt.speed", law.belt_speed);
        break;
      case FeederLaw::Kind::Vibration: {
        const Vibration& v = law.vibration;
        nonNegative(path + ".law.vibration.amplitude", v.amplitude);
        positive(path + ".law.vibration.frequency", v.frequency);
        unit(path + ".law.vibration.direction", v.direction);
        finite(path + ".law.vibration.phase", v.phase);
        nonNegative(path + ".law.vibration.torsion_amplitude", v.torsion_amplitude);
        finite(path + ".law.vibration.axis_origin", v.axis_origin);
        unit(path + ".law.vibration.axis_direction", v.axis_direction);
        if (v.isZero()) bad(path + ".law.vibration.amplitude", 0, "a vibration needs an amplitude");
        if (law.has_calibrated_drift)
          validateTwist(path + ".law.calibrated_drift", law.calibrated_drift);
        break;
      }
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
    for (int d = 0; d < dims; ++d) {
      const std::string sp = path + ".size[" + std::to_string(d) + "]";
      positive(sp + ".mean", p.size[d].mean);
      nonNegative(sp + ".stddev", p.size[d].stddev);
      nonNegative(sp + ".min", p.size[d].min);
      if (!(p.size[d].max > p.size[d].min)) bad(sp + ".max", p.size[d].max, "must exceed min");
    }
    positive(path + ".density", p.density);
    finite(path + ".spawn_min", p.spawn_min);
    finite(path + ".spawn_max", p.spawn_max);
    if (p.spawn_max.x < p.spawn_min.x || p.spawn_max.y < p.spawn_min.y ||
        p.spawn_max.z < p.spawn_min.z) {
      throw std::invalid_argument(path + ".spawn_max: must be >= spawn_min in every axis");
    }
    if (p.count < 1) bad(path + ".count", p.count, "must be >= 1");
    nonNegative(path + ".rate", p.rate);
    finite(path + ".initial_velocity", p.initial_velocity);
  }
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

MotionLaw rheonomicLaw(const Fixture& fixture) {
  const FeederLaw& law = fixture.law;
  switch (law.kind) {
    case FeederLaw::Kind::None:
      return MotionLaw{};
    case FeederLaw::Kind::Drift:
      return MotionLaw::twist(law.drift);
    case FeederLaw::Kind::Belt:
      return MotionLaw::belt(law.belt_direction, law.belt_speed);
    case FeederLaw::Kind::Vibration:
      if (!law.has_calibrated_drift) {
        throw std::invalid_argument("fixture '" + fixture.name +
                                    "': a vibrating feeder needs a calibrated drift for a "
                                    "rheonomic method (run the calibration first)");
      }
      return MotionLaw::twist(law.calibrated_drift);
  }
  return MotionLaw{};
}

std::vector<PartInstance> drawParts(const Scene& scene) {
  std::mt19937_64 rng(scene.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto draw = [&](const Distribution& d) {
    for (int k = 0; k < kRedraws; ++k) {
      const double v = d.mean + d.stddev * normal(rng);
      if (v >= d.min && v <= d.max && v > 0) return v;
    }
    return std::min(std::max(d.mean, d.min), d.max);
  };
  std::vector<PartInstance> out;
  std::vector<std::pair<Vec3, double>> placed;  // t = 0 parts: centre and bounding radius
  for (std::size_t s = 0; s < scene.parts.size(); ++s) {
    const PartSpec& spec = scene.parts[s];
    // Mesh parts: mass properties at scale 1 (mesh.hpp), and one scaled mesh per drawn scale.
    MassProperties unit_mesh;
    double unit_radius = 0;
    std::map<double, std::shared_ptr<const TriangleMesh>> scaled_meshes;
    if (spec.shape == Shape::Kind::Mesh) {
      if (!spec.mesh_data) {
        throw std::invalid_argument("parts[" + std::to_string(s) + "].mesh: '" + spec.mesh +
                                    "' is not loaded (use loadScene or loadSceneMeshes)");
      }
      unit_mesh = massProperties(*spec.mesh_data, spec.density);
      unit_radius = boundingRadius(*spec.mesh_data);
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
          const double scale = draw(spec.size[0]);
          std::shared_ptr<const TriangleMesh>& mesh = scaled_meshes[scale];
          if (!mesh) mesh = std::make_shared<const TriangleMesh>(scaleMesh(*spec.mesh_data, scale));
          p.shape.mesh = spec.mesh;
          p.shape.mesh_scale = scale;
          p.shape.mesh_data = mesh;
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
                                        " parts spawned at t = 0 without overlap");
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
