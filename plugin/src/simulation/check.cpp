// SPDX-License-Identifier: MIT
// The scene check before the run (check.hpp). Every criterion is stated next to its code; the
// mass-ratio limits are measured, and the command that measures them is given with the table.
#include "rheofeed/simulation/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "rheofeed/scene/mesh.hpp"
#include "rheofeed/scene/run_step.hpp"
#include "simulation_internal.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
// A size distribution is taken to reach mean +- 5 standard deviations (within min/max): a
// draw lies beyond with probability 5.7e-7, once in 580 scenes of 1000 boxes.
constexpr double kSigmas = 5;
// Two faces closer than this (m) are one seam for the flush-wall check, whatever the parts.
constexpr double kSeamTolerance = 1e-6;
// A box edge counts as upright when its direction is within this of the up direction (cosine).
constexpr double kUprightCosine = 1 - 1e-9;

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}
std::string mm(double metres) {
  return fmt(1000 * metres) + " mm";
}
std::string idx(const char* base, std::size_t i) {
  return base + ("[" + std::to_string(i) + "]");
}
std::string geomPath(std::size_t f, std::size_t g) {
  return idx("fixtures", f) + "." + idx("geoms", g);
}

// Axis-aligned bounding box (world) of a fixture geom; planes are unbounded.
struct Box3 {
  Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  bool bounded = true;
  void add(const Vec3& p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
};

// Bounding box of a fixture geom at its pose (the scene limits' computation); a plane or a mesh
// not loaded is unbounded.
Box3 geomBounds(const Fixture::Geom& g) {
  const Bounds bounds = fixtureGeomBounds(g);
  Box3 b;
  if (bounds.min.x > bounds.max.x) {
    b.bounded = false;
  } else {
    b.add(bounds.min);
    b.add(bounds.max);
  }
  return b;
}

// Heights along `up` of a box's extremes.
double maxAlong(const Box3& b, const Vec3& up) {
  return std::max(b.lo.x * up.x, b.hi.x * up.x) + std::max(b.lo.y * up.y, b.hi.y * up.y) +
         std::max(b.lo.z * up.z, b.hi.z * up.z);
}
double minAlong(const Box3& b, const Vec3& up) {
  return -maxAlong(b, -up);
}

// Wall thickness of a closed triangle mesh (m): from the centroid of every triangle a ray goes
// inwards (against the outward normal); the nearest other triangle it meets is the wall's far
// side there. Returned: the thickness below which lies kThinShare of the surface area, not
// the minimum, which a vanishing wedge (the start of a ramp that rises from a floor) takes to
// zero, and which overlapping shells make the overlap (demos/meshes/vibratory_bowl.stl: its
// ramp overlaps the wall by 1 mm over 2 % of the area; its thinnest real wall, the 4 mm ramp,
// is 19 %). A crude estimate: a thin wall covering less than 5 % of a mesh is not seen.
// O(n^2) in the triangles: 3000 triangles take about 0.1 s.
constexpr double kThinShare = 0.05;
double meshWallThickness(const TriangleMesh& mesh, double scale) {
  const std::vector<double>& v = mesh.vertices;
  const std::vector<int>& t = mesh.triangles;
  auto vert = [&](int i) { return scale * Vec3{v[3 * i], v[3 * i + 1], v[3 * i + 2]}; };
  const std::size_t n = t.size() / 3;
  std::vector<std::pair<double, double>> walls;  // thickness, area
  double total_area = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 a = vert(t[3 * i]), b = vert(t[3 * i + 1]), c = vert(t[3 * i + 2]);
    const Vec3 normal = cross(b - a, c - a);
    const double area2 = norm(normal);
    if (!(area2 > 0)) continue;
    const Vec3 dir = (-1.0 / area2) * normal;  // inwards
    const Vec3 origin = (1.0 / 3.0) * (a + b + c);
    double nearest = kInf;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      // Moller-Trumbore ray/triangle intersection.
      const Vec3 p = vert(t[3 * j]), q = vert(t[3 * j + 1]), r = vert(t[3 * j + 2]);
      const Vec3 e1 = q - p, e2 = r - p, pv = cross(dir, e2);
      const double det = dot(e1, pv);
      if (std::abs(det) < 1e-30) continue;
      const Vec3 tv = origin - p;
      const double u = dot(tv, pv) / det;
      if (u < 0 || u > 1) continue;
      const Vec3 qv = cross(tv, e1);
      const double w = dot(dir, qv) / det;
      if (w < 0 || u + w > 1) continue;
      const double dist = dot(e2, qv) / det;
      if (dist > 1e-9 * std::sqrt(area2)) nearest = std::min(nearest, dist);
    }
    total_area += 0.5 * area2;
    if (std::isfinite(nearest)) walls.emplace_back(nearest, 0.5 * area2);
  }
  std::sort(walls.begin(), walls.end());
  double area = 0;
  for (const auto& [thickness, a] : walls) {
    area += a;
    if (area >= kThinShare * total_area) return thickness;
  }
  return walls.empty() ? 0 : walls.back().first;
}

