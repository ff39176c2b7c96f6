// SPDX-License-Identifier: MIT
// What a calibration was measured for (CalibrationBasis, scene.hpp), and whether a scene still
// fits it (staleCalibration): the feeder's vibration, gravity and friction, the direction the
// drift is measured along, and for a sample run the parts and the fixtures' geometry it ran.
#include <algorithm>
#include <charconv>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "rheofeed/number_format.hpp"
#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {
namespace {

// A canonical text of the values a digest covers, hashed with 64-bit FNV-1a. Numbers are
// written to 9 significant digits and values below 1e-12 in magnitude as 0, the tolerance
// staleCalibration allows a number: a rotation computed again from the same angle, or read
// back from a file, gives the same digest.
class Digest {
 public:
  Digest& operator<<(double x) {
    char text[32];
    if (!(std::abs(x) >= 1e-12)) x = 0;  // also -0; NaN cannot reach a validated scene
    // std::to_chars: the same text under any C locale (snprintf would write "0,5" in some)
    const auto end = std::to_chars(text, text + sizeof text - 1, x, std::chars_format::general, 9);
    *end.ptr = ';';
    return *this << std::string(text, end.ptr + 1);
  }
  Digest& operator<<(int x) { return *this << static_cast<double>(x); }
  Digest& operator<<(const Vec3& x) { return *this << x.x << x.y << x.z; }
  Digest& operator<<(const std::string& text) {
    for (const unsigned char c : text) {
      hash_ ^= c;
      hash_ *= 0x100000001b3ULL;
    }
    return *this;
  }
  Digest& operator<<(const char* text) { return *this << std::string(text) << std::string(";"); }
  Digest& operator<<(const TriangleMesh* mesh) {
    if (!mesh) return *this << "no mesh";
    *this << static_cast<int>(mesh->vertices.size()) << static_cast<int>(mesh->triangles.size());
    for (const double v : mesh->vertices) *this << v;
    for (const int t : mesh->triangles) *this << t;
    return *this;
  }
  std::string hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016" PRIx64, hash_);
    return text;
  }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

bool isScrew(const Vibration& v) {
  return v.torsion_amplitude != 0;
}

}  // namespace

std::string partDigest(const PartSpec& p) {
  Digest d;
  d << toString(p.shape);
  for (const Distribution& s : p.size) d << s.mean << s.stddev << s.min << s.max;
  d << p.mesh_data.get() << (p.collision == PartSpec::Collision::ConvexHull ? "hull" : "mesh");
  d << p.density << p.spawn_min << p.spawn_max << (p.random_orientation ? "random" : "fixed")
    << p.initial_velocity;
  return d.hex();
}

std::string fixtureDigest(const Fixture& f) {
  Digest d;
  d << static_cast<int>(f.geoms.size());
  for (const Fixture::Geom& g : f.geoms) {
    d << toString(g.shape.kind) << g.pose.position;
    for (const double r : g.pose.rotation) d << r;
    switch (g.shape.kind) {
      case Shape::Kind::Box:
        d << g.shape.size;
        break;
      case Shape::Kind::Sphere:
        d << g.shape.radius;
        break;
      case Shape::Kind::Cylinder:
      case Shape::Kind::Capsule:
        d << g.shape.radius << g.shape.length;
        break;
      case Shape::Kind::Plane:
        d << g.shape.plane_normal << g.shape.plane_offset;
        break;
      case Shape::Kind::Mesh:
        d << g.shape.mesh_data.get();
        break;
    }
  }
  return d.hex();
}

