// SPDX-License-Identifier: MIT
// Scene files (JSON): text -> DOM (with paths, duplicate keys and overflowing numbers caught by
// a SAX handler) -> Scene (every value type- and range-checked, unknown keys refused) ->
// Scene::validate() -> meshes -> drawParts. This file reads the DOM into a Scene; text -> DOM is
// scene_io_json.cpp, the meshes scene_io_mesh.cpp, Scene -> JSON scene_io_write.cpp. The format
// is documented in demos/scenes/README.md; the key names follow the field names of scene.hpp.
#include "rheofeed/scene/scene_io.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>
#include <vector>

#include "rheofeed/scene/drift_table_file.hpp"
#include "rheofeed/scene/mesh.hpp"
#include "scene_io_internal.hpp"
#include "scene_limits.hpp"

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;
using io::describe;
using io::fail;
using io::json;
using io::parseText;
using io::show;

constexpr double kPi = 3.14159265358979323846;
constexpr int kFormatVersion = 1;

// ---- DOM to values -----------------------------------------------------------------------------

enum class Range { Any, Positive, NonNegative, UnitInterval };
struct UnitVector {};  // tag: read a direction, refuse zero, normalise

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// The closest of `options` to `word` if it is close enough to be a typo of it, else "".
std::string closest(const std::string& word, const std::vector<std::string>& options) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const std::string& o : options) {
    const std::size_t d = editDistance(word, o);
    if (d < best_distance) {
      best = o;
      best_distance = d;
    }
  }
  return best;
}

void checkRange(const std::string& path, double v, Range range) {
  if (!std::isfinite(v)) fail(path, "must be finite, got " + show(v));
  switch (range) {
    case Range::Any:
      break;
    case Range::Positive:
      if (!(v > 0)) fail(path, "must be > 0, got " + show(v));
      break;
    case Range::NonNegative:
      if (!(v >= 0)) fail(path, "must be >= 0, got " + show(v));
      break;
    case Range::UnitInterval:
      if (!(v >= 0 && v <= 1)) fail(path, "must be in [0, 1], got " + show(v));
      break;
  }
}

void read(const json& v, const std::string& path, double& out, Range range = Range::Any) {
  if (!v.is_number()) fail(path, "expected a number, got " + describe(v));
  out = v.get<double>();
  checkRange(path, out, range);
}

void read(const json& v, const std::string& path, int& out, int min) {
  double d = 0;
  read(v, path, d);
  if (d != std::floor(d)) fail(path, "expected an integer, got " + describe(v));
  if (std::abs(d) > 2e9) {
    fail(path,
         "expected an integer between -2e9 and 2e9 (the setting's own range is narrower), "
         "got " +
             describe(v));
  }
  if (d < min) fail(path, "must be >= " + std::to_string(min) + ", got " + describe(v));
  out = static_cast<int>(d);
}

void read(const json& v, const std::string& path, std::uint64_t& out) {
  if (v.is_number_unsigned()) {
    out = v.get<std::uint64_t>();
    return;
  }
  double d = 0;
  read(v, path, d);
  if (d != std::floor(d) || d < 0 || d >= 18446744073709551616.0) {
    fail(path, "expected an integer >= 0, got " + describe(v));
  }
  out = static_cast<std::uint64_t>(d);
}

void read(const json& v, const std::string& path, bool& out) {
  if (!v.is_boolean()) fail(path, "expected true or false, got " + describe(v));
  out = v.get<bool>();
}

void read(const json& v, const std::string& path, std::string& out) {
  if (!v.is_string()) fail(path, "expected a string, got " + describe(v));
  out = v.get<std::string>();
}

void read(const json& v, const std::string& path, Vec3& out, Range range = Range::Any) {
  if (!v.is_array() || v.size() != 3) fail(path, "expected [x, y, z], got " + describe(v));
  read(v[0], path + "[0]", out.x, range);
  read(v[1], path + "[1]", out.y, range);
  read(v[2], path + "[2]", out.z, range);
}

// A direction that is already of unit length to rounding (as toJson writes every normalised
// direction) is kept as written: normalising it again can move it by an ulp, and a written scene
// must read back equal (found by fuzz/fuzz_scene: [1, 1, 0] -> 0.7071067811865475 -> ...476).
constexpr double kUnitLengthSlack = 4 * std::numeric_limits<double>::epsilon();

