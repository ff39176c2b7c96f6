// SPDX-License-Identifier: MIT
// Geometry and part measures of the scene check (check_internal.hpp): bounding boxes, heights
// along up, thicknesses, part size ranges, plan overlaps, spawn regions against fixtures.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "check_internal.hpp"
#include "rheofeed/scene/mesh.hpp"
#include "simulation_internal.hpp"

namespace rheofeed::scene::checks {

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

Vec3 meshBoxExtents(const TriangleMesh& mesh, double scale) {
  Box3 b;
  for (std::size_t k = 0; k + 2 < mesh.vertices.size(); k += 3) {
    b.add({mesh.vertices[k], mesh.vertices[k + 1], mesh.vertices[k + 2]});
  }
  return scale * (b.hi - b.lo);
}

// Thickness of a fixture geom (m): the smallest distance across it. Planes are half-spaces.
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
    case Shape::Kind::Mesh: {
      if (!s.mesh_data) return {0, " (mesh not loaded: counted as a surface of no thickness)"};
      const MeshWallThickness wall = meshWallThickness(*s.mesh_data, 1.0);
      if (!wall.measured) {
        return {kInf, " (mesh wall not measured: skipped)", false, wall.ray_tests};
      }
      return {wall.thickness,
              " (mesh wall: 5 % of its area is thinner, by ray casting; a crude estimate)"};
    }
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
      const Vec3 e = meshBoxExtents(*p.mesh_data, sz[0]);
      return {massProperties(*p.mesh_data, rho).mass * std::pow(sz[0], 3),
              std::min({e.x, e.y, e.z}), std::max({e.x, e.y, e.z})};
    }
    case Shape::Kind::Plane:
      break;
  }
  return {};
}

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

double windingNumber(const TriangleMesh& m, const Vec3& p) {
  double sum = 0;
  for (std::size_t t = 0; 3 * t + 2 < m.triangles.size(); ++t) {
    Vec3 v[3];
    for (int k = 0; k < 3; ++k) {
      const double* x = &m.vertices[3 * static_cast<std::size_t>(m.triangles[3 * t + k])];
      v[k] = Vec3{x[0], x[1], x[2]} - p;
    }
    const double la = norm(v[0]), lb = norm(v[1]), lc = norm(v[2]);
    sum += 2 * std::atan2(dot(v[0], cross(v[1], v[2])), la * lb * lc + dot(v[0], v[1]) * lc +
                                                            dot(v[1], v[2]) * la +
                                                            dot(v[2], v[0]) * lb);
  }
  return sum / (4 * kPi);
}

bool closedMesh(const TriangleMesh& m) {
  // Vertices at the same point are one (a loader may keep them apart, one per face).
  const std::size_t n = m.vertices.size() / 3;
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  const auto point = [&m](std::size_t i) {
    return std::array<double, 3>{m.vertices[3 * i], m.vertices[3 * i + 1], m.vertices[3 * i + 2]};
  };
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return point(a) < point(b); });
  std::vector<std::size_t> id(n);
  for (std::size_t k = 0, next = 0; k < n; ++k) {
    if (k > 0 && point(order[k]) != point(order[k - 1])) ++next;
    id[order[k]] = next;
  }
  std::vector<std::pair<std::size_t, std::size_t>> edges, reversed;
  for (std::size_t t = 0; 3 * t + 2 < m.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::size_t a = id[static_cast<std::size_t>(m.triangles[3 * t + k])],
                        b = id[static_cast<std::size_t>(m.triangles[3 * t + (k + 1) % 3])];
      edges.emplace_back(a, b);
      reversed.emplace_back(b, a);
    }
  }
  std::sort(edges.begin(), edges.end());
  std::sort(reversed.begin(), reversed.end());
  // As multisets: a shell given twice, or two shells that share an edge, still bound solids.
  return !edges.empty() && edges == reversed;
}

namespace {

// Winding-number evaluations (one triangle each) a region test may spend: about 0.3 s.
constexpr double kMaxWindingTerms = 2e7;

// Whether the region [lo, hi] (world) reaches into the solid bounded by the closed mesh `m`
// placed at `pose`: the mesh's vertices inside the region (a wall thinner than the grid's spacing
// that crosses the region has corners in it when the region holds one of its edges), then a grid
// of points over the region by winding number (both ends of each axis and at most 5 mm apart, up
// to 17 per axis, fewer on a mesh so large that the grid would cost more than kMaxWindingTerms,
// down to the region's 8 corners). A sampling check: it can miss a thin wall that crosses the
// region between samples without a vertex in it.
bool regionInsideMesh(const Vec3& lo, const Vec3& hi, const Pose& pose, const TriangleMesh& m) {
  for (std::size_t k = 0; k + 2 < m.vertices.size(); k += 3) {
    const Vec3 w = pose.transform({m.vertices[k], m.vertices[k + 1], m.vertices[k + 2]});
    if (w.x > lo.x && w.x < hi.x && w.y > lo.y && w.y < hi.y && w.z > lo.z && w.z < hi.z) {
      return true;
    }
  }
  const double triangles = std::max<double>(1, static_cast<double>(m.triangles.size() / 3));
  const int most = std::clamp(static_cast<int>(std::cbrt(kMaxWindingTerms / triangles)), 2, 17);
  const auto samples = [most](double extent) {
    return std::clamp(static_cast<int>(std::ceil(extent / 0.005)) + 1, 2, most);
  };
  const int n[3] = {samples(hi.x - lo.x), samples(hi.y - lo.y), samples(hi.z - lo.z)};
  const auto at = [](double a, double b, int i, int count) {
    return a + (b - a) * i / (count - 1);
  };
  for (int i = 0; i < n[0]; ++i) {
    for (int j = 0; j < n[1]; ++j) {
      for (int k = 0; k < n[2]; ++k) {
        const Vec3 w{at(lo.x, hi.x, i, n[0]), at(lo.y, hi.y, j, n[1]), at(lo.z, hi.z, k, n[2])};
        if (windingNumber(m, pose.inverseTransform(w)) > 0.5) return true;
      }
    }
  }
  return false;
}

}  // namespace

bool overlaps(const Vec3& lo, const Vec3& hi, const Box3& b) {
  return lo.x < b.hi.x && hi.x > b.lo.x && lo.y < b.hi.y && hi.y > b.lo.y && lo.z < b.hi.z &&
         hi.z > b.lo.z;
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
  if (s.kind == Shape::Kind::Mesh && (!s.mesh_data || !closedMesh(*s.mesh_data))) {
    return false;  // no solid: not checked
  }
  if (s.kind == Shape::Kind::Sphere) {
    const Vec3 c = g.pose.position;
    const Vec3 nearest{std::clamp(c.x, lo.x, hi.x), std::clamp(c.y, lo.y, hi.y),
                       std::clamp(c.z, lo.z, hi.z)};
    return norm(nearest - c) < s.radius;
  }
  const Box3 b = geomBounds(g);
  if (!overlaps(lo, hi, b)) return false;
  if (s.kind == Shape::Kind::Mesh) return regionInsideMesh(lo, hi, g.pose, *s.mesh_data);
  if (s.kind != Shape::Kind::Box) return true;  // cylinder, capsule: bounding box
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

}  // namespace rheofeed::scene::checks