CalibrationBasis calibrationBasis(const Scene& scene, int fixture, const std::string& method) {
  const FeederLaw& law = scene.fixtures.at(static_cast<std::size_t>(fixture)).law;
  CalibrationBasis basis;
  basis.vibration = law.vibration;
  basis.gravity = scene.gravity;
  basis.mu = scene.material.mu;
  basis.method = method;
  const bool screw = isScrew(law.vibration);
  // A screw's drift is a rotation about its axis; a straight track's points along this.
  if (!screw) basis.conveying_direction = scene.outputs.conveying_direction;
  if (method == "classical" && screw && !scene.parts.empty()) {
    basis.track_point = 0.5 * (scene.parts[0].spawn_min + scene.parts[0].spawn_max);
  }
  if (method == "sampling") {
    basis.restitution = scene.material.restitution;
    for (const PartSpec& p : scene.parts) basis.part_digests.push_back(partDigest(p));
    for (const Fixture& f : scene.fixtures) basis.fixture_digests.push_back(fixtureDigest(f));
  }
  return basis;
}

std::string staleCalibration(const Scene& scene, int fixture) {
  const FeederLaw& law = scene.fixtures.at(static_cast<std::size_t>(fixture)).law;
  if (law.kind != FeederLaw::Kind::Vibration || law.drift_model == DriftModel::Local ||
      lacksCalibration(law) || !law.calibrated_for) {
    return "";
  }
  const CalibrationBasis& was = *law.calibrated_for;
  const Vibration& v = law.vibration;
  std::string feeder, parts;  // what changed: of the feeder and its track; of the parts
  // Equal within rounding (1e-9 relative, 1e-12 absolute: a hand-written angle_deg 90 against
  // [0, 0, 1], -0 against 0) is no change; an edit of the scene is.
  const auto close = [](double x, double y) {
    return std::abs(x - y) <= 1e-9 * std::max(std::abs(x), std::abs(y)) + 1e-12;
  };
  const auto note = [](std::string& list, const std::string& what, const std::string& then,
                       const std::string& now) {
    list += (list.empty() ? "" : ", ") + what + " " + then + " when calibrated, " + now + " now";
  };
  const auto number = [&](std::string& list, const char* what, double then, double now) {
    if (!close(then, now)) note(list, what, formatNumber(then), formatNumber(now));
  };
  const auto vector = [&](const char* what, const Vec3& then, const Vec3& now) {
    const auto text = [](const Vec3& x) {
      return "[" + formatNumber(x.x) + ", " + formatNumber(x.y) + ", " + formatNumber(x.z) + "]";
    };
    if (!close(then.x, now.x) || !close(then.y, now.y) || !close(then.z, now.z)) {
      note(feeder, what, text(then), text(now));
    }
  };
  number(feeder, "amplitude (m)", was.vibration.amplitude, v.amplitude);
  number(feeder, "frequency (Hz)", was.vibration.frequency, v.frequency);
  // A direction without a translation, an axis without a torsion, moves nothing.
  if (was.vibration.amplitude != 0 || v.amplitude != 0) {
    vector("direction", was.vibration.direction, v.direction);
  }
  number(feeder, "torsion amplitude (rad)", was.vibration.torsion_amplitude, v.torsion_amplitude);
  if (was.vibration.torsion_amplitude != 0 || v.torsion_amplitude != 0) {
    vector("axis origin (m)", was.vibration.axis_origin, v.axis_origin);
    vector("axis direction", was.vibration.axis_direction, v.axis_direction);
  }
  vector("gravity (m/s^2)", was.gravity, scene.gravity);
  number(feeder, "mu", was.mu, scene.material.mu);
  // The parts of the basis that a calibration records where they matter (calibrationBasis);
  // a file written before they were kept has none, and they are not compared.
  if (was.conveying_direction && !isScrew(v)) {
    vector("conveying direction", *was.conveying_direction, scene.outputs.conveying_direction);
  }
  if (was.track_point && isScrew(v) && !scene.parts.empty()) {
    // The model takes the track at the point's distance from the axis (its vibration there);
    // a point moved round the axis or along it is the same track.
    // That holds where the translation and gravity lie along the axis (a bowl's screw); with
    // either tilted the track's place round the axis matters too, and the point is compared.
    const Vec3 now = 0.5 * (scene.parts[0].spawn_min + scene.parts[0].spawn_max);
    const auto along_axis = [&v](const Vec3& x) {
      return norm(cross(x, v.axis_direction)) <= 1e-9 * norm(x);
    };
    if ((v.amplitude == 0 || along_axis(v.direction)) && along_axis(scene.gravity)) {
      const auto radius = [&v](const Vec3& point) {
        return norm(tangentialPart(point - v.axis_origin, v.axis_direction));
      };
      number(feeder, "track radius (m, the first part family's spawn centre from the axis)",
             radius(*was.track_point), radius(now));
    } else {
      vector("track point (m, the first part family's spawn centre)", *was.track_point, now);
    }
  }
  if (was.restitution) number(feeder, "restitution", *was.restitution, scene.material.restitution);
  // Each fixture's geometry: the sample run's parts may meet any of them.
  if (!was.fixture_digests.empty()) {
    if (was.fixture_digests.size() != scene.fixtures.size()) {
      note(feeder, "the number of fixtures", std::to_string(was.fixture_digests.size()),
           std::to_string(scene.fixtures.size()));
    } else {
      for (std::size_t i = 0; i < scene.fixtures.size(); ++i) {
        const std::string now = fixtureDigest(scene.fixtures[i]);
        if (was.fixture_digests[i] != now) {
          note(feeder,
               "fixture '" + scene.fixtures[i].name +
                   "' (the digest of its geoms' shapes, sizes "
                   "and poses)",
               was.fixture_digests[i], now);
        }
      }
    }
  }
  // The part families the calibration sampled: a calibrated drift the first (the sample run's
  // only family), efficiency factors each their own. "" marks a family whose factor this record
  // has not measured (withEfficiency, after a change of the feeder).
  if (!was.part_digests.empty() && !scene.parts.empty()) {
    const bool drift = law.drift_model == DriftModel::CalibratedDrift;
    const std::size_t families = drift ? 1 : scene.parts.size();
    if (!drift && was.part_digests.size() != scene.parts.size()) {
      note(parts, "the number of part families", std::to_string(was.part_digests.size()),
           std::to_string(scene.parts.size()));
    } else {
      for (std::size_t k = 0; k < families; ++k) {
        const std::string now = partDigest(scene.parts[k]);
        const std::string& then = was.part_digests[k];
        const std::string family = "parts[" + std::to_string(k) + "] '" + scene.parts[k].name + "'";
        if (then.empty()) {
          parts += (parts.empty() ? "" : ", ") + family +
                   (drift ? " (not recorded)"
                          : " (its factor is not one this record measured: calibrate every "
                            "family)");
        } else if (then != now) {
          note(parts,
               family +
                   " (the digest of its shape, sizes, mesh, density, spawn region, orientation "
                   "and initial velocity)",
               then, now);
        }
      }
    }
  }
  if (feeder.empty() && parts.empty()) return "";
  const std::string what = !parts.empty() && feeder.empty() ? "with other parts: "
                           : parts.empty()                  ? "for another feeder: "
                                                            : "for another feeder and parts: ";
  return std::string("its ") +
         (law.drift_model == DriftModel::CalibratedDrift ? "calibrated drift was"
                                                         : "part efficiency factors were") +
         " measured " + what + feeder + (feeder.empty() || parts.empty() ? "" : ", ") + parts;
}

bool uncheckedCalibration(const FeederLaw& law) {
  return law.kind == FeederLaw::Kind::Vibration && law.drift_model != DriftModel::Local &&
         !lacksCalibration(law) && !law.calibrated_for;
}

std::string missingDigests(const FeederLaw& law) {
  if (law.kind != FeederLaw::Kind::Vibration || law.drift_model == DriftModel::Local ||
      lacksCalibration(law) || !law.calibrated_for) {
    return "";
  }
  const CalibrationBasis& was = *law.calibrated_for;
  // A classical calibrated drift depends on neither; efficiency factors are always sampled.
  if (was.method == "classical" && law.drift_model == DriftModel::CalibratedDrift) return "";
  const bool parts = was.part_digests.empty(), fixtures = was.fixture_digests.empty();
  return parts && fixtures ? "part or fixture" : parts ? "part" : fixtures ? "fixture" : "";
}

}  // namespace rheofeed::scene