void read(const json& v, const std::string& path, Vec3& out, UnitVector) {
  read(v, path, out);
  const double n = norm(out);
  if (!(n > 0) || !std::isfinite(n)) fail(path, "a direction must not be the zero vector");
  if (std::abs(n - 1.0) > kUnitLengthSlack) out = (1.0 / n) * out;
}

// Readers of composite values (defined below; declared here for Object's templates).
void read(const json& v, const std::string& path, Distribution& out);
void read(const json& v, const std::string& path, Twist& out);
void read(const json& v, const std::string& path, Pose& out);

// |angle| within the scene files' range (scene_limits.hpp, kMaxAngleDegrees).
void checkAngle(const std::string& path, double angle, double max, const char* unit) {
  if (!(std::abs(angle) <= max)) {
    fail(path, "must be in [-" + show(max) + ", " + show(max) + "] " + unit +
                   " (1e6 degrees: a double resolves no finer angle there than 1e-10 degree), "
                   "got " +
                   show(angle));
  }
}

// A JSON object being read: every key asked for is remembered, and finish() refuses the rest.
class Object {
 public:
  Object(const json& j, std::string path) : j_(j), path_(std::move(path)) {
    if (!j.is_object()) fail(path_, "expected an object, got " + describe(j));
    std::string comment;  // "comment" is allowed everywhere and ignored
    opt("comment", comment);
  }

