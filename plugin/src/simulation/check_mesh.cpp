// SPDX-License-Identifier: MIT
// The wall thickness of a fixture mesh (check.hpp, meshWallThickness), in O(n log n).
//
// One ray per triangle, from its centroid inwards; the nearest other triangle it meets is the
// far side of the wall. The triangles are sorted into a bounding-volume tree (axis-aligned
// boxes, split at the median centroid along the longest axis, at most kLeafSize triangles per
// leaf), and a ray visits only the boxes it enters before its nearest hit so far, the nearer
// child of a node first. Each
// ray/triangle test is the Moller-Trumbore test of the all-pairs version, with the same
// arithmetic, and the nearest hit is a minimum, which does not depend on the order of the
// tests: the result is the all-pairs one exactly. The boxes are grown by a relative 1e-9 of
// the mesh's size, so that a hit on a triangle's edge is never culled by the rounding of the
// box test.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include "check_internal.hpp"

namespace rheofeed::scene {
namespace {

constexpr int kLeafSize = 4;

struct Node {
  double lo[3], hi[3];
  int left = -1, right = -1;  // children (inner node), or -1
  int axis = 0;               // split axis: left holds the lower centroids along it
  int begin = 0, end = 0;     // triangle range in the order (leaf)
};

class TriangleTree {
 public:
  TriangleTree(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const std::vector<Vec3>& c,
               double pad)
      : a_(a), b_(b), c_(c), pad_(pad), order_(a.size()) {
    std::iota(order_.begin(), order_.end(), 0);
    centroid_.reserve(a.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      centroid_.push_back((1.0 / 3.0) * (a[i] + b[i] + c[i]));
    if (!a.empty()) build(0, static_cast<int>(a.size()));
  }

  // The nearest hit distance > `min_distance` along the unit ray o + t d of any triangle but
  // `self`; infinity when none. `tests` counts the box and triangle tests.
  double nearest(const Vec3& o, const Vec3& d, std::size_t self, double min_distance,
                 long long& tests) const {
    double best = checks::kInf;
    if (nodes_.empty()) return best;
    const double inv[3] = {1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
    const double org[3] = {o.x, o.y, o.z}, dir[3] = {d.x, d.y, d.z};
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[static_cast<std::size_t>(stack[--top])];
      ++tests;
      if (!enters(n, org, dir, inv, best)) continue;
      if (n.left < 0) {
        for (int k = n.begin; k < n.end; ++k) {
          const std::size_t j = order_[static_cast<std::size_t>(k)];
          if (j == self) continue;
          ++tests;
          const double dist = hit(o, d, j);
          if (dist > min_distance) best = std::min(best, dist);
        }
        continue;
      }
      // Nearer child last (popped first): its hits shrink `best` before the farther is tried.
      const bool left_first = dir[n.axis] >= 0;
      stack[top++] = left_first ? n.right : n.left;
      stack[top++] = left_first ? n.left : n.right;
    }
    return best;
  }

 private:
  double hit(const Vec3& origin, const Vec3& dir, std::size_t j) const {
    return checks::rayTriangleDistance(origin, dir, a_[j], b_[j], c_[j]);
  }

  // Whether the ray enters the node's box at a distance <= best (and >= 0 at its far side).
  static bool enters(const Node& n, const double o[3], const double d[3], const double inv[3],
                     double best) {
    double t0 = 0, t1 = best;
    for (int k = 0; k < 3; ++k) {
      if (d[k] == 0) {
        if (o[k] < n.lo[k] || o[k] > n.hi[k]) return false;
        continue;
      }
      double a = (n.lo[k] - o[k]) * inv[k], b = (n.hi[k] - o[k]) * inv[k];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
      if (t0 > t1) return false;
    }
    return true;
  }

  int build(int begin, int end) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    Node n;
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = checks::kInf;
      n.hi[k] = -checks::kInf;
    }
    double clo[3] = {checks::kInf, checks::kInf, checks::kInf};
    double chi[3] = {-checks::kInf, -checks::kInf, -checks::kInf};
    for (int k = begin; k < end; ++k) {
      const std::size_t j = order_[static_cast<std::size_t>(k)];
      for (const Vec3* v : {&a_[j], &b_[j], &c_[j]}) {
        const double x[3] = {v->x, v->y, v->z};
        for (int i = 0; i < 3; ++i) {
          n.lo[i] = std::min(n.lo[i], x[i] - pad_);
          n.hi[i] = std::max(n.hi[i], x[i] + pad_);
        }
      }
      const double m[3] = {centroid_[j].x, centroid_[j].y, centroid_[j].z};
      for (int i = 0; i < 3; ++i) {
        clo[i] = std::min(clo[i], m[i]);
        chi[i] = std::max(chi[i], m[i]);
      }
    }
    n.begin = begin;
    n.end = end;
    if (end - begin > kLeafSize) {
      int axis = 0;
      for (int i = 1; i < 3; ++i) {
        if (chi[i] - clo[i] > chi[axis] - clo[axis]) axis = i;
      }
      const int mid = begin + (end - begin) / 2;
      auto key = [&](std::size_t j) {
        const Vec3& m = centroid_[j];
        return axis == 0 ? m.x : axis == 1 ? m.y : m.z;
      };
      std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                       [&](std::size_t x, std::size_t y) { return key(x) < key(y); });
      n.axis = axis;
      n.left = build(begin, mid);
      n.right = build(mid, end);
    }
    nodes_[static_cast<std::size_t>(index)] = n;
    return index;
  }

