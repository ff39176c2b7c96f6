// SPDX-License-Identifier: MIT
// Internal: the scene check's shared context and its pieces (check.hpp). check.cpp measures
// the scene once into a CheckContext and runs one function per hazard kind over it
// (check_hazards.cpp); the geometry they share is in check_geometry.cpp, the mesh wall
// thickness in check_mesh.cpp.
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "rheofeed/simulation/check.hpp"

namespace rheofeed::scene::checks {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
// A size distribution is taken to reach mean +- 5 standard deviations (within min/max): a
// draw lies beyond with probability 5.7e-7, once in 580 scenes of 1000 boxes.
constexpr double kSigmas = 5;
// Two faces closer than this (m) are one seam for the flush-wall check, whatever the parts.
constexpr double kSeamTolerance = 1e-6;
// A box edge counts as upright when its direction is within this of the up direction (cosine).
constexpr double kUprightCosine = 1 - 1e-9;

// Moller-Trumbore: the distance t along the ray origin + t dir (dir need not be unit; t in its
// lengths) at which it meets the triangle (p, q, r), either side; -1 when it misses or runs
// parallel to the triangle's plane. Shared by the mesh wall thickness (check_mesh.cpp) and the
// anchor search (part_anchor.cpp).
inline double rayTriangleDistance(const Vec3& origin, const Vec3& dir, const Vec3& p, const Vec3& q,
                                  const Vec3& r) {
  const Vec3 e1 = q - p, e2 = r - p, pv = cross(dir, e2);
  const double det = dot(e1, pv);
  if (std::abs(det) < 1e-30) return -1;
  const Vec3 tv = origin - p;
  const double u = dot(tv, pv) / det;
  if (u < 0 || u > 1) return -1;
  const Vec3 qv = cross(tv, e1);
  const double w = dot(dir, qv) / det;
  if (w < 0 || u + w > 1) return -1;
  return dot(e2, qv) / det;
}

// Numbers and JSON paths as the messages write them: "%.3g", "12.3 mm", "parts[2]",
// "fixtures[0].geoms[1]".
std::string fmt(double v);
std::string mm(double metres);
std::string idx(const char* base, std::size_t i);
std::string geomPath(std::size_t f, std::size_t g);

// Axis-aligned bounding box (world) of a fixture geom; planes are unbounded.
struct Box3 {
  Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  bool bounded = true;
  void add(const Vec3& p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
};
// Bounding box of a fixture geom at its pose; a plane or a mesh not loaded is unbounded.
Box3 geomBounds(const Fixture::Geom& g);
// Heights along `up` of a box's extremes.
double maxAlong(const Box3& b, const Vec3& up);
double minAlong(const Box3& b, const Vec3& up);

// Thickness of a fixture geom (m): the smallest distance across it. Planes are half-spaces. A
// mesh whose wall test was skipped (too many ray tests) has `measured` false and kInf.
struct Thickness {
  double value = kInf;
  std::string note;
  bool measured = true;
  long long ray_tests = 0;
};
Thickness fixtureThickness(const Shape& s);

// Mass (kg) and smallest thickness (m) of a part of a family at given sizes.
struct PartExtreme {
  double mass = 0, thickness = 0;
  double size = 0;  // largest extent (m); a mesh part: its largest bounding-box extent
};
struct PartRange {
  PartExtreme light, heavy;  // the lightest and heaviest parts of the family
  double thinnest = 0;       // smallest thickness of any part of the family (m)
  std::string note;
};
PartRange partRange(const PartSpec& p);

// Whether two upright boxes overlap in plan (normal to `up`), touching edges excluded.
bool planOverlap(const Fixture::Geom& a, const Fixture::Geom& b, const Vec3& up);
// Whether a geom is a box with an edge along `up`.
bool upright(const Fixture::Geom& g, const Vec3& up);
// Extents of a mesh's bounding box in its own frame, times `scale` (m).
Vec3 meshBoxExtents(const TriangleMesh& mesh, double scale);

// Generalized winding number of a closed mesh at p (its frame): the solid angles of its
// triangles seen from p (Van Oosterom and Strackee), summed, over 4 pi. 1 inside an outward
// mesh, 0 outside, whatever its edges and vertices.
double windingNumber(const TriangleMesh& m, const Vec3& p);

// Whether `m` is closed and consistently wound: its directed edges (a, b) and their reverses
// (b, a) are the same multiset, vertices at the same point counting as one, so the mesh bounds a
// solid (or several). An open mesh (a sheet) bounds none: spawn regions are not checked against
// it.
bool closedMesh(const TriangleMesh& m);

// Whether the region [lo, hi] and the box b overlap (open intervals).
bool overlaps(const Vec3& lo, const Vec3& hi, const Box3& b);

// Whether the axis-aligned region [lo, hi] (world) reaches into a fixture geom. A closed mesh
// is the solid it bounds, sampled (regionInsideMesh); an open one bounds none: false.
bool regionInsideGeom(const Vec3& lo, const Vec3& hi, const Fixture::Geom& g);
// Largest surface speed of a drift twist over a box (m/s).
double twistSpeedOver(const Twist& t, const Box3& b);
// Largest distance of a box's corners from an axis (m).
double radiusFromAxis(const Box3& b, const Vec3& origin, const Vec3& axis);

// What every hazard test reads: the scene and method, and the scene measured once.
struct CheckContext {
  const Scene& scene;
  Method method;
  double h = 0, g = 0;  // the run's step (s), |gravity| (m/s^2)
  Vec3 up;              // -gravity, unit (z without gravity)
  bool full = false, ode = false;
  std::string step_field;  // the scene field that sets this method's step (run_step.hpp)

