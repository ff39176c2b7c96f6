// SPDX-License-Identifier: MIT
// The scene check before the run (check.hpp): the scene is measured once into a CheckContext
// (the thinnest, lightest and heaviest parts; every fixture geom's bounds, the thinnest geom,
// the lowest top, the fastest surface), then one function per hazard kind runs over it
// (check_hazards.cpp). Every criterion is stated next to its code there; the mass-ratio limits
// are measured, and the command that measures them is given with their table
// (check_mass_ratio.cpp).
#include "rheofeed/simulation/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "check_internal.hpp"
#include "rheofeed/scene/run_step.hpp"

namespace rheofeed::scene {
namespace {

using namespace checks;

// Parts: the thinnest, the lightest and the heaviest over all families.
void measureParts(CheckContext& c) {
  for (std::size_t i = 0; i < c.scene.parts.size(); ++i) {
    const PartRange r = partRange(c.scene.parts[i]);
    c.total_parts += c.scene.parts[i].count;
    if (r.thinnest < c.thinnest_part) {
      c.thinnest_part = r.thinnest;
      c.thin_family = i;
      c.part_note = r.note;
    }
    if (r.light.mass > 0 && r.light.mass < c.lightest) {
      c.lightest = r.light.mass;
      c.light_thickness = r.light.thickness;
      c.light_family = i;
    }
    if (r.heavy.mass > c.heaviest) {
      c.heaviest = r.heavy.mass;
      c.heavy_family = i;
    }
  }
}

// The fastest surface point of fixture f (m/s) over its bounds `all`, and where it comes from.
double surfaceSpeed(const CheckContext& c, std::size_t f, const Box3& all, std::string& source) {
  const FeederLaw& law = c.scene.fixtures[f].law;
  switch (law.kind) {
    case FeederLaw::Kind::None:
      return 0;
    case FeederLaw::Kind::Belt:
      source = idx("fixtures", f) + ".law.belt.speed";
      return std::abs(law.belt_speed);
    case FeederLaw::Kind::Drift:
      source = idx("fixtures", f) + ".law.drift (over the fixture's extent)";
      return twistSpeedOver(law.drift, all);
    case FeederLaw::Kind::Vibration: {
      const Vibration& v = law.vibration;
      if (c.full || law.drift_model != DriftModel::CalibratedDrift) {
        // A point mass's cycle-averaged drift stays below the vibration's peak velocity at
        // its point; the local law multiplies it by the part family's efficiency.
        const double w = 2 * kPi * v.frequency;
        const double r = all.bounded ? radiusFromAxis(all, v.axis_origin, v.axis_direction) : 0;
        double factor = 1;
        if (!c.full) {
          for (double e : law.efficiency) factor = std::max(factor, e);
        }
        source = idx("fixtures", f) + ".law.vibration (peak velocity 2 pi f (A + theta r)" +
                 (factor > 1 ? " times the largest efficiency factor)" : ")");
        return factor * (w * v.amplitude + w * v.torsion_amplitude * r);
      }
      if (law.has_calibrated_drift) {
        source = idx("fixtures", f) + ".law.calibrated_drift (over the fixture's extent)";
        return twistSpeedOver(law.calibrated_drift, all);
      }
      return 0;
    }
  }
  return 0;
}

// Fixtures: bounds, the thinnest geom, the lowest top, the fastest surface.
void measureFixtures(CheckContext& c) {
  for (std::size_t f = 0; f < c.scene.fixtures.size(); ++f) {
    const Fixture& fx = c.scene.fixtures[f];
    Box3 all;
    for (std::size_t k = 0; k < fx.geoms.size(); ++k) {
      const Fixture::Geom& gm = fx.geoms[k];
      const Box3 b = geomBounds(gm);
      const bool open_mesh = gm.shape.kind == Shape::Kind::Mesh &&
                             (!gm.shape.mesh_data || !closedMesh(*gm.shape.mesh_data));
      c.geoms.push_back({f, k, b, open_mesh});
      if (b.bounded) {
        all.add(b.lo);
        all.add(b.hi);
        c.lowest_top = std::min(c.lowest_top, maxAlong(b, c.up));
      } else {
        all.bounded = false;
        if (gm.shape.kind == Shape::Kind::Plane && dot(gm.shape.plane_normal, c.up) > 0.5) {
          c.lowest_top =
              std::min(c.lowest_top, gm.shape.plane_offset / dot(gm.shape.plane_normal, c.up));
        }
      }
      const Thickness t = fixtureThickness(gm.shape);
      if (!t.measured) {
        c.skipped.push_back(
            {geomPath(f, k), gm.shape.mesh_data->triangles.size() / 3, t.ray_tests});
      }
      if (t.value < c.thinnest_fixture) {
        c.thinnest_fixture = t.value;
        c.thin_geom = geomPath(f, k);
        c.fixture_note = t.note;
      }
    }
    std::string source;
    const double speed = surfaceSpeed(c, f, all, source);
    if (speed > c.surface_speed) {
      c.surface_speed = speed;
      c.speed_source = source;
    }
  }
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
    case Hazard::Kind::ExtremeVibration:
      return "extreme_vibration";
    case Hazard::Kind::AgainstConveyingDirection:
      return "against_conveying_direction";
    case Hazard::Kind::SpawnInsideFixture:
      return "spawn_inside_fixture";
    case Hazard::Kind::SpawnOverNothing:
      return "spawn_over_nothing";
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
    case Hazard::Kind::CheckSkipped:
      return "check_skipped";
  }
  return "unknown";
}
std::vector<Hazard> checkScene(const Scene& scene, Method method) {
  CheckContext c(scene, method);
  c.h = scene.solver.time_step;
  c.g = norm(scene.gravity);
  c.up = c.g > 0 ? (-1.0 / c.g) * scene.gravity : Vec3{0, 0, 1};
  c.full = isFullVibration(method);
  c.ode = method == Method::OdeRheonomic || method == Method::OdeFullVibration;
  c.step_field = stepField(scene, method);
  measureParts(c);
  measureFixtures(c);

  std::vector<Hazard> out;
  checkTunnelling(c, out);
  checkFlushWalls(c, out);
  checkMassRatio(c, out);
  checkCoarseVibrationStep(c, out);
  checkExtremeVibration(c, out);
  checkConveyingSense(c, out);
  checkHighRestitution(c, out);
  for (std::size_t i = 0; i < scene.parts.size(); ++i) {
    checkSpawnStream(c, i, out);
    checkWeakCollider(c, i, out);
    checkSpawnInsideFixture(c, i, out);
    checkSpawnBelowRemoval(c, i, out);
    checkSpawnOverNothing(c, i, out);
  }
  checkSkippedTests(c, out);
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
