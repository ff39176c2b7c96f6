// SPDX-License-Identifier: MIT
/// @file narrow_phase.hpp
/// One colliding pair's contacts, with none cut off by the order in which ODE visits a mesh's
/// triangles.
///
/// dCollide(o1, o2, max, ...) returns at most `max` contacts, and ODE's triangle-mesh colliders
/// choose which (ODE 0.16.2): the cylinder-trimesh and capsule-trimesh colliders stop at the
/// first `max` they find in OPCODE's triangle order (and then merge near-duplicates), the
/// trimesh-trimesh collider keeps the first `max` places it finds, the box-trimesh collider
/// replaces its shallowest once the buffer is full. A part touching more triangles than `max` (a
/// nut lying on a finely tessellated floor beside a wall) then gets contacts on one side of its
/// footprint, or on one face only, tips into the mesh and sinks through it over a few steps. With
/// rheofeed's former 8 contacts per pair, the mesh bowl of demos/scenes/bowl_feeder.json at
/// h = 0.01 s lost 9 of 12 cylinder nuts and 3 of 12 mesh nuts in 12 s on its calibrated drift;
/// with every contact seen, none (demos/results/bowl_feeder.md, section 8).
///
/// collideSpanning asks ODE for every contact of a pair that involves a triangle mesh (a buffer of
/// kMeshContactCapacity, doubled while ODE fills it, and for cylinders and capsules while the
/// count still grows, up to kMeshContactCapacityLimit: two equal counts in a row are taken as
/// complete, a heuristic, since those colliders merge after they stop) and keeps `max` of them
/// that span the set: the deepest first, then each time the candidate whose distance to the nearest
/// contact kept, times its depth, is largest, the distance between contacts i and k being
///   |p_i - p_k| + s (1 - n_i . n_k),
/// with s the largest distance of a candidate from the deepest contact (m). So a contact on each
/// face the part touches (floor and wall: normals apart) and the corners of its footprint are
/// kept, ahead of the shallow side-normal contacts ODE's cylinder collider makes at the edges of
/// coplanar triangles; a candidate at distance 0 from a kept one (same point and normal) is never
/// kept. The contacts kept are written in a fixed order (by triangle index, then position), so
/// that the same contacts come in the same order from step to step (the reference world's warm
/// start falls back on the index). Pairs without a mesh go to dCollide(o1, o2, max) unchanged.
///
/// Before that reduction, collideSpanning corrects the normals ODE takes from the tessellation of
/// a fixture (the internal-edge problem of triangle meshes). ODE tests a mesh triangle by
/// triangle, and a floor triangle's edge that pokes a fraction of a millimetre past a mesh part's
/// side face gives a contact with that side face's normal, horizontal on a flat floor, although
/// the floor continues on the next triangle: the part snags on a seam that is not there. Only
/// fixture meshes are corrected (MeshCollisionScratch::is_fixture: by default a geom without a
/// body or with a kinematic one): a fixture is locally a plane wherever its surface is smooth,
/// and the contact normal of a plane is its own. A contact whose normal, turned out of the
/// fixture, is more than kFaceNormalTolerance from the face normal of the fixture's triangle (and
/// not pointing into it), at a point over that triangle, or over a neighbour reached across its
/// smooth edges, away from sharp edges and corners (MeshEdges: the surface continues across an
/// edge within kSmoothEdgeAngle), gets that triangle's face normal; its depth is how far its point
/// lies below the face, and at least ODE's depth times the cosine between the two normals.
/// Contacts at a sharp edge or corner (a rim, the corner of floor and wall, the mesh's border),
/// off the mesh's smooth surface, of spheres (whose contacts have a face's normal) and of convex
/// geoms (whose triangle ODE does not give; ODE corrects those itself) keep ODE's normal. A mesh
/// nut on a belt of 1 mm triangles at h = 0.01 s was carried at 65 % of the belt's speed with
/// ODE's normals (Plugin.NarrowPhase.MeshNutOnATessellatedBeltIsCarriedAtTheBeltSpeed); the mesh
/// bowl: demos/results/bowl_feeder.md, section 9.
///
/// Header only: the plugin's ContactCollider and the reference world (which does not link the
/// plugin library) both use it.
#pragma once

#include <ode/ode.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "rheofeed/vec3.hpp"

