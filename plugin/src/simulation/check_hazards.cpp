// SPDX-License-Identifier: MIT
// The hazard tests of the scene check (check.hpp), one function per kind over the measured
// scene (CheckContext, check.cpp). Every criterion is stated next to its code.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "check_internal.hpp"
#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene::checks {
namespace {

using GeomInfo = CheckContext::GeomInfo;

// The speed a part is expected to reach (m/s) and where it comes from: free fall from the
// highest spawn region to the fixture top under it, the fastest surface or an initial velocity.
struct ExpectedSpeed {
  double speed = 0;
  std::string source;
};
ExpectedSpeed expectedSpeed(const CheckContext& c) {
  // A part spawned at rest first lands on the highest fixture top under its spawn region (in
  // plan, with gravity along z); only where nothing is under it does it fall to the lowest
  // top (parts that later fall off an edge onto a catch floor are out of the feeder).
  const bool vertical = std::abs(c.up.z) > 0.99;
  double fall = 0, launch = 0;
  std::size_t high_family = 0, launch_family = 0;
  for (std::size_t i = 0; i < c.scene.parts.size(); ++i) {
    const PartSpec& p = c.scene.parts[i];
    Box3 region;
    region.add(p.spawn_min);
    region.add(p.spawn_max);
    const double top = maxAlong(region, c.up);
    double landing = c.lowest_top;
    if (vertical) {
      double under = -kInf;
      for (const GeomInfo& gi : c.geoms) {
        if (!gi.bounds.bounded) continue;
        const Box3& b = gi.bounds;
        const bool overlaps = b.lo.x <= region.hi.x && b.hi.x >= region.lo.x &&
                              b.lo.y <= region.hi.y && b.hi.y >= region.lo.y;
        const double geom_top = maxAlong(b, c.up);
        if (overlaps && geom_top <= top) under = std::max(under, geom_top);
      }
      if (std::isfinite(under)) landing = std::max(under, c.lowest_top);
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
  const double fall_speed = std::sqrt(2 * c.g * fall);
  double speed = fall_speed;
  std::string source = "free fall of " + mm(fall) + " from " + idx("parts", high_family) +
                       ".spawn_max to the fixture top under it";
  if (c.surface_speed > speed) {
    speed = c.surface_speed;
    source = c.speed_source;
  }
  if (launch > speed) {
    speed = launch;
    source = idx("parts", launch_family) + ".initial_velocity";
  }
  return {speed, source};
}

}  // namespace

void checkTunnelling(const CheckContext& c, std::vector<Hazard>& out) {
  // ODE with speculative contacts (SolverSettings::speculative_contacts, on unless the scene
  // turns it off): a part that moves more than a quarter of its smallest half extent in a step
  // is swept, and gets contacts across the gap before it arrives; its travel per step is no
  // hazard then. What the sweep cannot see (an obstacle edge thinner than the gaps between a
  // part's corner rays) is what the run's own loss counters report (check.hpp and the README
  // say the check is made for the reference engine and ODE without speculative contacts).
  if (c.ode && c.scene.solver.speculative_contacts.value_or(true)) return;
  const auto [speed, source] = expectedSpeed(c);
  // Semi-implicit Euler: x+ = x + h (v + g h), so one step moves a part by h (v + g h).
  const double travel = c.h * (speed + c.g * c.h);
  // The centre of a part of thickness t pressed into a geom of thickness T crosses the
  // geom's mid-surface at a penetration of (T + t) / 2; the collider's least-penetration
  // normal then points out of the far side. Parts against parts: T = t.
  const double across = std::min(c.thinnest_fixture, c.thinnest_part);
  const double allowed = 0.5 * (across + c.thinnest_part);
  if (std::isfinite(allowed) && travel > allowed) {
    Hazard hz;
    hz.kind = Hazard::Kind::Tunnelling;
    hz.value = travel;
    hz.limit = allowed;
    const bool fixture_thinner = c.thinnest_fixture <= c.thinnest_part;
    hz.where = c.step_field + ", " + idx("parts", c.thin_family) + ".size" +
               (fixture_thinner ? ", " + c.thin_geom : "");
    std::ostringstream m;
    m << "a part at the expected speed " << fmt(speed) << " m/s (" << source
      << ") moves h (v + g h) = " << mm(travel) << " per step of " << fmt(c.h)
      << " s, more than half the summed thickness of the thinnest "
      << (fixture_thinner
              ? "fixture geom " + c.thin_geom + " (" + mm(c.thinnest_fixture) + ")" + c.fixture_note
              : std::string("part as obstacle"))
      << " and the thinnest part " << idx("parts", c.thin_family) << " (" << mm(c.thinnest_part)
      << ")" << c.part_note << ": " << mm(allowed) << "; parts can pass through";
    hz.message = m.str();
    // Largest h with h (v + g h) <= allowed.
    const double safe_h = c.g > 0
                              ? (-speed + std::sqrt(speed * speed + 4 * c.g * allowed)) / (2 * c.g)
                              : allowed / speed;
    std::ostringstream s;
    s << c.step_field << " <= " << fmt(safe_h) << " s";
    if (fixture_thinner) {
      s << ", or make " << c.thin_geom << " at least "
        << mm(std::max(0.0, 2 * travel - c.thinnest_part)) << " thick";
    }
    if (source.rfind("free fall", 0) == 0) s << ", or spawn the parts lower";
    hz.safe_setting = s.str();
    out.push_back(hz);
  }
}

void checkFlushWalls(const CheckContext& c, std::vector<Hazard>& out) {
  if (std::isfinite(c.thinnest_part)) {
    for (const GeomInfo& wall : c.geoms) {
      const Fixture::Geom& wg = c.scene.fixtures[wall.f].geoms[wall.g];
      if (!upright(wg, c.up)) continue;
      const double bottom = minAlong(wall.bounds, c.up);
      for (const GeomInfo& floor : c.geoms) {
        if (&floor == &wall) continue;
        const Fixture::Geom& fg = c.scene.fixtures[floor.f].geoms[floor.g];
        if (!upright(fg, c.up)) continue;
        const double top = maxAlong(floor.bounds, c.up);
        const double floor_bottom = minAlong(floor.bounds, c.up);
        // The wall stands on the floor: its bottom within one thinnest part of the floor's top
        // (sunk less than that, or above it by less than that), it rises above the floor and
        // it does not start below the floor's bottom.
        const double gap = bottom - top;  // > 0: open above the floor, < 0: sunk
        if (!(gap > -c.thinnest_part + kSeamTolerance && gap < c.thinnest_part)) continue;
        if (maxAlong(wall.bounds, c.up) <= top || bottom <= floor_bottom) continue;
        if (!planOverlap(wg, fg, c.up)) continue;
        Hazard hz;
        hz.kind = Hazard::Kind::FlushWall;
        hz.value = gap;
        hz.limit = -c.thinnest_part;
        hz.where = geomPath(wall.f, wall.g) + ", " + geomPath(floor.f, floor.g) + ", " +
                   idx("parts", c.thin_family) + ".size";
        std::ostringstream m;
        m << "the bottom of " << geomPath(wall.f, wall.g) << " (fixture '"
          << c.scene.fixtures[wall.f].name << "') is "
          << (gap >= 0 ? mm(gap) + " above" : mm(-gap) + " below") << " the top of "
          << geomPath(floor.f, floor.g) << " (fixture '" << c.scene.fixtures[floor.f].name
          << "'), less than the thinnest part " << idx("parts", c.thin_family) << " ("
          << mm(c.thinnest_part) << "): a thin part can slip into the seam and under the wall";
        hz.message = m.str();
        hz.safe_setting = "extend " + geomPath(wall.f, wall.g) + " " + mm(c.thinnest_part + gap) +
                          " further down (its bottom " + mm(c.thinnest_part) +
                          " below the floor's top), or make them one fixture";
        out.push_back(hz);
      }
    }
  }
}

void checkMassRatio(const CheckContext& c, std::vector<Hazard>& out) {
  const bool quickstep = c.ode && c.scene.solver.ode_quickstep;
  const bool warm = c.ode && odeWarmStartsContacts(c.scene);
  if ((quickstep || !c.ode) && c.total_parts >= 2 && c.lightest < kInf && c.heaviest > 0) {
    const double ratio = c.heaviest / c.lightest;
    const int k = c.scene.solver.iterations;
    // The measured limit of this scene's engine at `iterations` and step h (warm starts as the
    // run at step h would have them: unset, they depend on the step).
    auto limitWith = [&](int iterations, double h, bool warm_start) {
      return quickstep
                 ? odeQuickstepMassRatioLimit(iterations, c.light_thickness, h, c.g, warm_start)
                 : referenceMassRatioLimit(iterations, c.light_thickness, h, c.g);
    };
    auto limitAt = [&](int iterations, double h) {
      return limitWith(iterations, h, c.ode && odeWarmStartsContacts(c.scene, h));
    };
    const double limit = limitAt(k, c.h);
    if (ratio > limit) {
      Hazard hz;
      hz.kind = Hazard::Kind::MassRatio;
      hz.value = ratio;
      hz.limit = limit;
      const bool one_family = c.heavy_family == c.light_family;
      hz.where = idx("parts", c.heavy_family) + ".size, " +
                 (one_family ? std::string() : idx("parts", c.light_family) + ".size, ") +
                 "density, solver.iterations, solver.time_step";
      const double x = c.light_thickness / (c.g * c.h * c.h);
      std::ostringstream m;
      const bool equal = ratio <= 1 + 1e-9;  // equal parts: the limit is below 1
      if (equal) {
        m << "the parts are of equal mass (" << fmt(c.heaviest) << " kg, " << mm(c.light_thickness)
          << " thick); ";
      } else if (one_family) {  // the size distribution's bounds
        m << "the heaviest part " << idx("parts", c.heavy_family) << " can draw ("
          << fmt(c.heaviest) << " kg) is " << fmt(ratio) << " times its lightest ("
          << fmt(c.lightest) << " kg, " << mm(c.light_thickness) << " thick); ";
      } else {
        m << "the heaviest part (" << idx("parts", c.heavy_family) << ", " << fmt(c.heaviest)
          << " kg) is " << fmt(ratio) << " times the lightest (" << idx("parts", c.light_family)
          << ", " << fmt(c.lightest) << " kg, " << mm(c.light_thickness) << " thick); ";
      }
      m << (quickstep ? (warm ? "ODE quickstep (warm starts)" : "ODE quickstep")
                      : "the reference solver")
        << " with " << k << " iterations at h = " << fmt(c.h)
        << " s (thickness / (g h^2) = " << fmt(x)
        << (limit < 1 ? ") is below the measured range, where even stacks of equal parts sank "
                        "into the floor"
                      : ") was measured to hold a ratio of " + fmt(limit))
        << (equal ? ": a part resting on another can push it into the floor"
                  : ": a heavy part resting on a light one crushes it into the floor");
      hz.message = m.str();
      std::ostringstream s;
      int need = 0;
      for (int kk :
           quickstep ? std::vector<int>{10, 20, 50, 100, 200} : std::vector<int>{20, 50, 100}) {
        if (!need && ratio <= limitAt(kk, c.h)) need = kk;
      }
      if (need) s << "solver.iterations >= " << need << ", or ";
      // The largest step (in factors of 0.8, down to 1e-3 of the step) whose limit holds the
      // ratio; none when the measured tables never do at these iterations.
      auto holds = [&](double step) { return ratio <= limitAt(k, step); };
      double safe_h = c.h;
      while (!holds(safe_h) && safe_h > 1e-3 * c.h) safe_h *= 0.8;
      if (holds(safe_h)) s << c.step_field << " <= " << fmt(safe_h) << " s, or ";
      if (warm && ratio <= limitWith(k, c.h, false)) s << "solver.warm_start = false, or ";
      if (quickstep) s << "solver.ode_quickstep = false (Dantzig LCP, exact but slower), or ";
      s << (equal ? "thicker parts (the limit grows with thickness / (g h^2))"
                  : "parts of closer masses");
      hz.safe_setting = s.str();
      out.push_back(hz);
    }
  }
}

void checkCoarseVibrationStep(const CheckContext& c, std::vector<Hazard>& out) {
  if (c.full) {
    for (std::size_t f = 0; f < c.scene.fixtures.size(); ++f) {
      const FeederLaw& law = c.scene.fixtures[f].law;
      if (law.kind != FeederLaw::Kind::Vibration) continue;
      const double per_cycle = 1.0 / (law.vibration.frequency * c.h);
      if (per_cycle >= kMinStepsPerCycle) continue;
      Hazard hz;
      hz.kind = Hazard::Kind::CoarseVibrationStep;
      hz.value = per_cycle;
      hz.limit = kMinStepsPerCycle;
      hz.where = "solver.time_step, " + idx("fixtures", f) + ".law.vibration.frequency";
      hz.message = "a full-vibration run resolves the " + fmt(law.vibration.frequency) +
                   " Hz vibration of fixture '" + c.scene.fixtures[f].name + "' with only " +
                   fmt(per_cycle) + " steps per cycle (h = " + fmt(c.h) + " s)";
      hz.safe_setting =
          "solver.time_step <= " + fmt(1.0 / (kMinStepsPerCycle * law.vibration.frequency)) + " s";
      out.push_back(hz);
    }
  }
}

void checkExtremeVibration(const CheckContext& c, std::vector<Hazard>& out) {
  const double g = c.g > 0 ? c.g : 9.81;
  for (std::size_t f = 0; f < c.scene.fixtures.size(); ++f) {
    const FeederLaw& law = c.scene.fixtures[f].law;
    if (law.kind != FeederLaw::Kind::Vibration) continue;
    const Vibration& v = law.vibration;
    const double w = 2 * kPi * v.frequency;
    double reach = 0;  // the fixture's farthest point from the torsion axis (m)
    if (v.torsion_amplitude > 0) {
      for (const GeomInfo& gi : c.geoms) {
        if (gi.f != f || !gi.bounds.bounded) continue;
        reach = std::max(reach, radiusFromAxis(gi.bounds, v.axis_origin, v.axis_direction));
      }
    }
    const double translation = v.amplitude * w * w, torsion = v.torsion_amplitude * w * w * reach;
    const double peak = std::hypot(translation, torsion);
    const double limit = kMaxFeederAcceleration * g;
    if (!(peak > limit)) continue;
    const std::string at = idx("fixtures", f) + ".law.vibration";
    Hazard hz;
    hz.kind = Hazard::Kind::ExtremeVibration;
    hz.value = peak;
    hz.limit = limit;
    hz.where = translation >= torsion ? at + ".amplitude" : at + ".torsion_amplitude";
    std::ostringstream m;
    m << "fixture '" << c.scene.fixtures[f].name << "' vibrates with a peak acceleration of "
      << fmt(peak) << " m/s^2 (" << std::lround(peak / g) << " g: amplitude " << fmt(v.amplitude)
      << " m";
    if (v.torsion_amplitude > 0) {
      m << ", torsion " << fmt(v.torsion_amplitude) << " rad at " << mm(reach) << " from the axis";
    }
    m << ", " << fmt(v.frequency) << " Hz); vibratory feeders run at a few g (throw numbers 1 to "
      << "5): is a length in mm given as m, an angle in degrees as rad, or a frequency in rad/s "
         "as Hz? (the scene's units are m, rad or *_deg, and Hz)";
    hz.message = m.str();
    std::ostringstream s;
    s << "a peak acceleration <= " << fmt(kMaxFeederAcceleration) << " g: ";
    if (translation >= torsion) {
      s << at << ".amplitude <= " << fmt(limit / (w * w)) << " m at " << fmt(v.frequency)
        << " Hz, or " << at << ".frequency <= " << fmt(std::sqrt(limit / v.amplitude) / (2 * kPi))
        << " Hz at this amplitude";
    } else {
      s << at << ".torsion_amplitude <= " << fmt(limit / (w * w * reach)) << " rad at "
        << fmt(v.frequency) << " Hz";
    }
    hz.safe_setting = s.str();
    out.push_back(hz);
  }
}

void checkConveyingSense(const CheckContext& c, std::vector<Hazard>& out) {
  if (c.scene.outputs.angular_drift) return;  // a bowl: measured about an axis
  const Vec3 d = c.scene.outputs.conveying_direction;
  for (std::size_t f = 0; f < c.scene.fixtures.size(); ++f) {
    const FeederLaw& law = c.scene.fixtures[f].law;
    if (law.kind != FeederLaw::Kind::Vibration) continue;
    const Vibration& v = law.vibration;
    if (v.torsion_amplitude != 0 || v.amplitude == 0) continue;
    // Parts hop along the horizontal part of the throw (NOTES section 5: a throw angle above
    // the track): of +-direction (one motion, half a cycle apart) the one that points up.
    // Straight up or nearly: no sense to judge.
    const Vec3 throw_dir = dot(v.direction, c.up) < 0 ? -1.0 * v.direction : v.direction;
    const Vec3 across = throw_dir - dot(throw_dir, c.up) * c.up;
    const double n = norm(across), nd = norm(d);
    if (!(n > 1e-3) || !(nd > 0)) continue;
    const double cosine = dot(across, d) / (n * nd);
    if (!(cosine < 0)) continue;
    Hazard hz;
    hz.kind = Hazard::Kind::AgainstConveyingDirection;
    hz.value = cosine;
    hz.limit = 0;
    hz.where = idx("fixtures", f) + ".law.vibration.direction, outputs.conveying_direction";
    const double above = std::atan2(dot(throw_dir, c.up), dot(throw_dir, (1.0 / nd) * d));
    hz.message = "fixture '" + c.scene.fixtures[f].name + "' vibrates " + fmt(above * 180 / kPi) +
                 " degrees above outputs.conveying_direction, beyond 90: its horizontal part "
                 "points against it (cosine " +
                 fmt(cosine) +
                 "), so the parts drift backwards, away from the exit (was a throw angle in "
                 "degrees given as angle_rad?)";
    hz.safe_setting =
        "a throw angle between 0 and 90 degrees above the conveying direction (angle_deg), or "
        "outputs.conveying_direction reversed for a feeder meant to run the other way";
    out.push_back(hz);
  }
}

void checkHighRestitution(const CheckContext& c, std::vector<Hazard>& out) {
  if (c.scene.material.restitution >= kHighRestitution && !c.scene.parts.empty()) {
    Hazard hz;
    hz.kind = Hazard::Kind::HighRestitution;
    hz.value = c.scene.material.restitution;
    hz.limit = kHighRestitution;
    hz.where = "material.restitution";
    hz.message = "material.restitution = " + fmt(c.scene.material.restitution) +
                 ": Newton's impact law is applied at every contact point, so a part landing on "
                 "an edge or a corner can leave faster than it came (boxes dropped 0.5 m with "
                 "restitution 1 reached 8.4 m/s against 3.1 m/s of free fall)";
    hz.safe_setting = "material.restitution < " + fmt(kHighRestitution) + ", or spherical parts";
    out.push_back(hz);
  }
}

void checkSpawnStream(const CheckContext& c, std::size_t part, std::vector<Hazard>& out) {
  const std::size_t i = part;
  const PartSpec& p = c.scene.parts[i];
  if (p.rate > 0 && p.count > 1 && c.g > 0) {
    // A part released at rest falls its own largest size s in t = sqrt(2 s / g); rate t more
    // parts appear meanwhile. The region holds at most n = prod max(1, floor(span_i / s)) of
    // them side by side; when more come (a narrow region and the next part within t, or a rate
    // that spawns many parts within a step), some certainly overlap. Fewer can still overlap:
    // streamed parts are placed at random, not side by side, so this is a lower bound on the
    // trouble, not a guarantee against it.
    const PartRange r = partRange(p);
    const double s_big = r.heavy.size;
    const double clear_time = std::sqrt(2 * s_big / c.g);
    const double interval = 1.0 / p.rate;
    const Vec3 span = p.spawn_max - p.spawn_min;
    const double across = std::max({std::abs(span.x), std::abs(span.y), std::abs(span.z)});
    double side_by_side = 1;
    for (double extent : {span.x, span.y, span.z}) {
      side_by_side *= std::max(1.0, std::floor(std::abs(extent) / s_big));
    }
    const double coming = std::min(p.rate * clear_time, static_cast<double>(p.count));
    if (coming > side_by_side) {
      Hazard hz;
      hz.kind = Hazard::Kind::SpawnStreamOverlap;
      hz.value = interval;
      hz.limit = clear_time / side_by_side;
      hz.where = idx("parts", i) + ".rate, " + idx("parts", i) + ".spawn_min/spawn_max";
      hz.message = idx("parts", i) + " ('" + p.name + "') spawns a part every " + fmt(interval) +
                   " s (" + fmt(coming) + " parts in the " + fmt(clear_time) +
                   " s a part needs to fall its own size, " + fmt(s_big) + " m) from a region " +
                   fmt(across) + " m across that holds " + fmt(side_by_side) +
                   " side by side: parts appear inside each other and are pushed apart at up to "
                   "solver.max_correcting_velocity";
      hz.safe_setting = idx("parts", i) + ".rate <= " + fmt(side_by_side / clear_time) +
                        " parts/s, or a larger spawn region (" + fmt(s_big) +
                        " m per part along each axis)";
      out.push_back(hz);
    }
  }
}

void checkWeakCollider(const CheckContext& c, std::size_t part, std::vector<Hazard>& out) {
  const std::size_t i = part;
  const PartSpec& p = c.scene.parts[i];
  if (p.shape == Shape::Kind::Capsule || p.shape == Shape::Kind::Cylinder) {  // both engines

    for (const GeomInfo& gi : c.geoms) {
      const Fixture::Geom& gm = c.scene.fixtures[gi.f].geoms[gi.g];
      if (gm.shape.kind != Shape::Kind::Cylinder) continue;
      Hazard hz;
      hz.kind = Hazard::Kind::WeakCollider;
      hz.where = idx("parts", i) + ".shape, " + geomPath(gi.f, gi.g) + ".shape";
      hz.message = std::string(toString(p.shape)) + " parts of " + idx("parts", i) +
                   " against the cylinder " + geomPath(gi.f, gi.g) + " (fixture '" +
                   c.scene.fixtures[gi.f].name +
                   "'): ODE 0.16 collides this pair with its general convex test (one contact "
                   "point per pair), parts tip into the cylinder and can sink through it";
      hz.safe_setting =
          "a box (or a triangle mesh) for " + geomPath(gi.f, gi.g) + ", or box/sphere parts";
      out.push_back(hz);
      break;  // one warning per part family
    }
  }
}

void checkSpawnInsideFixture(const CheckContext& c, std::size_t part, std::vector<Hazard>& out) {
  const std::size_t i = part;
  const PartSpec& p = c.scene.parts[i];
  for (const GeomInfo& gi : c.geoms) {
    const Fixture::Geom& gm = c.scene.fixtures[gi.f].geoms[gi.g];
    if (gi.open_mesh && overlaps(p.spawn_min, p.spawn_max, gi.bounds)) {
      // An open mesh bounds no solid: whether parts start inside its walls cannot be told.
      Hazard hz;
      hz.kind = Hazard::Kind::CheckSkipped;
      hz.where = idx("parts", i) + ".spawn_min, " + idx("parts", i) + ".spawn_max, " +
                 geomPath(gi.f, gi.g);
      hz.message = "the spawn region of " + idx("parts", i) + " ('" + p.name +
                   "') overlaps the bounding box of " + geomPath(gi.f, gi.g) +
                   ", an open mesh (fixture '" + c.scene.fixtures[gi.f].name +
                   "'; it bounds no solid): whether parts start inside its walls is not checked";
      hz.safe_setting = "a closed mesh for " + geomPath(gi.f, gi.g) +
                        " (every edge shared by two triangles), or check the spawn region by hand";
      out.push_back(hz);
      continue;
    }
    if (gi.open_mesh || !regionInsideGeom(p.spawn_min, p.spawn_max, gm)) continue;
    Hazard hz;
    hz.kind = Hazard::Kind::SpawnInsideFixture;
    hz.where =
        idx("parts", i) + ".spawn_min, " + idx("parts", i) + ".spawn_max, " + geomPath(gi.f, gi.g);
    hz.message = "the spawn region of " + idx("parts", i) + " ('" + p.name + "') reaches into " +
                 geomPath(gi.f, gi.g) + " (" + toString(gm.shape.kind) + ", fixture '" +
                 c.scene.fixtures[gi.f].name +
                 "'): parts can start inside it and are pushed out at up to "
                 "solver.max_correcting_velocity or through it";
    hz.safe_setting = "move or shrink " + idx("parts", i) +
                      ".spawn_min/spawn_max so that part centres stay outside every fixture "
                      "(at least half a part above a floor)";
    out.push_back(hz);
  }
}

void checkSpawnBelowRemoval(const CheckContext& c, std::size_t part, std::vector<Hazard>& out) {
  const std::size_t i = part;
  const PartSpec& p = c.scene.parts[i];
  Box3 region;
  region.add(p.spawn_min);
  region.add(p.spawn_max);
  // removal_height is a world z (simulation.hpp), whatever the gravity.
  if (region.lo.z < c.scene.removal_height) {
    Hazard hz;
    hz.kind = Hazard::Kind::SpawnBelowRemoval;
    hz.value = region.lo.z;
    hz.limit = c.scene.removal_height;
    hz.where = idx("parts", i) + ".spawn_min.z, removal_height";
    hz.message = "parts of " + idx("parts", i) + " can spawn at z = " + fmt(region.lo.z) +
                 " m, below removal_height = " + fmt(c.scene.removal_height) +
                 " m: they are removed as they appear";
    hz.safe_setting = "removal_height < " + fmt(region.lo.z) + " m";
    out.push_back(hz);
  }
}

void checkSpawnOverNothing(const CheckContext& c, std::size_t part, std::vector<Hazard>& out) {
  if (!(std::abs(c.up.z) > 0.99)) return;  // "under" is judged with gravity along z
  const PartSpec& p = c.scene.parts[part];
  Box3 region;
  region.add(p.spawn_min);
  region.add(p.spawn_max);
  const double top = maxAlong(region, c.up);
  for (const GeomInfo& gi : c.geoms) {
    if (!gi.bounds.bounded) return;  // a plane or a mesh not loaded: cannot tell
    const Box3& b = gi.bounds;
    const bool overlaps = b.lo.x <= region.hi.x && b.hi.x >= region.lo.x && b.lo.y <= region.hi.y &&
                          b.hi.y >= region.lo.y;
    if (overlaps && minAlong(b, c.up) <= top) return;  // something under (or around) it
  }
  if (norm(p.initial_velocity) > 0) return;  // thrown: where it lands is not straight below
  Hazard hz;
  hz.kind = Hazard::Kind::SpawnOverNothing;
  hz.value = std::isfinite(c.lowest_top) ? top - c.lowest_top : -kInf;
  hz.limit = 0;
  hz.where = idx("parts", part) + ".spawn_min/spawn_max";
  hz.message = idx("parts", part) + " ('" + p.name + "') spawns over no fixture: nothing lies " +
               "under its spawn region (x " + fmt(region.lo.x) + " to " + fmt(region.hi.x) +
               " m, y " + fmt(region.lo.y) + " to " + fmt(region.hi.y) +
               " m), so its parts fall to the removal height and are lost";
  hz.safe_setting = "a spawn region over the feeder (in plan, within a fixture's footprint)";
  out.push_back(hz);
}

void checkSkippedTests(const CheckContext& c, std::vector<Hazard>& out) {
  for (const CheckContext::Skipped& s : c.skipped) {
    Hazard hz;
    hz.kind = Hazard::Kind::CheckSkipped;
    hz.value = static_cast<double>(s.ray_tests);
    hz.limit = static_cast<double>(kMaxMeshRayTests);
    hz.where = s.path;
    hz.message =
        "the wall-thickness test of the mesh " + s.path + " (" + std::to_string(s.triangles) +
        " triangles) was skipped after " + std::to_string(s.ray_tests) + " ray tests (limit " +
        std::to_string(kMaxMeshRayTests) + "): its walls are not counted in the tunnelling check";
    hz.safe_setting =
        "a mesh with fewer overlapping triangles (a closed surface without "
        "stacked shells), or check the wall thickness by hand";
    out.push_back(hz);
  }
}

}  // namespace rheofeed::scene::checks