  // Parts: the thinnest, the lightest and the heaviest over all families.
  double thinnest_part = kInf, lightest = kInf, heaviest = 0, light_thickness = kInf;
  std::size_t thin_family = 0, light_family = 0, heavy_family = 0;
  std::string part_note;
  int total_parts = 0;

  // Fixtures: every geom's bounds, the thinnest geom, the lowest top, the fastest surface.
  struct GeomInfo {
    std::size_t f, g;
    Box3 bounds;
    bool open_mesh = false;  // a mesh that bounds no solid (closedMesh false, or no data)
  };
  std::vector<GeomInfo> geoms;
  double thinnest_fixture = kInf, lowest_top = kInf;
  std::string thin_geom, fixture_note;
  double surface_speed = 0;
  std::string speed_source = "nothing moves";
  // Mesh geoms whose wall test was skipped: path, triangles, ray tests done.
  struct Skipped {
    std::string path;
    std::size_t triangles = 0;
    long long ray_tests = 0;
  };
  std::vector<Skipped> skipped;

  CheckContext(const Scene& s, Method m) : scene(s), method(m) {}
};

// One function per hazard kind (check_hazards.cpp); each appends what it finds to `out`.
void checkTunnelling(const CheckContext& c, std::vector<Hazard>& out);
void checkFlushWalls(const CheckContext& c, std::vector<Hazard>& out);
void checkMassRatio(const CheckContext& c, std::vector<Hazard>& out);
void checkCoarseVibrationStep(const CheckContext& c, std::vector<Hazard>& out);
void checkExtremeVibration(const CheckContext& c, std::vector<Hazard>& out);
void checkConveyingSense(const CheckContext& c, std::vector<Hazard>& out);
void checkHighRestitution(const CheckContext& c, std::vector<Hazard>& out);
void checkSpawnStream(const CheckContext& c, std::size_t part, std::vector<Hazard>& out);
void checkWeakCollider(const CheckContext& c, std::size_t part, std::vector<Hazard>& out);
void checkSpawnInsideFixture(const CheckContext& c, std::size_t part, std::vector<Hazard>& out);
void checkSpawnBelowRemoval(const CheckContext& c, std::size_t part, std::vector<Hazard>& out);
void checkSpawnOverNothing(const CheckContext& c, std::size_t part, std::vector<Hazard>& out);
void checkSkippedTests(const CheckContext& c, std::vector<Hazard>& out);

}  // namespace rheofeed::scene::checks