// Smallest extent of a mesh's bounding box in its own frame, times `scale` (m).
double meshBoxExtent(const TriangleMesh& mesh, double scale) {
  Box3 b;
  for (std::size_t k = 0; k + 2 < mesh.vertices.size(); k += 3) {
    b.add({mesh.vertices[k], mesh.vertices[k + 1], mesh.vertices[k + 2]});
  }
  const Vec3 e = b.hi - b.lo;
  return scale * std::min({e.x, e.y, e.z});
}

// Thickness of a fixture geom (m): the smallest distance across it. Planes are half-spaces.
struct Thickness {
  double value = kInf;
  std::string note;
};
Thickness fixtureThickness(const Shape& s) {
  switch (s.kind) {
    case Shape::Kind::Box:
      return {std::min({s.size.x, s.size.y, s.size.z}), ""};
    case Shape::Kind::Sphere:
    case Shape::Kind::Capsule:
      return {2 * s.radius, ""};
    case Shape::Kind::Cylinder:
      return {std::min(2 * s.radius, s.length), ""};
    case Shape::Kind::Plane:
      return {kInf, ""};
    case Shape::Kind::Mesh:
      if (!s.mesh_data) return {0, " (mesh not loaded: counted as a surface of no thickness)"};
      return {meshWallThickness(*s.mesh_data, 1.0),
              " (mesh wall: 5 % of its area is thinner, by ray casting; a crude estimate)"};
  }
  return {};
}

// Range of a size distribution that drawParts can return (m).
double sizeLow(const Distribution& d) {
  return d.stddev > 0 ? std::max({d.min, d.mean - kSigmas * d.stddev, 1e-3 * d.mean}) : d.mean;
}
double sizeHigh(const Distribution& d) {
  return d.stddev > 0 ? std::min(d.max, d.mean + kSigmas * d.stddev) : d.mean;
}

// Mass (kg) and smallest thickness (m) of a part of family `p` with sizes `sz`.
struct PartExtreme {
  double mass = 0, thickness = 0;
  double size = 0;  // largest extent (m); a mesh part: its smallest bounding-box extent
};
PartExtreme partExtreme(const PartSpec& p, const double sz[3], std::string* note) {
  const double rho = p.density;
  switch (p.shape) {
    case Shape::Kind::Box:
      return {rho * sz[0] * sz[1] * sz[2], std::min({sz[0], sz[1], sz[2]}),
              std::max({sz[0], sz[1], sz[2]})};
    case Shape::Kind::Sphere:
      return {rho * 4.0 / 3.0 * kPi * std::pow(sz[0], 3), 2 * sz[0], 2 * sz[0]};
    case Shape::Kind::Cylinder:
      return {rho * kPi * sz[0] * sz[0] * sz[1], std::min(2 * sz[0], sz[1]),
              std::max(2 * sz[0], sz[1])};
    case Shape::Kind::Capsule:
      return {rho * kPi * sz[0] * sz[0] * (sz[1] + 4.0 / 3.0 * sz[0]), 2 * sz[0],
              sz[1] + 2 * sz[0]};
    case Shape::Kind::Mesh: {
      if (!p.mesh_data) {
        if (note) *note = " (mesh part not loaded: its mass and thickness are unknown)";
        return {0, 0, 0};
      }
      if (note) *note = " (mesh part: smallest bounding-box extent, an upper bound)";
      const double extent = meshBoxExtent(*p.mesh_data, sz[0]);
      return {massProperties(*p.mesh_data, rho).mass * std::pow(sz[0], 3), extent, extent};
    }
    case Shape::Kind::Plane:
      break;
  }
  return {};
}

struct PartRange {
  PartExtreme light, heavy;  // the lightest and heaviest parts of the family
  double thinnest = 0;       // smallest thickness of any part of the family (m)
  std::string note;
};
PartRange partRange(const PartSpec& p) {
  const int n = partSizeCount(p.shape);
  double lo[3], hi[3];
  for (int d = 0; d < 3; ++d) {
    lo[d] = d < n ? sizeLow(p.size[d]) : 0;
    hi[d] = d < n ? sizeHigh(p.size[d]) : 0;
  }
  PartRange r;
  r.light = partExtreme(p, lo, &r.note);
  r.heavy = partExtreme(p, hi, nullptr);
  // The thinnest part: every size at its low end but a cylinder's length (min(2r, L)) is
  // also lowest there, so the light part is the thinnest.
  r.thinnest = r.light.thickness;
  return r;
}

