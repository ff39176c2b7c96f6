// SPDX-License-Identifier: MIT
/// @file narrow_phase.hpp
/// One colliding pair's contacts, with none cut off by the order in which ODE visits a mesh's
/// triangles.
///
/// dCollide(o1, o2, max, ...) returns at most `max` contacts, and ODE's triangle-mesh colliders
/// choose which: the cylinder-trimesh collider (ODE 0.16.2) stops at the first `max` it finds in
/// OPCODE's triangle order, the box-trimesh and trimesh-trimesh colliders replace their shallowest
/// once the buffer is full. A part touching more triangles than `max` (a nut lying on a finely
/// tessellated floor beside a wall) then gets contacts on one side of its footprint, or on one face
/// only, tips into the mesh and sinks through it over a few steps. With rheofeed's former 8
/// contacts per pair, the mesh bowl of demos/scenes/bowl_feeder.json at h = 0.01 s lost 9 of 12
/// cylinder nuts and 3 of 12 mesh nuts in 12 s on its calibrated drift; with every contact seen,
/// none (demos/results/bowl_feeder.md).
///
/// collideSpanning asks ODE for every contact of a pair that involves a triangle mesh (a buffer of
/// kMeshContactCapacity, doubled while ODE fills it, and for a cylinder while the count still
/// grows, up to kMeshContactCapacityLimit) and keeps
/// `max` of them that span the set: the deepest first, then each time the candidate whose
/// distance to the nearest contact kept, times its depth, is largest, the distance between
/// contacts i and k being
///   |p_i - p_k| + s (1 - n_i . n_k),
/// with s the largest distance of a candidate from the deepest contact (m). So a contact on each
/// face the part touches (floor and wall: normals apart) and the corners of its footprint are
/// kept, ahead of the shallow side-normal contacts ODE's cylinder collider makes at the edges of
/// coplanar triangles; exact duplicates are dropped. Pairs without a mesh go to dCollide(o1, o2,
/// max) unchanged.
///
/// Header only: the plugin's ContactCollider and the reference world (which does not link the
/// plugin library) both use it.
#pragma once

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace rheofeed {

/// First buffer size (contacts) for a pair with a triangle mesh.
inline constexpr int kMeshContactCapacity = 64;
/// Largest buffer size (contacts) for one pair; dCollide's count field holds at most 0xffff.
inline constexpr int kMeshContactCapacityLimit = 4096;

namespace detail {

inline double contactSpan(const dContactGeom& a, const dContactGeom& b, double s) {
  const double dx = a.pos[0] - b.pos[0], dy = a.pos[1] - b.pos[1], dz = a.pos[2] - b.pos[2];
  const double cos_n =
      a.normal[0] * b.normal[0] + a.normal[1] * b.normal[1] + a.normal[2] * b.normal[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz) + s * (1.0 - cos_n);
}

/// Keeps at most `max` of `all` spanning the set (see the file comment), `max` < all.size(); writes
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
  // gap[i]: candidate i's distance to the nearest contact kept so far (all[0..kept)).
  std::vector<double> gap(n);
  // contacts touching or apart (depth <= 0) still count, as if 1e-6 of the deepest in
  const double depth_floor = std::max(1e-6 * all[0].depth, 1e-12);
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
  auto* bytes = reinterpret_cast<unsigned char*>(out);
  for (std::size_t i = 0; i < kept; ++i) {
    *reinterpret_cast<dContactGeom*>(bytes + i * static_cast<std::size_t>(stride)) = all[i];
  }
  return static_cast<int>(kept);
}

}  // namespace detail

/// dCollide(o1, o2, max, out, stride) where neither geom is a triangle mesh; for a pair with
/// one, every contact ODE finds, reduced to at most `max` that span the set (file comment).
/// `max` >= 1 and `out` room for `max` records of `stride` bytes, as dCollide. `scratch` is
/// the caller's buffer, reused between calls. Returns the number of contacts written.
inline int collideSpanning(dGeomID o1, dGeomID o2, int max, dContactGeom* out, int stride,
                           std::vector<dContactGeom>& scratch) {
  if (dGeomGetClass(o1) != dTriMeshClass && dGeomGetClass(o2) != dTriMeshClass) {
    return dCollide(o1, o2, max, out, stride);
  }
  // ODE's cylinder-trimesh collider stops at `capacity` contacts and then merges duplicates (a
  // vertex shared by several triangles), so it may return fewer than `capacity` having missed
  // triangles: for it the buffer grows until the count stops changing. The other mesh colliders
  // return a full buffer when they had more.
  const bool merges_after_stop =
      dGeomGetClass(o1) == dCylinderClass || dGeomGetClass(o2) == dCylinderClass;
  int capacity = std::max(kMeshContactCapacity, max);
  int n = 0, previous = -1;
  while (true) {
    scratch.resize(static_cast<std::size_t>(capacity));
    n = dCollide(o1, o2, capacity, scratch.data(), sizeof(dContactGeom));
    if (capacity >= kMeshContactCapacityLimit) break;
    if (n < capacity && !(merges_after_stop && n != previous)) break;
    previous = n;
    capacity = std::min(2 * capacity, kMeshContactCapacityLimit);
  }
  if (n <= 0) return 0;
  scratch.resize(static_cast<std::size_t>(n));
  if (n <= max) {  // all of them, in ODE's order
    auto* bytes = reinterpret_cast<unsigned char*>(out);
    for (int i = 0; i < n; ++i) {
      *reinterpret_cast<dContactGeom*>(bytes + static_cast<std::size_t>(i) * stride) =
          scratch[static_cast<std::size_t>(i)];
    }
    return n;
  }
  return detail::keepSpanningContacts(scratch, max, out, stride);
}

}  // namespace rheofeed
