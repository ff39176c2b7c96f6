// SPDX-License-Identifier: MIT
// The checks of a part's history after a step that need its contacts (simulation.hpp,
// RunHealth): whether it left the feeder over a wall, a rim or a side (issue 20), and whether
// it moves faster than its case's physics allows. Both count and report the part and keep it.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "simulation_internal.hpp"

namespace rheofeed::scene {
namespace {

// Whether the line through c along u meets the box b grown by `grow` (m) on every side;
// `bottom` receives the box's lowest point along u (the grown box's bottom).
bool lineMeetsBox(const Vec3& c, const Vec3& u, const Bounds& b, double grow, double* bottom) {
  const double lo[3] = {b.min.x - grow, b.min.y - grow, b.min.z - grow};
  const double hi[3] = {b.max.x + grow, b.max.y + grow, b.max.z + grow};
  const double p[3] = {c.x, c.y, c.z}, d[3] = {u.x, u.y, u.z};
  double t0 = -HUGE_VAL, t1 = HUGE_VAL;
  double low = 0;
  for (int k = 0; k < 3; ++k) {
    low += d[k] > 0 ? lo[k] * d[k] : hi[k] * d[k];
    if (std::abs(d[k]) < 1e-12) {  // parallel to this slab: inside it or never
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - p[k]) / d[k], z = (hi[k] - p[k]) / d[k];
    if (a > z) std::swap(a, z);
    t0 = std::max(t0, a);
    t1 = std::min(t1, z);
  }
  *bottom = low;
  return t0 <= t1;
}

}  // namespace

void PartSimulation::noteContacts() {
  for (Track& tr : tracks_) tr.stranger = -1;
  if (feeders_.empty()) return;  // nothing to leave
  for (const FixtureContact& c : fixtureContacts()) {
    const auto part = part_of_geom_.find(c.part);
    const auto fixture = fixture_of_geom_.find(c.fixture);
    if (part == part_of_geom_.end() || fixture == fixture_of_geom_.end()) continue;
    Track& tr = tracks_.at(static_cast<std::size_t>(part->second));
    const int f = fixture->second;
    if (scene_.fixtures[static_cast<std::size_t>(f)].law.kind != FeederLaw::Kind::None) {
      tr.on_feeder = true;
      continue;
    }
    if (dot(c.normal_on_part, up_) < kSupportCosine) continue;  // a wall, not a support
    const bool carrier = std::find(tr.carriers.begin(), tr.carriers.end(), f) != tr.carriers.end();
    if (!tr.on_feeder && !carrier) {
      tr.carriers.push_back(f);  // carried it to the feeder
    } else if (tr.on_feeder && !carrier) {
      tr.stranger = f;
    }
  }
}

bool PartSimulation::leftFeeder(std::size_t i, const PartState& s, std::string& where) const {
  const Track& tr = tracks_[i];
  if (!tr.on_feeder) return false;
  const double grow = kFootprintRadii * tr.radius;
  bool over = false;
  double lowest_bottom = HUGE_VAL;  // of the carrier geoms over or under the part, along up
  auto visit = [&](int f) {
    for (const Footprint& fp : footprints_[static_cast<std::size_t>(f)]) {
      double bottom = -HUGE_VAL;
      if (!(fp.box.min.x <= fp.box.max.x)) {  // a plane or a mesh not loaded: everywhere
        over = true;
      } else if (lineMeetsBox(s.position, up_, fp.box, grow + fp.reach, &bottom)) {
        over = true;
      } else {
        continue;
      }
      lowest_bottom = std::min(lowest_bottom, bottom);
    }
  };
  for (int f : feeders_) visit(f);
  for (int f : tr.carriers) visit(f);
  std::ostringstream out;
  if (!over) {
    out << "beyond the footprint of the fixtures that carried it (over a wall, a rim or a side; "
        << "crossed between " << formatPosition(tr.last.position) << " and "
        << formatPosition(s.position) << ")";
    where = out.str();
    return true;
  }
  if (dot(s.position, up_) < lowest_bottom) {
    out << "under it (below the bottom of every fixture that carried it, over an edge or "
        << "through a gap), at " << formatPosition(s.position);
    if (tr.stranger >= 0) {
      out << ", on fixture '" << scene_.fixtures[static_cast<std::size_t>(tr.stranger)].name
          << "' (fixtures[" << tr.stranger << "])";
    }
    where = out.str();
    return true;
  }
  return false;
}

void PartSimulation::checkPhysicalSpeed(std::size_t i, const PartState& s) {
  const Track& tr = tracks_[i];
  const PartInstance& p = instances_[i];
  const double speed = energySpeed(s, p.mass, p.inertia);
  const double bound =
      partPhysicalSpeedBound(limits_, scene_.material.restitution, norm(scene_.gravity),
                             limits_.initial_speed, top_spawn_height_, dot(s.position, up_));
  health_.max_speed_ratio = std::max(health_.max_speed_ratio, speed / bound);
  if (tr.counted || !(speed > bound)) return;
  std::ostringstream what;
  what << "moves at " << speed << " m/s (its kinetic energy as a speed), beyond its physical "
       << "bound " << bound << " m/s (" << kPhysicalSpeedFactor
       << " x [(1 + e) (fastest initial speed + free fall from the highest spawn point) + (1 + e) "
       << "fastest "
       << "surface " << limits_.surface_speed << " m/s + push-out " << limits_.correcting_speed
       << " m/s] + " << kPhysicalSpeedMargin << " m/s; kept)";
  countLoss(i, "too_fast", "too-fast part", what.str(), health_.parts_too_fast, s);
}

}  // namespace rheofeed::scene