  std::string at(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  bool has(const char* key) const { return j_.contains(key); }

  const json* find(const char* key) {
    known_.emplace_back(key);
    const auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  const json& require(const char* key) {
    if (const json* v = find(key)) return *v;
    std::vector<std::string> unknown;
    for (const auto& item : j_.items()) {
      if (std::find(known_.begin(), known_.end(), item.key()) == known_.end()) {
        unknown.push_back(item.key());
      }
    }
    const std::string typo = closest(key, unknown);
    fail(at(key), "missing required key" + (typo.empty() ? "" : " (is \"" + typo + "\" a typo?)"));
  }
  template <class T, class... Extra>
  bool opt(const char* key, T& out, Extra... extra) {
    const json* v = find(key);
    if (v) read(*v, at(key), out, extra...);
    return v != nullptr;
  }
  template <class T, class... Extra>
  void req(const char* key, T& out, Extra... extra) {
    read(require(key), at(key), out, extra...);
  }
  // An angle given as "<stem>_deg" or "<stem>_rad" (not both); out in radians.
  bool optAngle(const std::string& stem, double& out_rad, Range range = Range::Any) {
    const std::string deg = stem + "_deg", rad = stem + "_rad";
    const json* d = find(deg.c_str());
    const json* r = find(rad.c_str());
    if (d && r) fail(at(deg), "give either " + deg + " or " + rad + ", not both");
    if (d) {
      read(*d, at(deg), out_rad, range);
      checkAngle(at(deg), out_rad, limits::kMaxAngleDegrees, "degrees");
      out_rad *= kPi / 180;
    } else if (r) {
      read(*r, at(rad), out_rad, range);
      checkAngle(at(rad), out_rad, limits::kMaxAngle, "rad");
    }
    return d || r;
  }
  void reqAngle(const std::string& stem, double& out_rad, Range range = Range::Any) {
    if (!optAngle(stem, out_rad, range)) fail(at(stem + "_deg"), "missing (or " + stem + "_rad)");
  }
  // Refuses every key that was not asked for.
  void finish() const {
    for (const auto& item : j_.items()) {
      if (std::find(known_.begin(), known_.end(), item.key()) != known_.end()) continue;
      std::string list;
      std::set<std::string> listed{"comment"};
      for (const std::string& k : known_) {
        if (listed.insert(k).second) list += (list.empty() ? "" : ", ") + k;
      }
      const std::string typo = closest(item.key(), known_);
      fail(at(item.key()), "unknown key" +
                               (typo.empty() ? "" : " (did you mean \"" + typo + "\"?)") +
                               "; expected one of: " + list);
    }
  }

 private:
  const json& j_;
  std::string path_;
  std::vector<std::string> known_;
};

void read(const json& v, const std::string& path, Distribution& out) {
  if (v.is_number()) {
    out = Distribution{};
    read(v, path, out.mean, Range::Positive);
    return;
  }
  if (!v.is_object()) {
    fail(path, "expected a number or {\"mean\": ..., \"stddev\": ...}, got " + describe(v));
  }
  Object o(v, path);
  o.req("mean", out.mean, Range::Positive);
  o.opt("stddev", out.stddev, Range::NonNegative);
  o.opt("min", out.min, Range::NonNegative);
  o.opt("max", out.max, Range::Positive);
  o.finish();
}

void read(const json& v, const std::string& path, Twist& out) {
  Object o(v, path);
  o.opt("linear", out.linear);
  o.opt("angular", out.angular);
  o.opt("origin", out.origin);
  o.finish();
}

void read(const json& v, const std::string& path, Pose& out) {  // rotation part only
  Object o(v, path);
  Vec3 axis;
  double angle = 0;
  o.req("axis", axis, UnitVector{});
  o.reqAngle("angle", angle);
  o.finish();
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(angle, Eigen::Vector3d(axis.x, axis.y, axis.z)).matrix();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out.rotation[3 * i + j] = r(i, j);
  }
}

Shape::Kind shapeKind(const json& v, const std::string& path) {
  std::string name;
  read(v, path, name);
  for (Shape::Kind k : {Shape::Kind::Box, Shape::Kind::Sphere, Shape::Kind::Cylinder,
                        Shape::Kind::Capsule, Shape::Kind::Plane, Shape::Kind::Mesh}) {
    if (name == toString(k)) return k;
  }
  fail(path,
       "unknown shape \"" + name + "\"; expected box, sphere, cylinder, capsule, plane or mesh");
}

// A torsion amplitude, refused beyond half a turn in the unit it was given in (the scene's limit,
// limits::kMaxTorsion: "torsion_amplitude_deg": 400 is named as 400 degrees, not 6.98 rad).
void readTorsion(Object& o, Vibration& v) {
  if (!o.optAngle("torsion_amplitude", v.torsion_amplitude, Range::NonNegative)) return;
  if (v.torsion_amplitude > limits::kMaxTorsion) {
    const bool deg = o.has("torsion_amplitude_deg");
    fail(o.at(deg ? "torsion_amplitude_deg" : "torsion_amplitude_rad"),
         "a torsion amplitude must be at most half a turn, 180 degrees or pi rad, got " +
             show(deg ? v.torsion_amplitude * 180 / kPi : v.torsion_amplitude) +
             (deg ? " degrees" : " rad") + " (vibratory bowls turn by a fraction of a degree)");
  }
}

void readVibration(Object& o, Vibration& v) {
  o.opt("amplitude", v.amplitude, Range::NonNegative);
  o.req("frequency", v.frequency, Range::Positive);
  double angle = 0;
  if (o.optAngle("angle", angle)) {  // throw angle above +x, in the x-z plane
    if (o.has("direction")) fail(o.at("direction"), "give either direction or angle, not both");
    if (std::abs(angle) > 2 * kPi) {  // more than a turn: most often degrees given as radians
      const bool rad = o.has("angle_rad");
      fail(o.at(rad ? "angle_rad" : "angle_deg"),
           "a throw angle must be within one turn, [-360, 360] degrees or [-2 pi, 2 pi] rad, "
           "got " +
               show(rad ? angle : angle * 180 / kPi) + (rad ? " rad" : " degrees") +
               (rad ? " (did you mean angle_deg?)" : ""));
    }
    v.direction = {std::cos(angle), 0, std::sin(angle)};
  } else {
    o.opt("direction", v.direction, UnitVector{});
  }
  o.optAngle("phase", v.phase);
  readTorsion(o, v);
  o.opt("axis_origin", v.axis_origin);
  o.opt("axis_direction", v.axis_direction, UnitVector{});
}

// A bowl's screw motion: translation along the torsion axis in phase with the torsion.
void readScrew(Object& o, Vibration& v) {
  o.opt("vertical_amplitude", v.amplitude, Range::NonNegative);
  readTorsion(o, v);
  o.req("frequency", v.frequency, Range::Positive);
  o.optAngle("phase", v.phase);
  o.opt("axis_origin", v.axis_origin);
  o.opt("axis_direction", v.axis_direction, UnitVector{});
  v.direction = v.axis_direction;
  if (v.isZero()) {
    fail(o.at("vertical_amplitude"),
         "a screw motion needs vertical_amplitude or "
         "torsion_amplitude_deg/_rad > 0");
  }
}

// A law's "efficiency", read once the part families are known (readEfficiency).
struct PendingEfficiency {
  std::size_t fixture = 0;
  const json* value = nullptr;
  std::string path;
};

void readLaw(const json& v, const std::string& path, FeederLaw& law,
             std::vector<PendingEfficiency>& pending, std::size_t fixture) {
  if (v.is_string() && v.get<std::string>() == "none") return;
  Object o(v, path);
  const char* kinds[] = {"drift", "belt", "vibration", "screw"};
  const char* given = nullptr;
  for (const char* k : kinds) {
    if (!o.has(k)) continue;
    if (given) fail(o.at(k), std::string("a law has one kind; \"") + given + "\" is given too");
    given = k;
  }
  if (!given) {
    fail(path,
         "expected one of \"drift\", \"belt\", \"vibration\", \"screw\" (or no \"law\" "
         "for a fixture that does not move)");
  }
  const std::string kind = given;
  for (const char* key : {"calibrated_drift", "drift_model", "efficiency", "calibrated_for"}) {
    if (o.has(key) && (kind == "drift" || kind == "belt")) {
      fail(o.at(key), std::string("only a vibration or screw law has a ") +
                          (key == std::string("efficiency") ? "part efficiency" : key));
    }
  }
  if (kind == "drift") {
    law.kind = FeederLaw::Kind::Drift;
    o.req("drift", law.drift);
  } else if (kind == "belt") {
    law.kind = FeederLaw::Kind::Belt;
    Object belt(*o.find("belt"), o.at(kind));
    belt.req("direction", law.belt_direction, UnitVector{});
    belt.req("speed", law.belt_speed);
    belt.finish();
  } else {
    law.kind = FeederLaw::Kind::Vibration;
    Object body(*o.find(given), o.at(kind));
    kind == "vibration" ? readVibration(body, law.vibration) : readScrew(body, law.vibration);
    body.finish();
    if (o.opt("calibrated_drift", law.calibrated_drift)) law.has_calibrated_drift = true;
    if (const json* basis = o.find("calibrated_for")) {
      Object b(*basis, o.at("calibrated_for"));
      CalibrationBasis& was = law.calibrated_for.emplace();
      Object vibration(b.require("vibration"), b.at("vibration"));
      readVibration(vibration, was.vibration);
      vibration.finish();
      b.req("gravity", was.gravity);
      b.req("mu", was.mu, Range::NonNegative);
      if (b.opt("method", was.method) && was.method != "classical" && was.method != "sampling") {
        fail(b.at("method"),
             "unknown calibration method \"" + was.method + "\"; expected classical or sampling");
      }
      Vec3 point;
      if (b.opt("conveying_direction", point, UnitVector{})) was.conveying_direction = point;
      if (b.opt("track_point", point)) was.track_point = point;
      double restitution = 0;
      if (b.opt("restitution", restitution, Range::UnitInterval)) was.restitution = restitution;
      // One digest per part family and per fixture (partDigest, fixtureDigest): 16 lowercase
      // hex digits each, or "" for a family whose factor the record did not measure.
      for (auto [key, digests, blank] : {std::tuple<const char*, std::vector<std::string>*, bool>{
                                             "part_digests", &was.part_digests, true},
                                         {"fixture_digests", &was.fixture_digests, false}}) {
        const json* list = b.find(key);
        if (!list) continue;
        const std::string where = b.at(key);
        if (!list->is_array() || list->size() > static_cast<std::size_t>(limits::kMaxGeoms)) {
          fail(where, "expected an array of at most " + std::to_string(limits::kMaxGeoms) +
                          " digests (16 hex digits each, as rheofeed writes them), got " +
                          describe(*list));
        }
        for (std::size_t i = 0; i < list->size(); ++i) {
          const std::string at = where + "[" + std::to_string(i) + "]";
          std::string digest;
          read((*list)[i], at, digest);
          const bool hex = digest.size() == 16 &&
                           digest.find_first_not_of("0123456789abcdef") == std::string::npos;
          if (!hex && !(blank && digest.empty())) {
            fail(at, std::string("expected 16 lowercase hex digits") +
                         (blank ? " or \"\" (not measured)" : "") +
                         " (as rheofeed writes them), got \"" + digest + "\"");
          }
          digests->push_back(digest);
        }
      }
      b.finish();
    }
    // Without drift_model: a law that carries a calibrated drift keeps using it (files written
    // before the local law behave as before); any other uses the local law.
    law.drift_model = law.has_calibrated_drift ? DriftModel::CalibratedDrift : DriftModel::Local;
    std::string model;
    if (o.opt("drift_model", model) && !parseDriftModel(model, law.drift_model)) {
      const std::vector<std::string> names = {"local", "local_sampled", "calibrated_drift"};
      const std::string typo = closest(model, names);
      fail(o.at("drift_model"), "unknown drift model \"" + model + "\"" +
                                    (typo.empty() ? "" : " (did you mean \"" + typo + "\"?)") +
                                    "; expected local, local_sampled or calibrated_drift");
    }
    if (const json* e = o.find("efficiency")) {
      if (law.drift_model != DriftModel::LocalSampled) {
        fail(o.at("efficiency"), std::string("efficiency factors apply to drift_model "
                                             "local_sampled only; this law's drift_model is ") +
                                     toString(law.drift_model) +
                                     (o.has("drift_model") ? "" : " (the default)"));
      }
      pending.push_back({fixture, e, o.at("efficiency")});
    }
  }
  o.finish();
}

// "efficiency": {"<part family name>": factor, ...} (families not named get 1) or an array of
// one factor per family; each factor in [0, kMaxPartEfficiency].
std::vector<double> readEfficiency(const json& v, const std::string& path,
                                   const std::vector<PartSpec>& parts) {
  std::vector<double> out(parts.size(), 1.0);
  auto factor = [&](const json& x, const std::string& at, double& e) {
    read(x, at, e, Range::NonNegative);
    if (e > kMaxPartEfficiency) {
      fail(at, "must be in [0, " + show(kMaxPartEfficiency) +
                   "] (a part family's own efficiency under the local law, 1 = a point mass), "
                   "got " +
                   show(e));
    }
  };
  if (v.is_array()) {
    if (v.size() != parts.size()) {
      fail(path, "an array of efficiency factors needs one per part family (" +
                     std::to_string(parts.size()) + ", in the order of parts), got " + describe(v));
    }
    for (std::size_t k = 0; k < v.size(); ++k) {
      factor(v[k], path + "[" + std::to_string(k) + "]", out[k]);
    }
    return out;
  }
  if (!v.is_object()) {
    fail(path, "expected {\"<part family name>\": factor, ...} or an array of factors, got " +
                   describe(v));
  }
  std::vector<std::string> names;
  for (const PartSpec& p : parts) names.push_back(p.name);
  for (const auto& item : v.items()) {
    const std::string at = path + "." + item.key();
    std::size_t found = parts.size();
    for (std::size_t k = 0; k < parts.size(); ++k) {
      if (parts[k].name != item.key()) continue;
      if (found != parts.size()) {
        fail(at, "parts[" + std::to_string(found) + "] and parts[" + std::to_string(k) +
                     "] are both named \"" + item.key() +
                     "\"; give the efficiency as an array, one factor per family");
      }
      found = k;
    }
    if (found == parts.size()) {
      std::string list;
      for (const std::string& n : names) list += (list.empty() ? "\"" : ", \"") + n + "\"";
      const std::string typo = closest(item.key(), names);
      fail(at, "no part family is named \"" + item.key() + "\"" +
                   (typo.empty() ? "" : " (did you mean \"" + typo + "\"?)") +
                   "; the families are " + list);
    }
    factor(item.value(), at, out[found]);
  }
  return out;
}

Fixture::Geom readGeom(const json& v, const std::string& path) {
  Object o(v, path);
  Fixture::Geom g;
  Shape& s = g.shape;
  s.kind = shapeKind(o.require("shape"), o.at("shape"));
  switch (s.kind) {
    case Shape::Kind::Box:
      o.req("size", s.size, Range::Positive);
      break;
    case Shape::Kind::Sphere:
      o.req("radius", s.radius, Range::Positive);
      break;
    case Shape::Kind::Cylinder:
    case Shape::Kind::Capsule:
      o.req("radius", s.radius, Range::Positive);
      o.req("length", s.length, Range::Positive);
      break;
    case Shape::Kind::Plane:
      o.req("normal", s.plane_normal, UnitVector{});
      o.opt("offset", s.plane_offset);
      break;
    case Shape::Kind::Mesh:
      o.req("mesh", s.mesh);
      if (s.mesh.empty()) fail(o.at("mesh"), "empty file name");
      o.opt("scale", s.mesh_scale, Range::Positive);
      break;
  }
  if (s.kind != Shape::Kind::Plane) {  // a plane is placed by its equation
    o.opt("position", g.pose.position);
    o.opt("rotation", g.pose);
  }
  o.finish();
  return g;
}

template <class T, class F>
std::vector<T> readArray(const json& v, const std::string& path, F element) {
  if (!v.is_array()) fail(path, "expected an array, got " + describe(v));
  std::vector<T> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    out.push_back(element(v[i], path + "[" + std::to_string(i) + "]"));
  }
  return out;
}