// 2D overlap area test of two upright boxes projected on the plane normal to `up`
// (separating axes: the boxes' in-plane edges).
bool planOverlap(const Fixture::Geom& a, const Fixture::Geom& b, const Vec3& up) {
  auto axes = [&](const Fixture::Geom& g, Vec3 out[3], double half[3]) {
    const double* r = g.pose.rotation;
    const double size[3] = {g.shape.size.x, g.shape.size.y, g.shape.size.z};
    for (int c = 0; c < 3; ++c) {
      out[c] = {r[c], r[3 + c], r[6 + c]};
      half[c] = 0.5 * size[c];
    }
  };
  Vec3 ax[3], bx[3];
  double ah[3], bh[3];
  axes(a, ax, ah);
  axes(b, bx, bh);
  auto radius = [&](const Vec3 e[3], const double h[3], const Vec3& dir) {
    double s = 0;
    for (int c = 0; c < 3; ++c) {
      if (std::abs(dot(e[c], up)) < kUprightCosine) s += h[c] * std::abs(dot(e[c], dir));
    }
    return s;
  };
  const Vec3 d = b.pose.position - a.pose.position;
  for (const Vec3* set : {ax, bx}) {
    for (int c = 0; c < 3; ++c) {
      if (std::abs(dot(set[c], up)) >= kUprightCosine) continue;
      const double gap = std::abs(dot(d, set[c])) - radius(ax, ah, set[c]) - radius(bx, bh, set[c]);
      if (gap >= -kSeamTolerance) return false;  // touching edges are no overlap
    }
  }
  return true;
}

bool upright(const Fixture::Geom& g, const Vec3& up) {
  if (g.shape.kind != Shape::Kind::Box) return false;
  const double* r = g.pose.rotation;
  for (int c = 0; c < 3; ++c) {
    if (std::abs(r[c] * up.x + r[3 + c] * up.y + r[6 + c] * up.z) >= kUprightCosine) return true;
  }
  return false;
}

// Whether the axis-aligned region [lo, hi] (world) reaches into a fixture geom.
bool regionInsideGeom(const Vec3& lo, const Vec3& hi, const Fixture::Geom& g) {
  const Shape& s = g.shape;
  if (s.kind == Shape::Kind::Plane) {
    double lowest = kInf;  // the region's corner deepest below the plane
    for (int c = 0; c < 8; ++c) {
      const Vec3 p{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
      lowest = std::min(lowest, dot(s.plane_normal, p) - s.plane_offset);
    }
    return lowest < 0;
  }
  if (s.kind == Shape::Kind::Mesh) return false;  // hollow in general: not checked
  if (s.kind == Shape::Kind::Sphere) {
    const Vec3 c = g.pose.position;
    const Vec3 nearest{std::clamp(c.x, lo.x, hi.x), std::clamp(c.y, lo.y, hi.y),
                       std::clamp(c.z, lo.z, hi.z)};
    return norm(nearest - c) < s.radius;
  }
  const Box3 b = geomBounds(g);
  const bool aabb = lo.x < b.hi.x && hi.x > b.lo.x && lo.y < b.hi.y && hi.y > b.lo.y &&
                    lo.z < b.hi.z && hi.z > b.lo.z;
  if (!aabb || s.kind != Shape::Kind::Box) return aabb;  // cylinder, capsule: bounding box
  // Box: separating axes of two boxes (the region's 3, the geom's 3, their 9 cross products).
  const double* r = g.pose.rotation;
  const Vec3 ge[3] = {{r[0], r[3], r[6]}, {r[1], r[4], r[7]}, {r[2], r[5], r[8]}};
  const double gh[3] = {0.5 * s.size.x, 0.5 * s.size.y, 0.5 * s.size.z};
  const Vec3 re[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const double rh[3] = {0.5 * (hi.x - lo.x), 0.5 * (hi.y - lo.y), 0.5 * (hi.z - lo.z)};
  const Vec3 d = g.pose.position - 0.5 * (lo + hi);
  auto separated = [&](const Vec3& axis) {
    if (!(norm(axis) > 1e-12)) return false;
    double ra = 0, rb = 0;
    for (int c = 0; c < 3; ++c) {
      ra += rh[c] * std::abs(dot(re[c], axis));
      rb += gh[c] * std::abs(dot(ge[c], axis));
    }
    return std::abs(dot(d, axis)) >= ra + rb;
  };
  for (int i = 0; i < 3; ++i) {
    if (separated(re[i]) || separated(ge[i])) return false;
    for (int j = 0; j < 3; ++j) {
      if (separated(cross(re[i], ge[j]))) return false;
    }
  }
  return true;
}

// Largest surface speed of a drift twist over a box (m/s): |v + w x (c - O)| is convex in c,
// so its maximum over the box is at a corner.
double twistSpeedOver(const Twist& t, const Box3& b) {
  double fastest = norm(t.linear);
  if (!b.bounded) return isZero(t.angular) ? fastest : kInf;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z};
    fastest = std::max(fastest, norm(t.linear + cross(t.angular, p - t.origin)));
  }
  return fastest;
}

