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
/// Header only: the plugin's ContactCollider and the reference world (which does not link the
/// plugin library) both use it.
#pragma once

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <tuple>
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
/// `max` >= 1 and `out` room for `max` records of `stride` bytes, as dCollide. `scratch` is
/// the caller's buffer, reused between calls. Returns the number of contacts written. While it
/// collides a mesh pair, ODE's message handler is replaced by one that drops the trimesh-trimesh
/// culling warning (detail::dropTrimeshCullingMessage) and forwards every other message.
inline int collideSpanning(dGeomID o1, dGeomID o2, int max, dContactGeom* out, int stride,
                           std::vector<dContactGeom>& scratch) {
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
  int capacity = std::max(kMeshContactCapacity, max);
  int n = 0, previous = -1;
  const detail::TrimeshCullingMessageFilter filter;
  while (true) {
    scratch.resize(static_cast<std::size_t>(capacity));
    n = dCollide(o1, o2, capacity, scratch.data(), sizeof(dContactGeom));
    if (n == 0 || capacity >= kMeshContactCapacityLimit) break;
    if (n < capacity && !(merges && n != previous)) break;
    previous = n;
    capacity = std::min(2 * capacity, kMeshContactCapacityLimit);
  }
  if (n <= 0) return 0;
  scratch.resize(static_cast<std::size_t>(n));
  return detail::keepSpanningContacts(scratch, max, out, stride);
}

}  // namespace rheofeed