Fixture readFixture(const json& v, const std::string& path, std::vector<PendingEfficiency>& pending,
                    std::size_t index) {
  Object o(v, path);
  Fixture f;
  o.opt("name", f.name);
  f.geoms = readArray<Fixture::Geom>(o.require("geoms"), o.at("geoms"), readGeom);
  if (const json* law = o.find("law")) readLaw(*law, o.at("law"), f.law, pending, index);
  o.finish();
  return f;
}

PartSpec readPart(const json& v, const std::string& path) {
  Object o(v, path);
  PartSpec p;
  o.opt("name", p.name);
  p.shape = shapeKind(o.require("shape"), o.at("shape"));
  if (p.shape == Shape::Kind::Plane) fail(o.at("shape"), "a part cannot be a plane");
  const int n = partSizeCount(p.shape);
  if (p.shape == Shape::Kind::Mesh) {
    o.req("mesh", p.mesh);
    if (p.mesh.empty()) fail(o.at("mesh"), "empty file name");
    p.size[0] = Distribution{};
    p.size[0].mean = 1.0;  // the scale factor
    if (const json* c = o.find("collision")) {
      if (*c == "mesh") {
        p.collision = PartSpec::Collision::Mesh;
      } else if (*c == "convex_hull") {
        p.collision = PartSpec::Collision::ConvexHull;
      } else {
        fail(o.at("collision"), "must be \"mesh\" or \"convex_hull\", got " + describe(*c));
      }
    }
  }
  if (p.shape != Shape::Kind::Mesh && o.find("collision")) {
    fail(o.at("collision"), std::string("only mesh parts choose what they collide as (a ") +
                                toString(p.shape) + " part collides as itself)");
  }
  const json* size = p.shape == Shape::Kind::Mesh ? o.find("size") : &o.require("size");
  if (size) {
    static const char* kMeaning[] = {"", "sphere: radius; mesh: scale", "radius, length",
                                     "x, y, z edges"};
    if (!size->is_array() || static_cast<int>(size->size()) != n) {
      fail(o.at("size"), std::string("a ") + toString(p.shape) + " part needs an array of " +
                             std::to_string(n) + " sizes (" + kMeaning[n] + "), got " +
                             describe(*size));
    }
    for (int d = 0; d < n; ++d)
      read((*size)[d], o.at("size") + "[" + std::to_string(d) + "]", p.size[d]);
  }
  o.opt("density", p.density, Range::Positive);
  o.req("spawn_min", p.spawn_min);
  o.req("spawn_max", p.spawn_max);
  o.opt("random_orientation", p.random_orientation);
  o.opt("count", p.count, 1);
  o.opt("rate", p.rate, Range::NonNegative);
  o.opt("initial_velocity", p.initial_velocity);
  o.finish();
  return p;
}

