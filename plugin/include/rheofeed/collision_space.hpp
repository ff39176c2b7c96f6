// SPDX-License-Identifier: MIT
/// @file collision_space.hpp
/// A broad-phase collision space that pairs every overlapping pair of geoms.
///
/// Stock ODE's hash space (dHashSpaceCreate, ODE 0.16.2 and earlier) misses pairs: it hashes a
/// column of cells from the slot of its lowest cell stepped by one, in unsigned arithmetic that
/// wraps, so a geom whose bounding box spans the plane z = 0 in the cell x = y = 0 of its level
/// (cell size 2^level m; a 0.5-1 m trough wall standing on a floor whose top is z = 0, at x, y in
/// [0, 1) m) is never paired with the small geoms in the cells above z = 0. Parts then pass
/// through that fixture as if it were absent (rheofeed's main demo at 1000 parts lost 306 of them
/// through one side wall, and none through the mirror-image wall). rheofeed's patched ODE fixes
/// it (patches/0004-hash-space-cell-slots, dCheckConfiguration("ODE_EXT_hash_space_cells")).
///
/// createCollisionSpace gives the hash space where the linked ODE has the fix, and ODE's
/// sweep-and-prune space (dSweepAndPruneSpaceCreate, all three axes; exact, O(n log n)) on a
/// stock ODE. Applications that build their own space on a stock ODE should do the same, or
/// use dSimpleSpace for small scenes.
///
/// The two are equally exact and differ in cost and in the order in which they hand out pairs
/// (which moves a chaotic crowd's trajectory): on the main demo's trough at 1000 and 2000 parts,
/// 4 seeds each, sweep-and-prune took 10-25 % less CPU per step (its collision stage 2.4x
/// cheaper at 2000 parts) and its losses were not distinguishable from the hash space's (35
/// against 24 parts through a fixture in 8 runs; demos/results/crowd_leaks.md, section 6).
/// Scenes choose with solver.broad_phase.
///
/// The hash space is made with cell levels kHashSpaceMinLevel..kHashSpaceMaxLevel (cells of
/// 2^level m, 1/1024 m to 1024 m) instead of ODE's default -3..10: ODE files a geom at the
/// level whose cell covers its bounding box but never below the minimum, so with the default
/// every part smaller than 125 mm shares 125 mm cells with dozens of others in a heap and every
/// pair in a cell is tested. On the main demo's trough at 1000 parts the finer levels took a
/// third off the collision stage (crowd_leaks.md, section 9).
#pragma once

#include <ode/ode.h>

#include <optional>
#include <stdexcept>

namespace rheofeed {

/// True when the linked ODE's hash space has rheofeed's cell-slot fix (patches/0004). Header
/// only (the reference world uses it without the plugin library); ODE must be initialised.
inline bool odeHashSpaceIsSound() {
  static const bool sound = dCheckConfiguration("ODE_EXT_hash_space_cells") != 0;
  return sound;
}

/// The hash space's cell levels (cell edge 2^level m): parts down to about 1 mm get cells of
/// their own size; geoms larger than 1024 m (and planes) go to ODE's list of large geoms.
inline constexpr int kHashSpaceMinLevel = -10;
inline constexpr int kHashSpaceMaxLevel = 10;

/// A broad phase createCollisionSpace can be asked for.
enum class BroadPhase {
  Hash,           ///< dHashSpaceCreate: only where odeHashSpaceIsSound()
  SweepAndPrune,  ///< dSweepAndPruneSpaceCreate(parent, dSAP_AXES_XYZ): any ODE
};
/// Printable (and scene file) name: "hash" or "sweep_and_prune".
inline const char* toString(BroadPhase broad_phase) {
  return broad_phase == BroadPhase::Hash ? "hash" : "sweep_and_prune";
}

/// A new top-level (parent null) or child space that pairs every overlapping pair of geoms:
/// the one of `broad_phase`, or when it is unset dHashSpaceCreate(parent) (levels
/// kHashSpaceMinLevel..kHashSpaceMaxLevel) where
/// odeHashSpaceIsSound() and dSweepAndPruneSpaceCreate(parent, dSAP_AXES_XYZ) elsewhere.
/// Throws std::invalid_argument for BroadPhase::Hash on an ODE whose hash space misses pairs
/// (no patches/0004): it would let parts through fixtures. Destroy it with dSpaceDestroy.
inline dSpaceID createCollisionSpace(dSpaceID parent,
                                     std::optional<BroadPhase> broad_phase = std::nullopt) {
  if (!broad_phase) {
    broad_phase = odeHashSpaceIsSound() ? BroadPhase::Hash : BroadPhase::SweepAndPrune;
  }
  if (*broad_phase == BroadPhase::SweepAndPrune) {
    return dSweepAndPruneSpaceCreate(parent, dSAP_AXES_XYZ);
  }
  if (!odeHashSpaceIsSound()) {
    throw std::invalid_argument(
        "broad phase hash: the linked ODE's hash space misses pairs (it lacks rheofeed's "
        "patches/0004-hash-space-cell-slots); use sweep_and_prune");
  }
  dSpaceID space = dHashSpaceCreate(parent);
  dHashSpaceSetLevels(space, kHashSpaceMinLevel, kHashSpaceMaxLevel);
  return space;
}

/// The broad phase of a space createCollisionSpace made (for reporting).
inline BroadPhase broadPhaseOf(dSpaceID space) {
  return dSpaceGetClass(space) == dHashSpaceClass ? BroadPhase::Hash : BroadPhase::SweepAndPrune;
}

}  // namespace rheofeed