  const std::vector<Vec3>&a_, &b_, &c_;
  const double pad_;
  std::vector<std::size_t> order_;
  std::vector<Vec3> centroid_;
  std::vector<Node> nodes_;
};

}  // namespace

MeshWallThickness meshWallThickness(const TriangleMesh& mesh, double scale, long long max_tests) {
  const std::vector<double>& v = mesh.vertices;
  const std::vector<int>& t = mesh.triangles;
  auto vert = [&](int i) { return scale * Vec3{v[3 * i], v[3 * i + 1], v[3 * i + 2]}; };
  const std::size_t n = t.size() / 3;
  std::vector<Vec3> a(n), b(n), c(n);
  double size = 0;
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = vert(t[3 * i]);
    b[i] = vert(t[3 * i + 1]);
    c[i] = vert(t[3 * i + 2]);
    for (const Vec3* p : {&a[i], &b[i], &c[i]}) {
      size = std::max({size, std::abs(p->x), std::abs(p->y), std::abs(p->z)});
    }
  }
  const TriangleTree tree(a, b, c, 1e-9 * size + 1e-300);
  MeshWallThickness result;
  std::vector<std::pair<double, double>> walls;  // thickness, area
  double total_area = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 normal = cross(b[i] - a[i], c[i] - a[i]);
    const double area2 = norm(normal);
    if (!(area2 > 0)) continue;
    const Vec3 dir = (-1.0 / area2) * normal;  // inwards
    const Vec3 origin = (1.0 / 3.0) * (a[i] + b[i] + c[i]);
    const double nearest = tree.nearest(origin, dir, i, 1e-9 * std::sqrt(area2), result.ray_tests);
    total_area += 0.5 * area2;
    if (std::isfinite(nearest)) walls.emplace_back(nearest, 0.5 * area2);
    if (result.ray_tests > max_tests) {
      result.measured = false;
      return result;
    }
  }
  std::sort(walls.begin(), walls.end());
  double area = 0;
  for (const auto& [thickness, share] : walls) {
    area += share;
    if (area >= kThinShare * total_area) {
      result.thickness = thickness;
      return result;
    }
  }
  result.thickness = walls.empty() ? 0 : walls.back().first;
  return result;
}

}  // namespace rheofeed::scene