Scene readScene(const json& root) {
  Object o(root, "");
  Scene s;
  int version = kFormatVersion;
  if (o.opt("format_version", version, 1) && version != kFormatVersion) {
    fail("format_version", "this build reads version " + std::to_string(kFormatVersion) +
                               ", the file is version " + std::to_string(version));
  }
  o.opt("name", s.name);
  o.opt("gravity", s.gravity);
  std::vector<PendingEfficiency> pending;
  if (const json* v = o.find("fixtures")) {
    std::size_t index = 0;
    s.fixtures = readArray<Fixture>(*v, "fixtures", [&](const json& f, const std::string& path) {
      return readFixture(f, path, pending, index++);
    });
  }
  s.parts = readArray<PartSpec>(o.require("parts"), "parts", readPart);
  for (const PendingEfficiency& e : pending) {
    s.fixtures[e.fixture].law.efficiency = readEfficiency(*e.value, e.path, s.parts);
  }
  if (const json* v = o.find("material")) {
    Object m(*v, "material");
    m.opt("mu", s.material.mu, Range::NonNegative);
    m.opt("restitution", s.material.restitution, Range::UnitInterval);
    m.finish();
  }
  if (const json* v = o.find("solver")) {
    Object m(*v, "solver");
    SolverSettings& x = s.solver;
    m.opt("time_step", x.time_step, Range::Positive);
    m.opt("rheonomic_time_step", x.rheonomic_time_step, Range::NonNegative);
    m.opt("iterations", x.iterations, 1);
    m.opt("ode_quickstep", x.ode_quickstep);
    std::string friction;
    if (m.opt("friction", friction)) {
      FrictionModel model;
      if (!parseFrictionModel(friction.c_str(), model)) {
        const std::string typo = closest(friction, {"cone", "pyramid"});
        fail(m.at("friction"), "unknown friction model \"" + friction + "\"" +
                                   (typo.empty() ? "" : " (did you mean \"" + typo + "\"?)") +
                                   "; expected cone or pyramid");
      }
      x.friction = model;
    }
    m.opt("erp", x.erp, Range::UnitInterval);
    m.opt("cfm", x.cfm, Range::NonNegative);
    m.opt("tolerance", x.tolerance, Range::Positive);
    m.opt("apgd", x.apgd);
    m.opt("coulomb_iterations", x.coulomb_iterations, 0);
    m.opt("max_correcting_velocity", x.max_correcting_velocity, Range::Positive);
    m.opt("surface_layer", x.surface_layer, Range::NonNegative);
    bool speculative = true;
    if (m.opt("speculative_contacts", speculative)) x.speculative_contacts = speculative;
    bool warm_start = true;
    if (m.opt("warm_start", warm_start)) x.warm_start = warm_start;
    std::string broad_phase;
    if (m.opt("broad_phase", broad_phase)) {
      if (broad_phase == "hash") {
        x.broad_phase = BroadPhase::Hash;
      } else if (broad_phase == "sweep_and_prune") {
        x.broad_phase = BroadPhase::SweepAndPrune;
      } else {
        const std::string typo = closest(broad_phase, {"hash", "sweep_and_prune"});
        fail(m.at("broad_phase"), "unknown broad phase \"" + broad_phase + "\"" +
                                      (typo.empty() ? "" : " (did you mean \"" + typo + "\"?)") +
                                      "; expected hash or sweep_and_prune");
      }
    }
    m.finish();
  }
  o.opt("duration", s.duration, Range::Positive);
  o.opt("removal_height", s.removal_height);
  o.opt("seed", s.seed);
  if (o.opt("drift_table", s.drift_table) && s.drift_table.empty()) {
    fail(o.at("drift_table"), "empty file name");
  }
  if (const json* v = o.find("outputs")) {
    Object m(*v, "outputs");
    Outputs& x = s.outputs;
    m.opt("conveying_direction", x.conveying_direction, UnitVector{});
    m.opt("angular_drift", x.angular_drift);
    m.opt("axis_origin", x.axis_origin);
    m.opt("axis_direction", x.axis_direction, UnitVector{});
    m.opt("exit_plane", x.exit_plane);
    m.opt("exit_point", x.exit_point);
    m.opt("exit_normal", x.exit_normal, UnitVector{});
    m.opt("sample_interval", x.sample_interval, Range::Positive);
    m.opt("warmup", x.warmup, Range::NonNegative);
    m.finish();
  }
  o.finish();
  return s;
}