namespace rheofeed {

/// First buffer size (contacts) for a pair with a triangle mesh.
inline constexpr int kMeshContactCapacity = 64;
/// Largest buffer size (contacts) for one pair; dCollide's count field holds at most 0xffff.
inline constexpr int kMeshContactCapacityLimit = 4096;

/// The surface of a triangle mesh continues across an edge "smoothly" when the two triangles
/// sharing it have face normals within this angle (degrees): the facets of a tessellated floor,
/// cone or curved wall (the mesh bowl's: 0-4 degrees), not a rim, a corner or a part's edges
/// (60-90 degrees on a hexagonal nut).
inline constexpr double kSmoothEdgeAngle = 10.0;

/// A contact normal within this angle (degrees) of its fixture triangle's face normal is that
/// normal (rounding): any other, averaged ones included, is a candidate for the correction.
inline constexpr double kFaceNormalTolerance = 0.1;

/// Depths below this fraction of a contact set's span (s in the file comment; 1 um for a 10 mm
/// nut) are rounding: the faces touch. keepSpanningContacts weighs them all alike, so that a part
/// lying flat on coplanar triangles, whose depths ODE gives as noise around 1e-9 m (some zero or
/// negative), keeps contacts round its whole footprint and not the few that rounding made
/// deepest. With the former floor of 1e-6 of the deepest depth, a frictionless mesh nut sliding
/// on 1 mm triangles at h = 0.01 s kept contacts on one side of its footprint in one step of
/// seven and was kicked into spins of 5-15 rad/s
/// (Plugin.NarrowPhase.FrictionlessMeshNutSlidesFlatOverTheSeamsWithoutSpinning).
inline constexpr double kDepthResolution = 1e-4;

namespace detail {
inline const double kCosSmoothEdgeAngle = std::cos(kSmoothEdgeAngle * kPi / 180.0);
inline const double kCosFaceNormalTolerance = std::cos(kFaceNormalTolerance * kPi / 180.0);
}  // namespace detail

/// For each triangle edge of one triangle mesh (ODE's geom), whether the surface continues
/// smoothly across it (kSmoothEdgeAngle; consistent winding, exactly two triangles on the edge),
/// and for each corner whether every edge at its vertex does. Vertices are matched by position
/// (STL files repeat them per triangle), rounded to a grid of 1e-7 of the mesh's size (exact
/// copies always match). Built from the geom's triangles in the world frame: the angles do not
/// depend on where the mesh is. A mesh whose vertices move (dGeomTriMeshDataUpdate) is not
/// noticed.
class MeshEdges {
 public:
  explicit MeshEdges(dGeomID mesh) {
    const int n = dGeomTriMeshGetTriangleCount(mesh);
    triangles_ = n > 0 ? n : 0;
    fingerprint_ = fingerprintOf(mesh, triangles_);
    smooth_corner_.assign(static_cast<std::size_t>(triangles_), 0);
    neighbour_.assign(3 * static_cast<std::size_t>(triangles_), -1);
    if (triangles_ == 0) return;
    std::vector<double> v(9 * static_cast<std::size_t>(triangles_));
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int t = 0; t < triangles_; ++t) {
      dVector3 a, b, c;
      dGeomTriMeshGetTriangle(mesh, t, &a, &b, &c);
      const dReal* corners[3] = {a, b, c};
      for (int k = 0; k < 3; ++k) {
        for (int d = 0; d < 3; ++d) {
          const double x = corners[k][d];
          v[9 * static_cast<std::size_t>(t) + 3 * static_cast<std::size_t>(k) +
            static_cast<std::size_t>(d)] = x;
          lo[d] = std::min(lo[d], x);
          hi[d] = std::max(hi[d], x);
        }
      }
    }
    const double size =
        std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                  (hi[2] - lo[2]) * (hi[2] - lo[2]));
    const double q = size > 0 && std::isfinite(size) ? 1e-7 * size : 1.0;
    // vertex ids by quantised position, in order of first appearance
    std::map<std::array<std::int64_t, 3>, int> ids;
    std::vector<int> id(3 * static_cast<std::size_t>(triangles_));
    for (std::size_t i = 0; i < id.size(); ++i) {
      std::array<std::int64_t, 3> key{};
      for (std::size_t d = 0; d < 3; ++d) {
        key[d] = static_cast<std::int64_t>(std::llround((v[3 * i + d] - lo[d]) / q));
      }
      id[i] = ids.emplace(key, static_cast<int>(ids.size())).first->second;
    }
    const int next_id = static_cast<int>(ids.size());
    // edges: directed (from, to) -> triangle and edge index
    struct Side {
      int triangle, edge, from, to;
    };
    std::unordered_map<std::uint64_t, std::vector<Side>> edges;
    for (int t = 0; t < triangles_; ++t) {
      for (int k = 0; k < 3; ++k) {
        const int a = id[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(k)];
        const int b = id[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>((k + 1) % 3)];
        if (a == b) continue;  // a degenerate triangle
        const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                                  static_cast<std::uint32_t>(std::max(a, b));
        edges[key].push_back({t, k, a, b});
      }
    }
    // a corner is smooth when every edge at its vertex is (and it has edges: not a lone point)
    std::vector<std::uint8_t> sharp_vertex(static_cast<std::size_t>(next_id), 0);
    for (const auto& entry : edges) {
      const std::vector<Side>& sides = entry.second;
      bool smooth = sides.size() == 2 && sides[0].from == sides[1].to;
      if (smooth) {
        const Normal n0 = faceNormal(&v[9 * static_cast<std::size_t>(sides[0].triangle)]);
        const Normal n1 = faceNormal(&v[9 * static_cast<std::size_t>(sides[1].triangle)]);
        smooth = n0.valid && n1.valid &&
                 n0.x * n1.x + n0.y * n1.y + n0.z * n1.z >= detail::kCosSmoothEdgeAngle;
      }
      if (!smooth) {
        sharp_vertex[static_cast<std::size_t>(sides[0].from)] = 1;
        sharp_vertex[static_cast<std::size_t>(sides[0].to)] = 1;
        continue;
      }
      for (int i = 0; i < 2; ++i) {
        const Side& sd = sides[static_cast<std::size_t>(i)];
        neighbour_[3 * static_cast<std::size_t>(sd.triangle) + static_cast<std::size_t>(sd.edge)] =
            sides[static_cast<std::size_t>(1 - i)].triangle;
      }
    }
    for (int t = 0; t < triangles_; ++t) {
      for (int k = 0; k < 3; ++k) {
        const int vertex = id[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(k)];
        if (!sharp_vertex[static_cast<std::size_t>(vertex)]) {
          smooth_corner_[static_cast<std::size_t>(t)] |= static_cast<std::uint8_t>(1u << k);
        }
      }
    }
  }

  /// Whether this table may describe `mesh`'s triangles: the same count, and the same edge
  /// lengths (to 1e-9) of kFingerprintTriangles triangles spread evenly through the mesh. A
  /// cache keyed by the mesh data's address (MeshCollisionScratch) checks this because ODE may
  /// reuse the address for another mesh once one is destroyed; a sample cannot tell every
  /// other mesh apart, so a caller that destroys mesh data calls MeshCollisionScratch::forget.
  bool describes(dGeomID mesh) const {
    const int n = dGeomTriMeshGetTriangleCount(mesh);
    if (n != triangles_) return false;
    const Fingerprint f = fingerprintOf(mesh, n);
    for (std::size_t i = 0; i < f.lengths.size(); ++i) {
      if (!(std::abs(f.lengths[i] - fingerprint_.lengths[i]) <=
            1e-9 * std::max(1.0, std::abs(f.lengths[i])))) {
        return false;
      }
    }
    return true;
  }

  /// Triangles whose edge lengths describes() compares.
  static constexpr int kFingerprintTriangles = 32;

  /// Whether the surface continues smoothly across edge `edge` (0: corner 0 to 1, 1: 1 to 2,
  /// 2: 2 to 0) of triangle `triangle`; false for an index out of range.
  bool smooth(int triangle, int edge) const { return neighbour(triangle, edge) >= 0; }

  /// Whether the surface is smooth all round corner `corner` (0, 1, 2) of triangle `triangle`:
  /// every edge at that vertex is smooth; false for an index out of range.
  bool smoothCorner(int triangle, int corner) const {
    if (triangle < 0 || triangle >= triangles_ || corner < 0 || corner > 2) return false;
    return (smooth_corner_[static_cast<std::size_t>(triangle)] >> corner) & 1u;
  }

  /// The triangle across smooth edge `edge` of triangle `triangle`; -1 across a sharp edge or for
  /// an index out of range.
  int neighbour(int triangle, int edge) const {
    if (triangle < 0 || triangle >= triangles_ || edge < 0 || edge > 2) return -1;
    return neighbour_[3 * static_cast<std::size_t>(triangle) + static_cast<std::size_t>(edge)];
  }

  int triangles() const { return triangles_; }

  struct Normal {
    double x = 0, y = 0, z = 0;
    bool valid = false;
  };
  /// Unit normal of the triangle with corners v[0..2], v[3..5], v[6..8] (counter-clockwise seen
  /// from outside, ODE's convention); invalid for a degenerate triangle.
  static Normal faceNormal(const double* v) {
    const double ax = v[3] - v[0], ay = v[4] - v[1], az = v[5] - v[2];
    const double bx = v[6] - v[0], by = v[7] - v[1], bz = v[8] - v[2];
    Normal n{ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx, false};
    const double len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    if (!(len > 0) || !std::isfinite(len)) return n;
    n.x /= len;
    n.y /= len;
    n.z /= len;
    n.valid = true;
    return n;
  }

 private:
  struct Fingerprint {
    std::array<double, 3 * kFingerprintTriangles> lengths{};  // m, 0 past the mesh's count
  };
  static Fingerprint fingerprintOf(dGeomID mesh, int n) {
    Fingerprint f;
    const int samples = std::min(n, kFingerprintTriangles);
    for (int w = 0; w < samples; ++w) {
      // triangles 0 .. n - 1 evenly, the first and the last among them
      const int t =
          samples > 1 ? static_cast<int>((static_cast<long long>(n - 1) * w) / (samples - 1)) : 0;
      dVector3 a, b, c;
      dGeomTriMeshGetTriangle(mesh, t, &a, &b, &c);
      const dReal* p[3] = {a, b, c};
      for (int k = 0; k < 3; ++k) {
        const dReal* u = p[k];
        const dReal* v = p[(k + 1) % 3];
        f.lengths[static_cast<std::size_t>(3 * w + k)] =
            std::sqrt((u[0] - v[0]) * (u[0] - v[0]) + (u[1] - v[1]) * (u[1] - v[1]) +
                      (u[2] - v[2]) * (u[2] - v[2]));
      }
    }
    return f;
  }

  int triangles_ = 0;
  Fingerprint fingerprint_;
  std::vector<std::uint8_t> smooth_corner_;  // bit k: corner k is smooth
  std::vector<int> neighbour_;  // 3 per triangle: the triangle across each smooth edge, else -1
};

