// SPDX-License-Identifier: MIT
// Scene -> JSON (scene_io.hpp's toJson): the inverse of scene_io.cpp's reader, with the same
// key names; parseScene(toJson(s)) gives s back (tests/io).
#include <Eigen/Geometry>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::scene {
namespace {

using ojson = nlohmann::ordered_json;

constexpr int kFormatVersion = 1;  // as scene_io.cpp reads it
// Distribution::max when a file gives none (scene.hpp's default: unbounded).
constexpr double kUnbounded = Distribution{}.max;

// ---- Scene to JSON -----------------------------------------------------------------------------

// Like dump(2), but arrays of numbers, strings and booleans stay on one line: [0.0, 0.0, 1.0].
void pretty(const ojson& v, int indent, std::string& out) {
  const bool flat = v.is_array() && std::none_of(v.begin(), v.end(),
                                                 [](const ojson& e) { return e.is_structured(); });
  if (!v.is_structured() || v.empty()) {
    out += v.dump();
  } else if (flat) {
    out += "[";
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + v[i].dump();
    out += "]";
  } else {
    const std::string pad(indent + 2, ' ');
    out += v.is_object() ? "{\n" : "[\n";
    for (auto it = v.begin(); it != v.end(); ++it) {
      out += (it == v.begin() ? "" : ",\n") + pad;
      if (v.is_object()) out += ojson(it.key()).dump() + ": ";
      pretty(*it, indent + 2, out);
    }
    out += "\n" + std::string(indent, ' ') + (v.is_object() ? "}" : "]");
  }
}

ojson toJson(const Vec3& v) {
  return ojson::array({v.x, v.y, v.z});
}

ojson toJson(const Twist& t) {
  return ojson{
      {"linear", toJson(t.linear)}, {"angular", toJson(t.angular)}, {"origin", toJson(t.origin)}};
}

ojson toJson(const Distribution& d) {
  if (d.stddev == 0 && d.min == 0 && d.max == kUnbounded) return d.mean;
  ojson out{{"mean", d.mean}, {"stddev", d.stddev}, {"min", d.min}};
  if (d.max != kUnbounded) out["max"] = d.max;
  return out;
}

bool isIdentity(const Pose& p) {
  const Pose identity;
  return std::equal(p.rotation, p.rotation + 9, identity.rotation);
}

ojson rotationJson(const Pose& p) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = p.rotation[3 * i + j];
  }
  const Eigen::AngleAxisd aa(r);
  const Eigen::Vector3d& a = aa.axis();
  return ojson{{"axis", toJson(Vec3{a.x(), a.y(), a.z()})}, {"angle_rad", aa.angle()}};
}

ojson toJson(const Fixture::Geom& g) {
  const Shape& s = g.shape;
  ojson out{{"shape", toString(s.kind)}};
  switch (s.kind) {
    case Shape::Kind::Box:
      out["size"] = toJson(s.size);
      break;
    case Shape::Kind::Sphere:
      out["radius"] = s.radius;
      break;
    case Shape::Kind::Cylinder:
    case Shape::Kind::Capsule:
      out["radius"] = s.radius;
      out["length"] = s.length;
      break;
    case Shape::Kind::Plane:
      out["normal"] = toJson(s.plane_normal);
      out["offset"] = s.plane_offset;
      return out;
    case Shape::Kind::Mesh:
      out["mesh"] = s.mesh;
      out["scale"] = s.mesh_scale;
      break;
  }
  out["position"] = toJson(g.pose.position);
  if (!isIdentity(g.pose)) out["rotation"] = rotationJson(g.pose);
  return out;
}

ojson toJson(const Vibration& v) {
  return ojson{{"amplitude", v.amplitude},
               {"frequency", v.frequency},
               {"direction", toJson(v.direction)},
               {"phase_rad", v.phase},
               {"torsion_amplitude_rad", v.torsion_amplitude},
               {"axis_origin", toJson(v.axis_origin)},
               {"axis_direction", toJson(v.axis_direction)}};
}

// A law's efficiency factors: an object keyed by part family name when the names are unique
// and not empty (readable), else an array in the order of the parts.
ojson efficiencyJson(const std::vector<double>& factors, const std::vector<PartSpec>& parts) {
  bool named = factors.size() == parts.size();
  for (std::size_t k = 0; k < parts.size() && named; ++k) {
    if (parts[k].name.empty()) named = false;
    for (std::size_t j = 0; j < k && named; ++j) named = parts[j].name != parts[k].name;
  }
  if (!named) return ojson(factors);
  ojson out = ojson::object();
  for (std::size_t k = 0; k < factors.size(); ++k) out[parts[k].name] = factors[k];
  return out;
}