// Scene::validate() and drawParts() say "<path> = <value>: <why>" or "<path>: <why>" or
// "<path> <more>: <why>"; split off the path so that the error names it like the parser does.
[[noreturn]] void rethrowWithPath(const std::exception& e) {
  const std::string msg = e.what();
  const std::size_t end = msg.find_first_of(" :");
  if (end == std::string::npos) fail("", msg);
  const std::string path = msg.substr(0, end);
  std::string rest = msg.substr(end);
  if (rest.compare(0, 3, " = ") == 0) {
    const std::size_t colon = rest.find(": ");
    if (colon != std::string::npos) {
      fail(path, rest.substr(colon + 2) + " (got " + rest.substr(3, colon - 3) + ")");
    }
  }
  rest.erase(0, rest.find_first_not_of(" :"));
  fail(path, rest);
}

// Reads the corners of scene.drift_table (relative to `base_dir`) with the shared table's
// settings and makes the name absolute (as the meshes', so that the scene written elsewhere, by
// a sweep or a calibration, still finds it); a refusal names "drift_table" and the table file's
// own error. A file that is not there is noted in scene.drift_table_problem instead (Scene).
void loadSceneDriftTable(Scene& scene, const fs::path& base_dir) {
  fs::path file(scene.drift_table);
  if (file.is_relative()) file = base_dir / file;
  std::error_code ec;
  if (!fs::exists(file, ec) && !fs::is_symlink(file, ec)) {  // a scene copied without its table
    scene.drift_table_problem =
        "drift_table " + file.string() +
        ": file not found, not read (the local law's point-mass model runs fill the table, as "
        "without it; copy the table there, or remove \"drift_table\" from the scene file)";
    return;
  }
  LocalDriftTable table(LocalDriftTable::shared()->settings());
  try {
    loadDriftTable(file, table);
  } catch (const SceneFileError& e) {
    fail("drift_table", std::string(e.what()) +
                            " (the table only saves the local law's point-mass model runs: remove "
                            "\"drift_table\" from the scene file to run without it)");
  }
  scene.drift_table = fs::absolute(file).lexically_normal().string();
  scene.drift_table_corners =
      std::make_shared<const std::vector<DriftTableCorner>>(table.corners());
}

}  // namespace