/// collideSpanning's working memory, kept by the caller between calls: the contact buffer, and
/// the edge tables of the fixture meshes met, keyed by their mesh data (built on the first call
/// that collides one; kept until forget() or clear()). A table is rebuilt when its mesh data's
/// address comes back with other triangles (MeshEdges::describes, a sample); an application
/// that destroys mesh data (dGeomTriMeshDataDestroy) or moves its vertices
/// (dGeomTriMeshDataUpdate) calls forget() for it, so that a new mesh at the same address, or
/// the moved one, gets its own table.
struct MeshCollisionScratch {
  std::vector<dContactGeom> contacts;
  std::unordered_map<dTriMeshDataID, MeshEdges> edges;
  /// Which meshes are fixtures, whose normals are corrected (file comment). Null: a geom with no
  /// body or a kinematic one. The reference world, whose geoms carry no ODE bodies, sets its own.
  std::function<bool(dGeomID)> is_fixture;

  bool fixture(dGeomID g) const {
    if (is_fixture) return is_fixture(g);
    const dBodyID b = dGeomGetBody(g);
    return b == nullptr || dBodyIsKinematic(b);
  }

  /// Drops the edge table of `data` (nothing when there is none).
  void forget(dTriMeshDataID data) { edges.erase(data); }
  /// Drops every edge table.
  void clear() { edges.clear(); }

