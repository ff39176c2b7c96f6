// SPDX-License-Identifier: MIT
// A part's sizes (partSizes) and the point of it the tunnelling checks follow (simulation.hpp,
// partAnchor; the rule is in simulation.cpp, "Tunnelling"): the centre of mass, or for a mesh part
// whose centre lies outside its own solid (a nut's, in its hole), a point deep in its material.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "check_internal.hpp"
#include "simulation_internal.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Vec3 meshVertex(const TriangleMesh& m, std::size_t triangle, int corner) {
  const double* v = &m.vertices[3 * static_cast<std::size_t>(m.triangles[3 * triangle + corner])];
  return {v[0], v[1], v[2]};
}

// Distance from p to the triangle (a, b, c): its closest point by the triangle's Voronoi
// regions (Ericson, Real-Time Collision Detection, 5.1.5).
double triangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return norm(ap);
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return norm(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return norm(ap - (d1 / (d1 - d3)) * ab);
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return norm(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return norm(ap - (d2 / (d2 - d6)) * ac);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return norm(bp - ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b));
  }
  const double denom = 1 / (va + vb + vc);
  return norm(ap - (vb * denom) * ab - (vc * denom) * ac);
}

double meshDistance(const TriangleMesh& m, const Vec3& p) {
  double best = kInf;
  for (std::size_t t = 0; 3 * t + 2 < m.triangles.size(); ++t) {
    best = std::min(
        best, triangleDistance(p, meshVertex(m, t, 0), meshVertex(m, t, 1), meshVertex(m, t, 2)));
  }
  return best;
}

// Distances t > 0 at which the ray o + t d meets the mesh's triangles (either side), sorted.
std::vector<double> rayCrossings(const TriangleMesh& m, const Vec3& o, const Vec3& d) {
  std::vector<double> hits;
  for (std::size_t t = 0; 3 * t + 2 < m.triangles.size(); ++t) {
    const double dist = checks::rayTriangleDistance(o, d, meshVertex(m, t, 0), meshVertex(m, t, 1),
                                                    meshVertex(m, t, 2));
    if (dist > 0) hits.push_back(dist);
  }
  std::sort(hits.begin(), hits.end());
  return hits;
}

}  // namespace

void partSizes(const Shape& s, double& min_half, double& radius) {
  switch (s.kind) {
    case Shape::Kind::Box:
      min_half = 0.5 * std::min({s.size.x, s.size.y, s.size.z});
      radius = 0.5 * norm(s.size);
      return;
    case Shape::Kind::Sphere:
      min_half = radius = s.radius;
      return;
    case Shape::Kind::Cylinder:
      min_half = std::min(s.radius, 0.5 * s.length);
      radius = std::hypot(s.radius, 0.5 * s.length);
      return;
    case Shape::Kind::Capsule:
      min_half = s.radius;
      radius = s.radius + 0.5 * s.length;
      return;
    case Shape::Kind::Mesh: {
      radius = 0;
      min_half = 0;
      if (!s.mesh_data || s.mesh_data->vertices.size() < 3) return;
      for (std::size_t k = 0; k + 2 < s.mesh_data->vertices.size(); k += 3) {
        const double* v = &s.mesh_data->vertices[k];
        radius = std::max(radius, norm(Vec3{v[0], v[1], v[2]}));
      }
      const Vec3 e = checks::meshBoxExtents(*s.mesh_data, 1.0);
      min_half = 0.5 * std::min({e.x, e.y, e.z});
      return;
    }
    case Shape::Kind::Plane:
      break;
  }
  min_half = radius = 0;
}

PartAnchor partAnchor(const Shape& shape) {
  PartAnchor anchor;
  double radius = 0;
  partSizes(shape, anchor.clearance, radius);
  const std::shared_ptr<const TriangleMesh>& mesh =
      shape.collision_mesh_data ? shape.collision_mesh_data : shape.mesh_data;
  if (shape.kind != Shape::Kind::Mesh || !mesh || checks::windingNumber(*mesh, {}) > 0.5)
    return anchor;
  // Spans between consecutive crossings closer than this (m) are one crossing counted twice (a
  // ray through an edge or a vertex shared by several triangles).
  const double same = 1e-9 * radius;
  // Directions: a cube's 26 (faces, edges, corners), and towards the centroids of up to
  // kMaxCentroidRays of the mesh's triangles, spread through it: a ray towards a triangle meets
  // it, so a thin part in any orientation in its file (a ring tilted in its CAD frame, which the
  // 26 alone can all miss) gets candidates.
  constexpr std::size_t kMaxCentroidRays = 256;
  std::vector<Vec3> directions;
  for (int k = 0; k < 27; ++k) {
    if (k != 13) directions.push_back({k % 3 - 1.0, (k / 3) % 3 - 1.0, k / 9 - 1.0});  // not 0
  }
  const std::size_t triangles = mesh->triangles.size() / 3;
  const std::size_t stride =
      std::max<std::size_t>(1, (triangles + kMaxCentroidRays - 1) / kMaxCentroidRays);
  for (std::size_t t = 0; t < triangles; t += stride) {
    const Vec3 c =
        (1.0 / 3) * (meshVertex(*mesh, t, 0) + meshVertex(*mesh, t, 1) + meshVertex(*mesh, t, 2));
    if (norm(c) > same) directions.push_back(c);
  }
  double deepest = 0;
  for (const Vec3& dir : directions) {
    const Vec3 d = (1 / norm(dir)) * dir;
    const std::vector<double> hits = rayCrossings(*mesh, {}, d);
    for (std::size_t j = 1; j < hits.size(); ++j) {
      if (hits[j] - hits[j - 1] <= same) continue;
      const Vec3 x = (0.5 * (hits[j - 1] + hits[j])) * d;
      if (!(checks::windingNumber(*mesh, x) > 0.5)) continue;
      const double depth = meshDistance(*mesh, x);
      if (depth > deepest) {
        deepest = depth;
        anchor = {x, depth};
      }
    }
  }
  return anchor;
}

}  // namespace rheofeed::scene