Scene parseScene(const std::string& json_text, const std::string& source_name,
                 const MeshLoader& mesh_loader) {
  try {
    Scene scene = readScene(parseText(json_text));
    try {
      scene.validate();
    } catch (const std::invalid_argument& e) {
      rethrowWithPath(e);
    }
    if (scene.hasMeshes()) loadSceneMeshes(scene, fs::path(source_name).parent_path(), mesh_loader);
    if (!scene.drift_table.empty()) {
      loadSceneDriftTable(scene, fs::path(source_name).parent_path());
    }
    try {
      (void)drawParts(scene);  // refuses spawn regions too small for the parts
    } catch (const std::invalid_argument& e) {
      rethrowWithPath(e);
    }
    return scene;
  } catch (const SceneFileError& e) {
    throw SceneFileError(source_name, e.path(), e.problem(), e.line(), e.column());
  }
}

Scene loadScene(const fs::path& file, const MeshLoader& mesh_loader) {
  // Kind and size first, from stat: a FIFO, a device or a directory is never opened.
  const std::string problem = limits::regularFileProblem(file, limits::kMaxSceneFileBytes);
  if (!problem.empty()) throw SceneFileError(file.string(), "", problem);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw SceneFileError(file.string(), "", "cannot open the file for reading");
  // Read at most one byte past the cap: a file that grew since stat is still bounded.
  std::error_code ec;
  const std::uintmax_t expected = fs::file_size(file, ec);
  std::string text(static_cast<std::size_t>(std::min(expected, limits::kMaxSceneFileBytes)) + 1,
                   '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw SceneFileError(file.string(), "", "cannot read the file");
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > limits::kMaxSceneFileBytes) {
    throw SceneFileError(file.string(), "",
                         "the file grew beyond " + std::to_string(limits::kMaxSceneFileBytes) +
                             " bytes while being read");
  }
  if (text.empty()) throw SceneFileError(file.string(), "", "the file is empty");
  Scene scene = parseScene(text, file.string(), mesh_loader);
  scene.source_file = fs::absolute(file, ec).lexically_normal().string();
  return scene;
}

}  // namespace rheofeed::scene