  const MeshEdges& edgesOf(dGeomID mesh) {
    const dTriMeshDataID data = dGeomTriMeshGetTriMeshDataID(mesh);
    auto it = edges.find(data);
    if (it == edges.end()) return edges.emplace(data, MeshEdges(mesh)).first->second;
    if (!it->second.describes(mesh)) it->second = MeshEdges(mesh);
    return it->second;
  }
};

namespace detail {

/// Triangle `t` of `mesh` (its corners in the world frame, v[0..2], v[3..5], v[6..8]) and its
/// face normal; false for a degenerate triangle.
inline bool triangleOf(dGeomID mesh, int t, double v[9], MeshEdges::Normal& f) {
  dVector3 a, b, c;
  dGeomTriMeshGetTriangle(mesh, t, &a, &b, &c);
  const double corners[9] = {a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]};
  std::copy(corners, corners + 9, v);
  f = MeshEdges::faceNormal(v);
  return f.valid;
}

/// For the triangle v with unit face normal f: how far point p lies inside each edge k (corner k
/// to k + 1), in the triangle's plane (m; < 0 beyond it; 0 for an edge of length 0), and the
/// longest edge's length. Returns whether every edge has a length.
inline bool insideEdges(const double v[9], const MeshEdges::Normal& f, const double p[3],
                        double inside[3], double& longest) {
  bool all = true;
  longest = 0;
  for (int k = 0; k < 3; ++k) {
    const double* p0 = v + 3 * k;
    const double* p1 = v + 3 * ((k + 1) % 3);
    const double e[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double len = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    longest = std::max(longest, len);
    all = all && len > 0;
    // f x e / |e|: the edge's in-plane normal, into the triangle (counter-clockwise corners)
    const double m[3] = {f.y * e[2] - f.z * e[1], f.z * e[0] - f.x * e[2], f.x * e[1] - f.y * e[0]};
    inside[k] = len > 0
                    ? ((p[0] - p0[0]) * m[0] + (p[1] - p0[1]) * m[1] + (p[2] - p0[2]) * m[2]) / len
                    : 0.0;
  }
  return all;
}

}  // namespace detail