ojson toJson(const FeederLaw& law, const std::vector<PartSpec>& parts) {
  switch (law.kind) {
    case FeederLaw::Kind::None:
      return "none";
    case FeederLaw::Kind::Drift:
      return ojson{{"drift", toJson(law.drift)}};
    case FeederLaw::Kind::Belt:
      return ojson{
          {"belt", ojson{{"direction", toJson(law.belt_direction)}, {"speed", law.belt_speed}}}};
    case FeederLaw::Kind::Vibration: {
      ojson out{{"vibration", toJson(law.vibration)}};
      out["drift_model"] = toString(law.drift_model);
      if (law.has_calibrated_drift) out["calibrated_drift"] = toJson(law.calibrated_drift);
      if (!law.efficiency.empty()) out["efficiency"] = efficiencyJson(law.efficiency, parts);
      if (law.calibrated_for) {
        out["calibrated_for"] = ojson{{"vibration", toJson(law.calibrated_for->vibration)},
                                      {"gravity", toJson(law.calibrated_for->gravity)},
                                      {"mu", law.calibrated_for->mu}};
        const CalibrationBasis& was = *law.calibrated_for;
        ojson& basis = out["calibrated_for"];
        if (!was.method.empty()) basis["method"] = was.method;
        if (was.conveying_direction)
          basis["conveying_direction"] = toJson(*was.conveying_direction);
        if (was.track_point) basis["track_point"] = toJson(*was.track_point);
        if (was.restitution) basis["restitution"] = *was.restitution;
        if (!was.part_digests.empty()) basis["part_digests"] = was.part_digests;
        if (!was.fixture_digests.empty()) basis["fixture_digests"] = was.fixture_digests;
      }
      return out;
    }
  }
  return "none";
}

ojson toJson(const PartSpec& p) {
  ojson out{{"name", p.name}, {"shape", toString(p.shape)}};
  if (p.shape == Shape::Kind::Mesh) {
    out["mesh"] = p.mesh;
    out["collision"] = p.collision == PartSpec::Collision::ConvexHull ? "convex_hull" : "mesh";
  }
  ojson size = ojson::array();
  for (int d = 0; d < partSizeCount(p.shape); ++d) size.push_back(toJson(p.size[d]));
  out["size"] = size;
  out["density"] = p.density;
  out["spawn_min"] = toJson(p.spawn_min);
  out["spawn_max"] = toJson(p.spawn_max);
  out["random_orientation"] = p.random_orientation;
  out["count"] = p.count;
  out["rate"] = p.rate;
  out["initial_velocity"] = toJson(p.initial_velocity);
  return out;
}

}  // namespace

std::string toJson(const Scene& scene) {
  ojson out;
  out["format_version"] = kFormatVersion;
  out["name"] = scene.name;
  out["gravity"] = toJson(scene.gravity);
  out["duration"] = scene.duration;
  out["removal_height"] = scene.removal_height;
  out["seed"] = scene.seed;
  if (!scene.drift_table.empty()) out["drift_table"] = scene.drift_table;
  ojson fixtures = ojson::array();
  for (const Fixture& f : scene.fixtures) {
    ojson fj{{"name", f.name}};
    ojson geoms = ojson::array();
    for (const Fixture::Geom& g : f.geoms) geoms.push_back(toJson(g));
    fj["geoms"] = geoms;
    if (f.law.kind != FeederLaw::Kind::None) fj["law"] = toJson(f.law, scene.parts);
    fixtures.push_back(fj);
  }
  out["fixtures"] = fixtures;
  ojson parts = ojson::array();
  for (const PartSpec& p : scene.parts) parts.push_back(toJson(p));
  out["parts"] = parts;
  out["material"] = {{"mu", scene.material.mu}, {"restitution", scene.material.restitution}};
  const SolverSettings& x = scene.solver;
  out["solver"] = {{"time_step", x.time_step},
                   {"iterations", x.iterations},
                   {"ode_quickstep", x.ode_quickstep},
                   {"erp", x.erp},
                   {"cfm", x.cfm},
                   {"tolerance", x.tolerance},
                   {"apgd", x.apgd},
                   {"coulomb_iterations", x.coulomb_iterations},
                   {"max_correcting_velocity", x.max_correcting_velocity},
                   {"surface_layer", x.surface_layer}};
  if (x.rheonomic_time_step != 0) out["solver"]["rheonomic_time_step"] = x.rheonomic_time_step;
  if (x.friction) out["solver"]["friction"] = toString(*x.friction);
  if (x.speculative_contacts) out["solver"]["speculative_contacts"] = *x.speculative_contacts;
  if (x.broad_phase) out["solver"]["broad_phase"] = toString(*x.broad_phase);
  if (x.warm_start) out["solver"]["warm_start"] = *x.warm_start;
  const Outputs& o = scene.outputs;
  const Outputs defaults;
  ojson oj{{"conveying_direction", toJson(o.conveying_direction)}};
  oj["angular_drift"] = o.angular_drift;
  if (o.angular_drift || o.axis_origin != defaults.axis_origin ||
      o.axis_direction != defaults.axis_direction) {
    oj["axis_origin"] = toJson(o.axis_origin);
    oj["axis_direction"] = toJson(o.axis_direction);
  }
  oj["exit_plane"] = o.exit_plane;
  if (o.exit_plane || o.exit_point != defaults.exit_point ||
      o.exit_normal != defaults.exit_normal) {
    oj["exit_point"] = toJson(o.exit_point);
    oj["exit_normal"] = toJson(o.exit_normal);
  }
  oj["sample_interval"] = o.sample_interval;
  oj["warmup"] = o.warmup;
  out["outputs"] = oj;
  std::string text;
  pretty(out, 0, text);
  return text + "\n";
}

}  // namespace rheofeed::scene