// Largest distance of a box's corners from an axis (m).
double radiusFromAxis(const Box3& b, const Vec3& origin, const Vec3& axis) {
  double r = 0;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z};
    r = std::max(r, norm(cross(axis, p - origin)));
  }
  return r;
}

}  // namespace

const char* toString(Hazard::Kind kind) {
  switch (kind) {
    case Hazard::Kind::Tunnelling:
      return "tunnelling";
    case Hazard::Kind::FlushWall:
      return "flush_wall";
    case Hazard::Kind::MassRatio:
      return "mass_ratio";
    case Hazard::Kind::CoarseVibrationStep:
      return "coarse_vibration_step";
    case Hazard::Kind::SpawnInsideFixture:
      return "spawn_inside_fixture";
    case Hazard::Kind::SpawnBelowRemoval:
      return "spawn_below_removal";
    case Hazard::Kind::SpawnStreamOverlap:
      return "spawn_stream_overlap";
    case Hazard::Kind::WeakCollider:
      return "weak_collider";
    case Hazard::Kind::HighRestitution:
      return "high_restitution";
    case Hazard::Kind::IgnoredSetting:
      return "ignored_setting";
  }
  return "unknown";
}

std::vector<Hazard> checkScene(const Scene& scene, Method method) {
  std::vector<Hazard> out;
  const double h = scene.solver.time_step;
  const double g = norm(scene.gravity);
  const Vec3 up = g > 0 ? (-1.0 / g) * scene.gravity : Vec3{0, 0, 1};
  const bool full = isFullVibration(method);
  const bool ode = method == Method::OdeRheonomic || method == Method::OdeFullVibration;
  // The scene field that sets this method's step (the time step rule, run_step.hpp).
  const std::string step_field = stepField(scene, method);

  // Parts: the thinnest, the lightest and the heaviest over all families.
  double thinnest_part = kInf, lightest = kInf, heaviest = 0, light_thickness = kInf;
  std::size_t thin_family = 0, light_family = 0, heavy_family = 0;
  std::string part_note;
  int total_parts = 0;
  for (std::size_t i = 0; i < scene.parts.size(); ++i) {
    const PartRange r = partRange(scene.parts[i]);
    total_parts += scene.parts[i].count;
    if (r.thinnest < thinnest_part) {
      thinnest_part = r.thinnest;
      thin_family = i;
      part_note = r.note;
    }
    if (r.light.mass > 0 && r.light.mass < lightest) {
      lightest = r.light.mass;
      light_thickness = r.light.thickness;
      light_family = i;
    }
    if (r.heavy.mass > heaviest) {
      heaviest = r.heavy.mass;
      heavy_family = i;
    }
  }

  // Fixtures: bounds, the thinnest geom, the lowest top, the fastest surface.
  struct GeomInfo {
    std::size_t f, g;
    Box3 bounds;
  };
  std::vector<GeomInfo> geoms;
  double thinnest_fixture = kInf, lowest_top = kInf;
  std::string thin_geom, fixture_note;
  double surface_speed = 0;
  std::string speed_source = "nothing moves";
  for (std::size_t f = 0; f < scene.fixtures.size(); ++f) {
    const Fixture& fx = scene.fixtures[f];
    Box3 all;
    for (std::size_t k = 0; k < fx.geoms.size(); ++k) {
      const Fixture::Geom& gm = fx.geoms[k];
      const Box3 b = geomBounds(gm);
      geoms.push_back({f, k, b});
      if (b.bounded) {
        all.add(b.lo);
        all.add(b.hi);
        lowest_top = std::min(lowest_top, maxAlong(b, up));
      } else {
        all.bounded = false;
        if (gm.shape.kind == Shape::Kind::Plane && dot(gm.shape.plane_normal, up) > 0.5) {
          lowest_top = std::min(lowest_top, gm.shape.plane_offset / dot(gm.shape.plane_normal, up));
        }
      }
      const Thickness t = fixtureThickness(gm.shape);
      if (t.value < thinnest_fixture) {
        thinnest_fixture = t.value;
        thin_geom = geomPath(f, k);
        fixture_note = t.note;
      }
    }
    const FeederLaw& law = fx.law;
    double speed = 0;
    std::string source;
    switch (law.kind) {
      case FeederLaw::Kind::None:
        break;
      case FeederLaw::Kind::Belt:
        speed = std::abs(law.belt_speed);
        source = idx("fixtures", f) + ".law.belt.speed";
        break;
      case FeederLaw::Kind::Drift:
        speed = twistSpeedOver(law.drift, all);
        source = idx("fixtures", f) + ".law.drift (over the fixture's extent)";
        break;
      case FeederLaw::Kind::Vibration: {
        const Vibration& v = law.vibration;
        if (full || law.drift_model != DriftModel::CalibratedDrift) {
          // A point mass's cycle-averaged drift stays below the vibration's peak velocity at
          // its point; the local law multiplies it by the part family's efficiency.
          const double w = 2 * kPi * v.frequency;
          const double r = all.bounded ? radiusFromAxis(all, v.axis_origin, v.axis_direction) : 0;
          double factor = 1;
          if (!full) {
            for (double e : law.efficiency) factor = std::max(factor, e);
          }
          speed = factor * (w * v.amplitude + w * v.torsion_amplitude * r);
          source = idx("fixtures", f) + ".law.vibration (peak velocity 2 pi f (A + theta r)" +
                   (factor > 1 ? " times the largest efficiency factor)" : ")");
        } else if (law.has_calibrated_drift) {
          speed = twistSpeedOver(law.calibrated_drift, all);
          source = idx("fixtures", f) + ".law.calibrated_drift (over the fixture's extent)";
        }
        break;
      }
    }
    if (speed > surface_speed) {
      surface_speed = speed;
      speed_source = source;
    }
  }

  // --- 1. Tunnelling -------------------------------------------------------------------------
  {
    // A part spawned at rest first lands on the highest fixture top under its spawn region (in
    // plan, with gravity along z); only where nothing is under it does it fall to the lowest
    // top (parts that later fall off an edge onto a catch floor are out of the feeder).
    const bool vertical = std::abs(up.z) > 0.99;
    double fall = 0, launch = 0;
    std::size_t high_family = 0, launch_family = 0;
    for (std::size_t i = 0; i < scene.parts.size(); ++i) {
      const PartSpec& p = scene.parts[i];
      Box3 region;
      region.add(p.spawn_min);
      region.add(p.spawn_max);
      const double top = maxAlong(region, up);
      double landing = lowest_top;
      if (vertical) {
        double under = -kInf;
        for (const GeomInfo& gi : geoms) {
          if (!gi.bounds.bounded) continue;
          const Box3& b = gi.bounds;
          const bool overlaps = b.lo.x <= region.hi.x && b.hi.x >= region.lo.x &&
                                b.lo.y <= region.hi.y && b.hi.y >= region.lo.y;
          const double geom_top = maxAlong(b, up);
          if (overlaps && geom_top <= top) under = std::max(under, geom_top);
        }
        if (std::isfinite(under)) landing = std::max(under, lowest_top);
      }
      const double drop = std::isfinite(landing) ? std::max(0.0, top - landing) : 0;
      if (drop > fall) {
        fall = drop;
        high_family = i;
      }
      if (norm(p.initial_velocity) > launch) {
        launch = norm(p.initial_velocity);
        launch_family = i;
      }
    }
    const double fall_speed = std::sqrt(2 * g * fall);
    double speed = fall_speed;
    std::string source = "free fall of " + mm(fall) + " from " + idx("parts", high_family) +
                         ".spawn_max to the fixture top under it";
    if (surface_speed > speed) {
      speed = surface_speed;
      source = speed_source;
    }
    if (launch > speed) {
      speed = launch;
      source = idx("parts", launch_family) + ".initial_velocity";
    }
    // Semi-implicit Euler: x+ = x + h (v + g h), so one step moves a part by h (v + g h).
    const double travel = h * (speed + g * h);
    // The centre of a part of thickness t pressed into a geom of thickness T crosses the
    // geom's mid-surface at a penetration of (T + t) / 2; the collider's least-penetration
    // normal then points out of the far side. Parts against parts: T = t.
    const double across = std::min(thinnest_fixture, thinnest_part);
    const double allowed = 0.5 * (across + thinnest_part);
    if (std::isfinite(allowed) && travel > allowed) {
      Hazard hz;
      hz.kind = Hazard::Kind::Tunnelling;
      hz.value = travel;
      hz.limit = allowed;
      const bool fixture_thinner = thinnest_fixture <= thinnest_part;
      hz.where = step_field + ", " + idx("parts", thin_family) + ".size" +
                 (fixture_thinner ? ", " + thin_geom : "");
      std::ostringstream m;
      m << "a part at the expected speed " << fmt(speed) << " m/s (" << source
        << ") moves h (v + g h) = " << mm(travel) << " per step of " << fmt(h)
        << " s, more than half the summed thickness of the thinnest "
        << (fixture_thinner
                ? "fixture geom " + thin_geom + " (" + mm(thinnest_fixture) + ")" + fixture_note
                : std::string("part as obstacle"))
        << " and the thinnest part " << idx("parts", thin_family) << " (" << mm(thinnest_part)
        << ")" << part_note << ": " << mm(allowed) << "; parts can pass through";
      hz.message = m.str();
      // Largest h with h (v + g h) <= allowed.
      const double safe_h =
          g > 0 ? (-speed + std::sqrt(speed * speed + 4 * g * allowed)) / (2 * g) : allowed / speed;
      std::ostringstream s;
      s << step_field << " <= " << fmt(safe_h) << " s";
      if (fixture_thinner) {
        s << ", or make " << thin_geom << " at least "
          << mm(std::max(0.0, 2 * travel - thinnest_part)) << " thick";
      }
      if (source.rfind("free fall", 0) == 0) s << ", or spawn the parts lower";
      hz.safe_setting = s.str();
      out.push_back(hz);
    }
  }

  // --- 2. Walls that end flush with a floor ---------------------------------------------------
  if (std::isfinite(thinnest_part)) {
    for (const GeomInfo& wall : geoms) {
      const Fixture::Geom& wg = scene.fixtures[wall.f].geoms[wall.g];
      if (!upright(wg, up)) continue;
      const double bottom = minAlong(wall.bounds, up);
      for (const GeomInfo& floor : geoms) {
        if (&floor == &wall) continue;
        const Fixture::Geom& fg = scene.fixtures[floor.f].geoms[floor.g];
        if (!upright(fg, up)) continue;
        const double top = maxAlong(floor.bounds, up);
        const double floor_bottom = minAlong(floor.bounds, up);
        // The wall stands on the floor: its bottom within one thinnest part of the floor's top
        // (sunk less than that, or above it by less than that), it rises above the floor and
        // it does not start below the floor's bottom.
        const double gap = bottom - top;  // > 0: open above the floor, < 0: sunk
        if (!(gap > -thinnest_part + kSeamTolerance && gap < thinnest_part)) continue;
        if (maxAlong(wall.bounds, up) <= top || bottom <= floor_bottom) continue;
        if (!planOverlap(wg, fg, up)) continue;
        Hazard hz;
        hz.kind = Hazard::Kind::FlushWall;
        hz.value = gap;
        hz.limit = -thinnest_part;
        hz.where = geomPath(wall.f, wall.g) + ", " + geomPath(floor.f, floor.g) + ", " +
                   idx("parts", thin_family) + ".size";
        std::ostringstream m;
        m << "the bottom of " << geomPath(wall.f, wall.g) << " (fixture '"
          << scene.fixtures[wall.f].name << "') is "
          << (gap >= 0 ? mm(gap) + " above" : mm(-gap) + " below") << " the top of "
          << geomPath(floor.f, floor.g) << " (fixture '" << scene.fixtures[floor.f].name
          << "'), less than the thinnest part " << idx("parts", thin_family) << " ("
          << mm(thinnest_part) << "): a thin part can slip into the seam and under the wall";
        hz.message = m.str();
        hz.safe_setting = "extend " + geomPath(wall.f, wall.g) + " " + mm(thinnest_part + gap) +
                          " further down (its bottom " + mm(thinnest_part) +
                          " below the floor's top), or make them one fixture";
        out.push_back(hz);
      }
    }
  }

  // --- 3. Mass ratios beyond the iteration count --------------------------------------------
  const bool quickstep = ode && scene.solver.ode_quickstep;
  if ((quickstep || !ode) && total_parts >= 2 && lightest < kInf && heaviest > 0) {
    const double ratio = heaviest / lightest;
    const int k = scene.solver.iterations;
    const double limit = quickstep ? odeQuickstepMassRatioLimit(k, light_thickness, h, g)
                                   : referenceMassRatioLimit(k, light_thickness, h, g);
    if (ratio > limit) {
      Hazard hz;
      hz.kind = Hazard::Kind::MassRatio;
      hz.value = ratio;
      hz.limit = limit;
      hz.where = idx("parts", heavy_family) + ".size, " + idx("parts", light_family) +
                 ".size, density, solver.iterations, solver.time_step";
      const double x = light_thickness / (g * h * h);
      std::ostringstream m;
      m << "the heaviest part (" << idx("parts", heavy_family) << ", " << fmt(heaviest)
        << " kg) is " << fmt(ratio) << " times the lightest (" << idx("parts", light_family) << ", "
        << fmt(lightest) << " kg, " << mm(light_thickness) << " thick); "
        << (quickstep ? "ODE quickstep" : "the reference solver") << " with " << k
        << " iterations at h = " << fmt(h) << " s (thickness / (g h^2) = " << fmt(x)
        << (limit < 1 ? ") is below the measured range, where even stacks of equal parts sank "
                        "into the floor"
                      : ") was measured to hold a ratio of " + fmt(limit))
        << ": a heavy part resting on a light one crushes it into the floor";
      hz.message = m.str();
      std::ostringstream s;
      int need = 0;
      for (int kk :
           quickstep ? std::vector<int>{10, 20, 50, 100, 200} : std::vector<int>{20, 50, 100}) {
        const double l = quickstep ? odeQuickstepMassRatioLimit(kk, light_thickness, h, g)
                                   : referenceMassRatioLimit(kk, light_thickness, h, g);
        if (!need && ratio <= l) need = kk;
      }
      if (need) s << "solver.iterations >= " << need << ", or ";
      double safe_h = h;
      for (int n = 0;
           n < 60 && ratio > (quickstep ? odeQuickstepMassRatioLimit(k, light_thickness, safe_h, g)
                                        : referenceMassRatioLimit(k, light_thickness, safe_h, g));
           ++n) {
        safe_h *= 0.8;
      }
      s << step_field << " <= " << fmt(safe_h) << " s";
      if (quickstep) s << ", or solver.ode_quickstep = false (Dantzig LCP, exact but slower)";
      s << ", or parts of closer masses";
      hz.safe_setting = s.str();
      out.push_back(hz);
    }
  }

  // --- 4. Coarse full-vibration steps ---------------------------------------------------------
  if (full) {
    for (std::size_t f = 0; f < scene.fixtures.size(); ++f) {
      const FeederLaw& law = scene.fixtures[f].law;
      if (law.kind != FeederLaw::Kind::Vibration) continue;
      const double per_cycle = 1.0 / (law.vibration.frequency * h);
      if (per_cycle >= kMinStepsPerCycle) continue;
      Hazard hz;
      hz.kind = Hazard::Kind::CoarseVibrationStep;
      hz.value = per_cycle;
      hz.limit = kMinStepsPerCycle;
      hz.where = "solver.time_step, " + idx("fixtures", f) + ".law.vibration.frequency";
      hz.message = "a full-vibration run resolves the " + fmt(law.vibration.frequency) +
                   " Hz vibration of fixture '" + scene.fixtures[f].name + "' with only " +
                   fmt(per_cycle) + " steps per cycle (h = " + fmt(h) + " s)";
      hz.safe_setting =
          "solver.time_step <= " + fmt(1.0 / (kMinStepsPerCycle * law.vibration.frequency)) + " s";
      out.push_back(hz);
    }
  }

  // --- 4b. Restitution near 1 ---------------------------------------------------------------
  if (scene.material.restitution >= kHighRestitution && !scene.parts.empty()) {
    Hazard hz;
    hz.kind = Hazard::Kind::HighRestitution;
    hz.value = scene.material.restitution;
    hz.limit = kHighRestitution;
    hz.where = "material.restitution";
    hz.message = "material.restitution = " + fmt(scene.material.restitution) +
                 ": Newton's impact law is applied at every contact point, so a part landing on "
                 "an edge or a corner can leave faster than it came (boxes dropped 0.5 m with "
                 "restitution 1 reached 8.4 m/s against 3.1 m/s of free fall)";
    hz.safe_setting = "material.restitution < " + fmt(kHighRestitution) + ", or spherical parts";
    out.push_back(hz);
  }

  // --- 5. Spawn regions inside fixtures or below the removal height, streams into themselves --
  for (std::size_t i = 0; i < scene.parts.size(); ++i) {
    const PartSpec& p = scene.parts[i];
    if (p.rate > 0 && p.count > 1 && g > 0) {
      // A part released at rest falls its own largest size s in t = sqrt(2 s / g); the next
      // one appears 1 / rate later. When it comes sooner, and the region is narrower than s
      // across (so the next part cannot be drawn beside the last), they overlap.
      const PartRange r = partRange(p);
      const double s_big = r.heavy.size;
      const double clear_time = std::sqrt(2 * s_big / g);
      const double interval = 1.0 / p.rate;
      const Vec3 span = p.spawn_max - p.spawn_min;
      const double across = std::max({std::abs(span.x), std::abs(span.y), std::abs(span.z)});
      if (interval < clear_time && across < s_big) {
        Hazard hz;
        hz.kind = Hazard::Kind::SpawnStreamOverlap;
        hz.value = interval;
        hz.limit = clear_time;
        hz.where = idx("parts", i) + ".rate, " + idx("parts", i) + ".spawn_min/spawn_max";
        hz.message = idx("parts", i) + " ('" + p.name + "') spawns a part every " + fmt(interval) +
                     " s from a region " + fmt(across) + " m across, smaller than a part (" +
                     fmt(s_big) + " m), while a part needs " + fmt(clear_time) +
                     " s to fall clear of the next: parts appear inside each other and are "
                     "pushed apart at up to solver.max_correcting_velocity";
        hz.safe_setting = idx("parts", i) + ".rate <= " + fmt(1.0 / clear_time) +
                          " parts/s, or a spawn region at least " + fmt(s_big) + " m across";
        out.push_back(hz);
      }
    }
    if (p.shape == Shape::Kind::Capsule || p.shape == Shape::Kind::Cylinder) {  // both engines

      for (const GeomInfo& gi : geoms) {
        const Fixture::Geom& gm = scene.fixtures[gi.f].geoms[gi.g];
        if (gm.shape.kind != Shape::Kind::Cylinder) continue;
        Hazard hz;
        hz.kind = Hazard::Kind::WeakCollider;
        hz.where = idx("parts", i) + ".shape, " + geomPath(gi.f, gi.g) + ".shape";
        hz.message = std::string(toString(p.shape)) + " parts of " + idx("parts", i) +
                     " against the cylinder " + geomPath(gi.f, gi.g) + " (fixture '" +
                     scene.fixtures[gi.f].name +
                     "'): ODE 0.16 collides this pair with its general convex test (one contact "
                     "point per pair), parts tip into the cylinder and can sink through it";
        hz.safe_setting =
            "a box (or a triangle mesh) for " + geomPath(gi.f, gi.g) + ", or box/sphere parts";
        out.push_back(hz);
        break;  // one warning per part family
      }
    }
    for (const GeomInfo& gi : geoms) {
      const Fixture::Geom& gm = scene.fixtures[gi.f].geoms[gi.g];
      if (!regionInsideGeom(p.spawn_min, p.spawn_max, gm)) continue;
      Hazard hz;
      hz.kind = Hazard::Kind::SpawnInsideFixture;
      hz.where = idx("parts", i) + ".spawn_min, " + idx("parts", i) + ".spawn_max, " +
                 geomPath(gi.f, gi.g);
      hz.message = "the spawn region of " + idx("parts", i) + " ('" + p.name + "') reaches into " +
                   geomPath(gi.f, gi.g) + " (" + toString(gm.shape.kind) + ", fixture '" +
                   scene.fixtures[gi.f].name +
                   "'): parts can start inside it and are pushed out at up to "
                   "solver.max_correcting_velocity or through it";
      hz.safe_setting = "move or shrink " + idx("parts", i) +
                        ".spawn_min/spawn_max so that part centres stay outside every fixture "
                        "(at least half a part above a floor)";
      out.push_back(hz);
    }
    Box3 region;
    region.add(p.spawn_min);
    region.add(p.spawn_max);
    // removal_height is a world z (simulation.hpp), whatever the gravity.
    if (region.lo.z < scene.removal_height) {
      Hazard hz;
      hz.kind = Hazard::Kind::SpawnBelowRemoval;
      hz.value = region.lo.z;
      hz.limit = scene.removal_height;
      hz.where = idx("parts", i) + ".spawn_min.z, removal_height";
      hz.message = "parts of " + idx("parts", i) + " can spawn at z = " + fmt(region.lo.z) +
                   " m, below removal_height = " + fmt(scene.removal_height) +
                   " m: they are removed as they appear";
      hz.safe_setting = "removal_height < " + fmt(region.lo.z) + " m";
      out.push_back(hz);
    }
  }

  return out;
}

std::string formatHazards(const std::vector<Hazard>& hazards, const std::string& prefix) {
  std::string text;
  for (const Hazard& h : hazards) {
    text += prefix + "warning [" + toString(h.kind) + "] " + h.where + ": " + h.message + "\n";
    text += prefix + "  safe: " + h.safe_setting + "\n";
  }
  return text;
}

std::vector<std::string> reportSceneCheck(const Scene& scene, Method method) {
  const std::vector<Hazard> hazards = checkScene(scene, method);
  std::vector<std::string> lines;
  for (const Hazard& hz : hazards) {
    lines.push_back(std::string(toString(hz.kind)) + " at " + hz.where + ": " + hz.message +
                    " (safe: " + hz.safe_setting + ")");
  }
  std::fprintf(
      stderr, "%s",
      formatHazards(hazards, "rheofeed: " + scene.name + ", " + toString(method) + ": ").c_str());
  return lines;
}

}  // namespace rheofeed::scene