/// A point's place over a fixture mesh's smooth surface (surfacePointOver).
struct SurfacePoint {
  int triangle = -1;             ///< the triangle under the point
  double normal[3] = {0, 0, 0};  ///< its unit face normal (world, out of the fixture)
  double height = 0;             ///< the point's height above its plane (m; < 0 below it)
};

/// Where point `p` (m, world) lies over the smooth surface of triangle mesh `mesh` (edge table
/// `edges`) near triangle `start`: the triangle whose prism (the triangle swept along its normal)
/// holds p, `start` or one reached from it across smooth edges (at most 4 triangles, each step
/// across the edge p lies farthest beyond). False when the walk would cross a sharp edge or the
/// mesh's border, takes more steps, or meets a degenerate triangle.
inline bool surfacePointOver(dGeomID mesh, const MeshEdges& edges, int start, const double p[3],
                             SurfacePoint& out) {
  int t = start;
  for (int walk = 0; walk < 4; ++walk) {
    if (t < 0 || t >= edges.triangles()) return false;
    double v[9], inside[3], longest;
    MeshEdges::Normal f;
    if (!detail::triangleOf(mesh, t, v, f)) return false;
    const double height = (p[0] - v[0]) * f.x + (p[1] - v[1]) * f.y + (p[2] - v[2]) * f.z;
    if (!detail::insideEdges(v, f, p, inside, longest)) return false;
    int beyond = -1;
    double farthest = 0;
    for (int k = 0; k < 3; ++k) {
      if (inside[k] < farthest) {
        farthest = inside[k];
        beyond = k;
      }
    }
    if (beyond < 0) {
      out.triangle = t;
      out.normal[0] = f.x, out.normal[1] = f.y, out.normal[2] = f.z;
      out.height = height;
      return true;
    }
    t = edges.neighbour(t, beyond);  // -1 across a sharp edge or the border: false above
  }
  return false;
}

namespace detail {

inline double contactSpan(const dContactGeom& a, const dContactGeom& b, double s) {
  const double dx = a.pos[0] - b.pos[0], dy = a.pos[1] - b.pos[1], dz = a.pos[2] - b.pos[2];
  const double cos_n =
      a.normal[0] * b.normal[0] + a.normal[1] * b.normal[1] + a.normal[2] * b.normal[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz) + s * (1.0 - cos_n);
}

/// Keeps at most `max` of `all` spanning the set, in the fixed order (see the file comment); writes
/// them to `out` (every `stride` bytes) and returns their number.
inline int keepSpanningContacts(std::vector<dContactGeom>& all, int max, dContactGeom* out,
                                int stride) {
  const std::size_t n = all.size();
  std::size_t deepest = 0;
  for (std::size_t i = 1; i < n; ++i) {
    if (all[i].depth > all[deepest].depth) deepest = i;
  }
  std::swap(all[0], all[deepest]);
  double s = 0;
  for (std::size_t i = 1; i < n; ++i) s = std::max(s, contactSpan(all[i], all[0], 0.0));
  // gap[i]: candidate i's distance to the nearest contact kept so far (all[0..kept)); kept
  // between calls so that a pair's collision allocates nothing once it has grown.
  thread_local std::vector<double> gap;
  gap.assign(n, 0.0);
  // contacts touching, apart (depth <= 0) or in by rounding (kDepthResolution) count alike
  const double depth_floor = std::max({1e-6 * all[0].depth, kDepthResolution * s, 1e-12});
  for (std::size_t i = 1; i < n; ++i) gap[i] = contactSpan(all[i], all[0], s);
  std::size_t kept = 1;
  while (kept < static_cast<std::size_t>(max) && kept < n) {
    std::size_t best = kept;
    double best_score = -1;
    for (std::size_t i = kept; i < n; ++i) {
      const double score = gap[i] * std::max(all[i].depth, depth_floor);
      if (score > best_score) {
        best = i;
        best_score = score;
      }
    }
    if (!(gap[best] > 0)) break;  // only duplicates of kept contacts remain
    std::swap(all[kept], all[best]);
    std::swap(gap[kept], gap[best]);
    for (std::size_t i = kept + 1; i < n; ++i) {
      gap[i] = std::min(gap[i], contactSpan(all[i], all[kept], s));
    }
    ++kept;
  }
  std::sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(kept),
            [](const dContactGeom& a, const dContactGeom& b) {
              return std::tie(a.side1, a.side2, a.pos[0], a.pos[1], a.pos[2]) <
                     std::tie(b.side1, b.side2, b.pos[0], b.pos[1], b.pos[2]);
            });
  auto* bytes = reinterpret_cast<unsigned char*>(out);
  for (std::size_t i = 0; i < kept; ++i) {
    *reinterpret_cast<dContactGeom*>(bytes + i * static_cast<std::size_t>(stride)) = all[i];
  }
  return static_cast<int>(kept);
}

/// ODE's merge callback for contacts found on two triangles of one mesh (dTriTriMergeCallback).
inline int keepFirstTriangle(dGeomID, int first, int) {
  return first;
}

/// Sets detail::keepFirstTriangle as `mesh`'s merge callback for its lifetime (one collideSpanning
/// call) when the mesh has none, and removes it again, exceptions included.
class MergeCallbackScope {
 public:
  MergeCallbackScope() = default;
  void set(dGeomID mesh) {
    if (dGeomTriMeshGetTriMergeCallback(mesh) != nullptr) return;  // the user's own: left alone
    dGeomTriMeshSetTriMergeCallback(mesh, &keepFirstTriangle);
    meshes_[count_++] = mesh;
  }
  ~MergeCallbackScope() {
    for (int i = 0; i < count_; ++i) dGeomTriMeshSetTriMergeCallback(meshes_[i], nullptr);
  }
  MergeCallbackScope(const MergeCallbackScope&) = delete;
  MergeCallbackScope& operator=(const MergeCallbackScope&) = delete;

 private:
  dGeomID meshes_[2] = {nullptr, nullptr};
  int count_ = 0;
};

/// Partner classes whose contacts with a mesh name the mesh's triangle in side1 / side2 (ODE
/// 0.16.2) and may carry a seam's normal; the convex-trimesh collider gives a position in its own
/// list instead, and a sphere's contacts already have a face's normal (merged ones, when a user
/// turns merging on, an average ODE means to keep).
inline bool namesTheTriangle(dGeomID partner) {
  const int c = dGeomGetClass(partner);
  return c == dTriMeshClass || c == dBoxClass || c == dCapsuleClass || c == dCylinderClass;
}

/// How far (m) the deepest corner of the mesh partner's triangle of contact c lies below the
/// plane through `corner` with unit normal `face` (out of the fixture): the most any point of
/// that triangle can penetrate along the face normal, and so a bound on the contact's depth along
/// it. Infinite when c names no triangle of a mesh partner.
inline double partnerTriangleDepthBound(const dContactGeom& c, dGeomID partner, bool partner_is_g1,
                                        const double* corner, const MeshEdges::Normal& face) {
  const int triangle = partner_is_g1 ? c.side1 : c.side2;
  if (dGeomGetClass(partner) != dTriMeshClass || triangle < 0 ||
      triangle >= dGeomTriMeshGetTriangleCount(partner)) {
    return std::numeric_limits<double>::infinity();
  }
  dVector3 v[3];
  dGeomTriMeshGetTriangle(partner, triangle, &v[0], &v[1], &v[2]);
  double deepest = -std::numeric_limits<double>::infinity();
  for (const dVector3& p : v) {
    deepest = std::max(deepest, -((p[0] - corner[0]) * face.x + (p[1] - corner[1]) * face.y +
                                  (p[2] - corner[2]) * face.z));
  }
  return std::max(0.0, deepest);
}

/// The internal-edge correction of the file comment for contact c, whose fixture mesh is
/// `fixture` (c.g1 or c.g2) with edge table `edges`: returns whether it changed the contact.
inline bool correctInternalEdgeNormal(dContactGeom& c, dGeomID fixture, const MeshEdges& edges) {
  const bool fixture_is_g2 = c.g2 == fixture;
  const int triangle = fixture_is_g2 ? c.side2 : c.side1;
  const dGeomID partner = fixture_is_g2 ? c.g1 : c.g2;
  if (triangle < 0 || triangle >= edges.triangles() || !namesTheTriangle(partner)) return false;
  // The triangle the contact lies over: ODE names one, and places some contacts just past it (a
  // merged contact, a cylinder's rim over the next cell); across a smooth edge the walk goes on to
  // the neighbour, at most kMaxWalk triangles. The contact is corrected when it lies over a
  // triangle away from its sharp edges and corners.
  constexpr int kMaxWalk = 4;
  int t = triangle;
  double v[9];
  MeshEdges::Normal f;
  double dist = 0, cos_f = 0;
  const double sign = fixture_is_g2 ? 1.0 : -1.0;  // ODE's normal points out of g2 into g1
  for (int walk = 0;; ++walk) {
    if (!triangleOf(fixture, t, v, f)) return false;
    // ODE's normal turned out of the fixture, against this face's
    cos_f = sign * (c.normal[0] * f.x + c.normal[1] * f.y + c.normal[2] * f.z);
    if (walk == 0 && cos_f >= detail::kCosFaceNormalTolerance) {
      // The face's own normal (to rounding): only the depth may need bounding. ODE's
      // trimesh-trimesh test gives a part's face lying in the fixture's plane, where a face of
      // the part stands on it (the nut's side or hole), the face normal with the depth of the
      // fixture triangle's far corner behind that standing face: up to a fixture triangle's
      // size (0.96 mm on 1 mm triangles), which kicked a flat nut up and spinning.
      const double bound = partnerTriangleDepthBound(c, partner, fixture_is_g2, v, f);
      if (!(c.depth > bound)) return false;
      c.depth = bound;
      return true;
    }
    // a normal pointing into the face is a contact from the other side of a thin wall, not a seam
    if (cos_f < -0.5) return false;
    dist = (c.pos[0] - v[0]) * f.x + (c.pos[1] - v[1]) * f.y + (c.pos[2] - v[2]) * f.z;
    const double q[3] = {c.pos[0] - dist * f.x, c.pos[1] - dist * f.y, c.pos[2] - dist * f.z};
    double longest = 0, inside[3];
    insideEdges(v, f, q, inside, longest);  // an edge of length 0 reads 0: beside it
    // beside an edge: within the contact's depth of it, or 1 % of the triangle's size
    const double near = std::max(std::abs(c.depth), 0.01 * longest);
    int beyond = -1;  // the edge the point lies farthest beyond, when it is off this triangle
    for (int k = 0; k < 3; ++k) {
      if (inside[k] < -near && (beyond < 0 || inside[k] < inside[beyond])) beyond = k;
    }
    if (beyond >= 0) {
      const int next = edges.neighbour(t, beyond);
      if (next < 0 || walk + 1 >= kMaxWalk) return false;  // off the mesh's smooth surface
      t = next;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      if (inside[k] < near && !edges.smooth(t, k)) return false;
      // corner k + 1 joins edges k and k + 1
      const int k1 = (k + 1) % 3;
      if (inside[k] < near && inside[k1] < near && !edges.smoothCorner(t, k1)) return false;
    }
    break;
  }
  // depth: how far the contact point lies below the triangle's plane, and at least ODE's depth
  // projected on the new normal; at most how far a mesh partner's triangle reaches below that
  // plane (a bound only). Not that reach itself: the partner's triangle reaches past this one,
  // and on a curved fixture (the bowl's 4 degree cone) its deepest corner lies below this
  // triangle's plane where the fixture does not; that depth pushed a flat nut up every step and
  // made it hop (demos/results/bowl_feeder.md, section 9).
  const double depth = std::min(std::max(-dist, std::abs(c.depth) * std::max(0.0, cos_f)),
                                partnerTriangleDepthBound(c, partner, fixture_is_g2, v, f));
  c.normal[0] = sign * f.x;
  c.normal[1] = sign * f.y;
  c.normal[2] = sign * f.z;
  c.depth = std::max(0.0, depth);
  return true;
}

// ODE's trimesh-trimesh collider (debug builds, as Debian's) warns through dMessage when more
// contacts than its culling table holds fall into one of its 256 slots: "Trimesh-trimesh contach
// hash table bucket overflow - close contacts might not be culled". That happens only with the
// large buffers above, and its near-duplicates are what keepSpanningContacts thins out, so while
// collideSpanning collides a mesh pair that one message is dropped; every other message goes to
// the handler that was installed (ODE's own printing when none was).
inline thread_local dMessageFunction* forward_message = nullptr;

inline void dropTrimeshCullingMessage(int num, const char* format, va_list ap) {
  va_list copy;
  va_copy(copy, ap);
  char text[512];
  std::vsnprintf(text, sizeof text, format, copy);
  va_end(copy);
  if (std::strstr(text, "hash table bucket overflow") != nullptr) return;
  if (forward_message != nullptr && forward_message != &dropTrimeshCullingMessage) {
    forward_message(num, format, ap);
    return;
  }
  std::fflush(stdout);
  std::fprintf(stderr, "\nODE Message %d: %s\n", num, text);
  std::fflush(stderr);
}

// Installs dropTrimeshCullingMessage for its lifetime (one dCollide call). ODE's handler is one
// global pointer: when the filter is already installed (another thread colliding at the same
// time), the handler it forwards to stays the one found first.
class TrimeshCullingMessageFilter {
 public:
  TrimeshCullingMessageFilter() : previous_(dGetMessageHandler()) {
    if (previous_ != &dropTrimeshCullingMessage) forward_message = previous_;
    dSetMessageHandler(&dropTrimeshCullingMessage);
  }
  ~TrimeshCullingMessageFilter() { dSetMessageHandler(previous_); }
  TrimeshCullingMessageFilter(const TrimeshCullingMessageFilter&) = delete;
  TrimeshCullingMessageFilter& operator=(const TrimeshCullingMessageFilter&) = delete;

 private:
  dMessageFunction* previous_;
};

}  // namespace detail

/// dCollide(o1, o2, max, out, stride) where neither geom is a triangle mesh; for a pair with
/// one, every contact ODE finds, reduced to at most `max` that span the set (file comment).
/// `max` is dCollide's flags: its low 16 bits the number of records `out` has room for (each
/// `stride` bytes), its high bits options (CONTACTS_UNIMPORTANT: any contacts will do, which the
/// spanning set is). A count of 0 collides nothing and returns 0 (dCollide stops the program
/// with ODE's debug message). `scratch` is the caller's memory, reused between calls. Returns
/// the number of contacts written, at most the count. While it
/// collides a mesh pair, ODE's message handler is replaced by one that drops the trimesh-trimesh
/// culling warning (detail::dropTrimeshCullingMessage) and forwards every other message.
inline int collideSpanning(dGeomID o1, dGeomID o2, int max, dContactGeom* out, int stride,
                           MeshCollisionScratch& scratch) {
  const int room = max & 0xffff;  // ODE's NUMC_MASK
  if (room < 1) return 0;
  if (dGeomGetClass(o1) != dTriMeshClass && dGeomGetClass(o2) != dTriMeshClass) {
    return dCollide(o1, o2, max, out, stride);
  }
  // The cylinder- and capsule-trimesh colliders stop at `capacity` contacts and then merge
  // near-duplicates (a vertex shared by several triangles), so they may return fewer than
  // `capacity` having missed triangles: for them the buffer grows until the count stops changing
  // (no contact at all ends it at once). The other mesh colliders return a full buffer when they
  // had more.
  const auto stops_then_merges = [](dGeomID g) {
    return dGeomGetClass(g) == dCylinderClass || dGeomGetClass(g) == dCapsuleClass;
  };
  const bool merges = stops_then_merges(o1) || stops_then_merges(o2);
  int capacity = std::max(kMeshContactCapacity, room);
  int n = 0, previous = -1;
  const detail::TrimeshCullingMessageFilter filter;
  // The fixture meshes of the pair, whose normals are corrected (file comment); their edge tables
  // are looked up once per call.
  dGeomID fixtures[2] = {nullptr, nullptr};
  const MeshEdges* fixture_edges[2] = {nullptr, nullptr};
  for (int i = 0; i < 2; ++i) {
    const dGeomID g = i == 0 ? o1 : o2;
    if (dGeomGetClass(g) == dTriMeshClass && scratch.fixture(g)) {
      fixtures[i] = g;
      fixture_edges[i] = &scratch.edgesOf(g);
    }
  }
  // ODE's trimesh-trimesh test merges contacts found at one point on two triangles (depths
  // within its epsilon, normals averaged) and, without a merge callback, forgets the triangle
  // (side -1). For the call, a fixture without one gets detail::keepFirstTriangle, so that such
  // a contact on a seam can be corrected (it lies on both triangles; at a sharp edge or corner
  // either finds it); the callback is removed again after the call.
  detail::MergeCallbackScope merge_callbacks;
  for (int i = 0; i < 2; ++i) {
    const dGeomID other = i == 0 ? o2 : o1;
    if (fixtures[i] && dGeomGetClass(other) == dTriMeshClass) merge_callbacks.set(fixtures[i]);
  }
  while (true) {
    scratch.contacts.resize(static_cast<std::size_t>(capacity));
    n = dCollide(o1, o2, capacity, scratch.contacts.data(), sizeof(dContactGeom));
    if (n == 0 || capacity >= kMeshContactCapacityLimit) break;
    if (n < capacity && !(merges && n != previous)) break;
    previous = n;
    capacity = std::min(2 * capacity, kMeshContactCapacityLimit);
  }
  if (n <= 0) return 0;
  scratch.contacts.resize(static_cast<std::size_t>(n));
  for (dContactGeom& c : scratch.contacts) {
    for (int i = 0; i < 2; ++i) {
      if (fixtures[i] && (c.g1 == fixtures[i] || c.g2 == fixtures[i]) &&
          detail::correctInternalEdgeNormal(c, fixtures[i], *fixture_edges[i])) {
        break;
      }
    }
  }
  return detail::keepSpanningContacts(scratch.contacts, room, out, stride);
}

}  // namespace rheofeed
