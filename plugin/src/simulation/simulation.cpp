// SPDX-License-Identifier: MIT
// The part bookkeeping both engines share, and the checks that keep a run from failing
// silently (issue 7).
//
// ## Scene limits (sceneLimits)
// The extent of a scene is the union of its fixtures' bounding boxes at rest (plane geoms,
// unbounded, excluded) and its spawn regions. A part can move no faster than what it was given
// and what the scene can give it:
//   v_phys = v_initial + v_fall + 2 v_surface + v_correct
// with v_initial the fastest initial velocity, v_fall = sqrt(2 |g| (z_top - removal_height)) the
// free-fall speed from the highest point of the extent to the removal height (energy), v_surface
// the fastest feeder surface point (a belt's speed; a twist's |v| + |w| R, R the farthest
// distance from its origin to the fixture's box; a vibration's peak velocity 2 pi f (A + theta R)
// and, in rheonomic runs, its calibrated drift twist), counted twice because an impact on a
// surface moving at V changes the relative velocity by up to (1 + e) V <= 2 V, and v_correct the
// contact push-out speed cap (SolverSettings::max_correcting_velocity). A part above
//   kSpeedBoundFactor v_phys + kSpeedBoundMargin   (2 v_phys + 1 m/s)
// is an energy blow-up: the factor 2 leaves room for one elastic transfer from a heavy part to
// a light one (which leaves at up to twice the heavy part's speed), the margin for scenes at
// rest. The speed of a part is that of its fastest point, |v| + |w| r (r its bounding radius).
// The scene bounds are the extent grown by a margin: the larger of 1 m, the extent's largest
// edge and the distance a part thrown sideways at the surface, initial and push-out speeds
// covers while it falls from z_top to the removal height; upwards at least the height a part at
// v_phys can climb (v_phys^2 / 2 |g|). Downwards Scene::removal_height takes parts out.
//
// ## Physical speed bound (partPhysicalSpeedBound, issue 20)
// The blow-up bound above is one number for the whole scene and must let a part fall from the
// top of the scene to the removal height; a part in a trough 5 cm above its floor can be ten
// times slower than that and still be beyond what its case allows. Each part is held to the
// energy budget of its height instead: its kinetic energy per mass, as the speed v_e =
// sqrt(|v|^2 + w.I w / m) it would have all in translation, comes from the fastest initial
// speed |v0| of the scene, from a drop from the highest spawn point z0 to its height z,
// sqrt(2 |g| (z0 - z)) (energy: its own fall or that of a part falling from z0 onto it, whose
// speed an impact passes on multiplied by up to 1 + e, Newton's law for a light part hit by a
// heavy one), from impacts on feeder surfaces moving at up to V, which change the relative
// velocity by up to (1 + e) V, and from the push-out of an overlap, capped at v_c per contact:
//   v_phys(z) = (1 + e) (|v0| + sqrt(2 |g| max(0, z0 - z))) + (1 + e) V + v_c.
// kPhysicalSpeedFactor (25 %) and kPhysicalSpeedMargin (0.1 m/s) leave room for the contact
// solvers' penetration recovery and the rounding of a part at rest; the shipped scenes and
// tests stay below (RunHealth::max_speed_ratio in their JSON).
//
// ## Tunnelling
// The checks follow one point of each part, its anchor (partAnchor): the centre of mass,
// unless that lies outside the part's own solid (a hex nut's is in its hole), when it is a point
// deep inside the material. The anchor never reaches a fixture surface in contact: it stays at
// least its clearance away, less the penetration; the clearance is the smallest half-size for
// a centre of mass (a primitive, or a mesh whose centre is inside its closed mesh) and the
// anchor's distance to the part's surface otherwise. When the anchor moves by more than
// kTunnelCheckFraction of its clearance in one step, an ODE ray from its old position to its
// new one is collided with every fixture geom whose box it overlaps (at the geoms' current
// poses); a slower crossing needs an anchor already sunk by nearly its whole clearance. If the
// ray crosses a surface:
// - and the reverse ray (new to old anchor) crosses one elsewhere, the anchor went into a
//   fixture and out again within the step: through (a thin floor jumped over);
// - else the anchor is now inside a fixture (or behind a mesh sheet): the entry point and the
//   entry surface's outward normal are kept and the part's rays are cast every step until its
//   anchor crosses a surface again: on the outer side of the entry surface's plane, or out
//   through a surface that does not face away from the entry surface (kThroughCosine: a
//   corner cut, into a wall's face near its edge and out under it), is a deep penetration that
//   recovered (parts_sunk); out on the far side is a pass through (parts_through_fixture);
//   leaving the scene while inside is a pass through too.
// A centre of mass outside the solid would break the first rule: a nut threaded on a pin has
// its centre inside the pin, at rest. Its anchor is found once per part from its collision mesh
// (the convex hull for a part that collides as its hull, which holds its centre): the origin
// is inside when the mesh's generalized winding number there is above 1/2 (the solid angle the
// triangles subtend, summed, over 4 pi: 1 inside a closed outward mesh, 0 outside, whatever
// the mesh's edges and vertices); otherwise rays from the origin along the 26 directions of a
// cube's faces, edges and corners and towards up to 256 triangle centroids (so that a thin part
// tilted in its file is met) are cut by the mesh, the midpoints of the spans between
// consecutive crossings that are inside (winding number) are the candidates, and the one
// farthest from the nearest triangle is the anchor. The M6 nut's is midway between its hole
// and an outer corner, about 1.2 mm deep (2.5 mm is its smallest half-size).
// Every part counted is also recorded (RunHealth::part_events: when, where, which fixture).
#include "rheofeed/simulation/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "check_internal.hpp"
#include "rheofeed/contact_collider.hpp"
#include "simulation_internal.hpp"
#include "stage_clock.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinMargin = 1.0;             // m: smallest margin around the scene's extent
constexpr double kTunnelCheckFraction = 1e-3;  // of the anchor's clearance, see above
// Two crossings along one segment are distinct when they are this far apart (m): far below any
// part or fixture size (at least 1e-5 m), far above the round-off of a ray test over a step.
// ODE's ray against a triangle mesh (OPCODE) works in single precision: about 1e-8 m at 0.1 m
// from the origin. With 1e-9, a mesh nut's anchor that ended 0.3 mm inside a mesh cone met the
// cone's surface going in and, backwards, coming out 3 nm apart, and counted as passed through.
// Far from the origin the round-off grows with the coordinates (crossingTolerance).
constexpr double kCrossingTolerance = 1e-6;

// The distance (m) below which two crossings of the segment [a, b] are one surface: at least
// kCrossingTolerance, and 8 single-precision units of the larger coordinate (1e-5 m at 10 m).
double crossingTolerance(const Vec3& a, const Vec3& b) {
  const double extent = std::max(
      {std::abs(a.x), std::abs(a.y), std::abs(a.z), std::abs(b.x), std::abs(b.y), std::abs(b.z)});
  return std::max(kCrossingTolerance,
                  8 * static_cast<double>(std::numeric_limits<float>::epsilon()) * extent);
}
// An anchor that went into a fixture and out again passed through it when the exit surface faces
// away from the entry surface: their outward normals more than 120 degrees apart (cosine below
// -kThroughCosine). Out through a face at a right angle to the entry is a corner cut.
constexpr double kThroughCosine = 0.5;

Bounds emptyBounds() {
  return {{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}};
}
bool isEmpty(const Bounds& b) {
  return !(b.min.x <= b.max.x);
}

void grow(Bounds& b, const Vec3& x) {
  b.min = {std::min(b.min.x, x.x), std::min(b.min.y, x.y), std::min(b.min.z, x.z)};
  b.max = {std::max(b.max.x, x.x), std::max(b.max.y, x.y), std::max(b.max.z, x.z)};
}
void grow(Bounds& b, const Bounds& other) {
  if (isEmpty(other)) return;
  grow(b, other.min);
  grow(b, other.max);
}

// Bounding box of a fixture geom at its pose (empty for a plane, or a mesh not loaded).
Bounds geomBounds(const Fixture::Geom& g) {
  Bounds b = emptyBounds();
  const double* r = g.pose.rotation;
  const Shape& s = g.shape;
  Vec3 half;
  const Vec3 axis{r[2], r[5], r[8]};  // local z in the world (cylinders, capsules)
  auto acrossAxis = [](double a) { return std::sqrt(std::max(0.0, 1 - a * a)); };
  switch (s.kind) {
    case Shape::Kind::Plane:
      return b;
    case Shape::Kind::Mesh:
      if (!s.mesh_data) return b;
      for (std::size_t k = 0; k + 2 < s.mesh_data->vertices.size(); k += 3) {
        const double* v = &s.mesh_data->vertices[k];
        grow(b, g.pose.transform({v[0], v[1], v[2]}));
      }
      return b;
    case Shape::Kind::Box:
      half = {
          0.5 * (std::abs(r[0]) * s.size.x + std::abs(r[1]) * s.size.y + std::abs(r[2]) * s.size.z),
          0.5 * (std::abs(r[3]) * s.size.x + std::abs(r[4]) * s.size.y + std::abs(r[5]) * s.size.z),
          0.5 *
              (std::abs(r[6]) * s.size.x + std::abs(r[7]) * s.size.y + std::abs(r[8]) * s.size.z)};
      break;
    case Shape::Kind::Sphere:
      half = {s.radius, s.radius, s.radius};
      break;
    case Shape::Kind::Cylinder:
      half = {0.5 * s.length * std::abs(axis.x) + s.radius * acrossAxis(axis.x),
              0.5 * s.length * std::abs(axis.y) + s.radius * acrossAxis(axis.y),
              0.5 * s.length * std::abs(axis.z) + s.radius * acrossAxis(axis.z)};
      break;
    case Shape::Kind::Capsule:
      half = {0.5 * s.length * std::abs(axis.x) + s.radius,
              0.5 * s.length * std::abs(axis.y) + s.radius,
              0.5 * s.length * std::abs(axis.z) + s.radius};
      break;
  }
  grow(b, g.pose.position - half);
  grow(b, g.pose.position + half);
  return b;
}

// Farthest distance from `o` to a point of the box b (m).
double farthest(const Bounds& b, const Vec3& o) {
  const Vec3 d{std::max(std::abs(b.min.x - o.x), std::abs(b.max.x - o.x)),
               std::max(std::abs(b.min.y - o.y), std::abs(b.max.y - o.y)),
               std::max(std::abs(b.min.z - o.z), std::abs(b.max.z - o.z))};
  return norm(d);
}

double twistSpeed(const Twist& t, const Bounds& b) {
  return norm(t.linear) + norm(t.angular) * farthest(b, t.origin);
}

// Fastest surface point of a fixture (m/s) within the box b.
double surfaceSpeed(const FeederLaw& law, const Bounds& b) {
  switch (law.kind) {
    case FeederLaw::Kind::None:
      return 0;
    case FeederLaw::Kind::Drift:
      return twistSpeed(law.drift, b);
    case FeederLaw::Kind::Belt:
      return std::abs(law.belt_speed);
    case FeederLaw::Kind::Vibration: {
      const Vibration& v = law.vibration;
      const double vibrating =
          2 * kPi * v.frequency *
          (std::abs(v.amplitude) + std::abs(v.torsion_amplitude) * farthest(b, v.axis_origin));
      return std::max(vibrating,
                      law.has_calibrated_drift ? twistSpeed(law.calibrated_drift, b) : 0.0);
    }
  }
  return 0;
}

}  // namespace

std::string formatPosition(const Vec3& x) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.6g, %.6g, %.6g) m", x.x, x.y, x.z);
  return b;
}

void PartSimulation::markNonFinite(int index) {
  tracks_.at(static_cast<std::size_t>(index)).engine_nonfinite = true;
}

Bounds fixtureGeomBounds(const Fixture::Geom& g) {
  return geomBounds(g);
}

SceneLimits sceneLimits(const Scene& scene) {
  SceneLimits l;
  l.removal_height = scene.removal_height;
  std::vector<Bounds> fixture_bounds;
  Bounds extent = emptyBounds();
  for (const Fixture& f : scene.fixtures) {
    Bounds b = emptyBounds();
    for (const Fixture::Geom& g : f.geoms) grow(b, geomBounds(g));
    fixture_bounds.push_back(b);
    grow(extent, b);
  }
  for (const PartSpec& p : scene.parts) {
    grow(extent, p.spawn_min);
    grow(extent, p.spawn_max);
    l.initial_speed = std::max(l.initial_speed, norm(p.initial_velocity));
  }
  if (isEmpty(extent)) grow(extent, Vec3{});
  l.extent = extent;
  for (std::size_t k = 0; k < scene.fixtures.size(); ++k) {
    // A fixture of planes only is bounded by the scene's extent.
    const Bounds& b = isEmpty(fixture_bounds[k]) ? extent : fixture_bounds[k];
    l.surface_speed = std::max(l.surface_speed, surfaceSpeed(scene.fixtures[k].law, b));
  }
  const double g = norm(scene.gravity);
  const double drop = std::max(0.0, extent.max.z - scene.removal_height);
  l.fall_speed = std::sqrt(2 * g * drop);
  l.correcting_speed = scene.solver.max_correcting_velocity;
  l.physical_speed = l.initial_speed + l.fall_speed + 2 * l.surface_speed + l.correcting_speed;
  l.speed_bound = kSpeedBoundFactor * l.physical_speed + kSpeedBoundMargin;

  const Vec3 edge = extent.max - extent.min;
  double margin = std::max({kMinMargin, edge.x, edge.y, edge.z});
  double climb = margin;
  if (g > 0) {
    const double fall_time = std::sqrt(2 * drop / g);
    margin = std::max(margin, (l.surface_speed + l.initial_speed + l.correcting_speed) * fall_time);
    climb = std::max(margin, l.physical_speed * l.physical_speed / (2 * g));
  }
  l.margin = margin;
  l.bounds.min = {extent.min.x - margin, extent.min.y - margin, -kInf};
  l.bounds.max = {extent.max.x + margin, extent.max.y + margin, extent.max.z + climb};
  return l;
}

bool beyondExitPlane(const Outputs& outputs, const Vec3& x) {
  return outputs.exit_plane && dot(x - outputs.exit_point, outputs.exit_normal) >= 0;
}

const char* toString(PartCheck check) {
  switch (check) {
    case PartCheck::Ok:
      return "ok";
    case PartCheck::NonFinite:
      return "non-finite";
    case PartCheck::TooFast:
      return "too fast";
    case PartCheck::BelowRemovalHeight:
      return "below the removal height";
    case PartCheck::OutOfBounds:
      return "out of bounds";
  }
  return "?";
}

PartCheck checkPartState(const PartState& s, const SceneLimits& limits, double radius) {
  bool finite = isFinite(s.position) && isFinite(s.velocity) && isFinite(s.angular_velocity);
  for (double r : s.rotation) finite = finite && std::isfinite(r);
  if (!finite) return PartCheck::NonFinite;
  if (!(partSpeed(s, radius) <= limits.speed_bound)) return PartCheck::TooFast;
  if (s.position.z < limits.removal_height) return PartCheck::BelowRemovalHeight;
  if (!limits.bounds.contains(s.position)) return PartCheck::OutOfBounds;
  return PartCheck::Ok;
}

double partSpeed(const PartState& s, double radius) {
  return norm(s.velocity) + norm(s.angular_velocity) * radius;
}

double partPhysicalSpeedBound(const SceneLimits& limits, double restitution, double g,
                              double initial_speed, double spawn_height, double height) {
  const double fall = std::sqrt(2 * g * std::max(0.0, spawn_height - height));
  const double physical = (1 + restitution) * (initial_speed + fall) +
                          (1 + restitution) * limits.surface_speed + limits.correcting_speed;
  return kPhysicalSpeedFactor * physical + kPhysicalSpeedMargin;
}

double energySpeed(const PartState& s, double mass, const double inertia[9]) {
  const double* r = s.rotation;  // body to world: w_body = R^T w
  const Vec3& w = s.angular_velocity;
  const double b[3] = {r[0] * w.x + r[3] * w.y + r[6] * w.z, r[1] * w.x + r[4] * w.y + r[7] * w.z,
                       r[2] * w.x + r[5] * w.y + r[8] * w.z};
  double wiw = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) wiw += b[i] * inertia[3 * i + j] * b[j];
  }
  const double v = norm(s.velocity);
  return mass > 0 ? std::sqrt(v * v + std::max(0.0, wiw) / mass) : v;
}

PartSimulation::PartSimulation(const Scene& scene, Method method)
    : scene_(scene), method_(method), instances_(drawParts(scene)), limits_(sceneLimits(scene)) {
  health_.speed_bound = limits_.speed_bound;
  const double g = norm(scene.gravity);
  if (g > 0) up_ = (-1.0 / g) * scene.gravity;
  top_spawn_height_ = -kInf;
  for (const PartSpec& p : scene.parts) {  // the highest corner of every spawn region
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner{c & 1 ? p.spawn_max.x : p.spawn_min.x,
                        c & 2 ? p.spawn_max.y : p.spawn_min.y,
                        c & 4 ? p.spawn_max.z : p.spawn_min.z};
      top_spawn_height_ = std::max(top_spawn_height_, dot(corner, up_));
    }
  }
  for (std::size_t f = 0; f < scene.fixtures.size(); ++f) {
    const FeederLaw& law = scene.fixtures[f].law;
    if (law.kind != FeederLaw::Kind::None) feeders_.push_back(static_cast<int>(f));
    std::vector<Footprint> boxes;
    for (const Fixture::Geom& geom : scene.fixtures[f].geoms) {
      Footprint fp{geomBounds(geom), 0};
      if (law.kind == FeederLaw::Kind::Vibration && !isEmpty(fp.box)) {
        const Vibration& v = law.vibration;
        fp.reach =
            std::abs(v.amplitude) + std::abs(v.torsion_amplitude) * farthest(fp.box, v.axis_origin);
      }
      boxes.push_back(fp);
    }
    footprints_.push_back(boxes);
  }
  if (!isFullVibration(method)) part_efficiency_ = partEfficiencies(scene);
}

MotionLaw PartSimulation::feederLaw(int fixture) {
  MotionLaw law = rheonomicLaw(scene_, fixture);
  if (law.kind() == MotionLaw::Kind::LocalVibration) {
    ++health_.local_law_feeders;
    const std::shared_ptr<LocalDriftTable>& table = law.localTable();
    const bool known = std::any_of(local_tables_.begin(), local_tables_.end(),
                                   [&](const auto& t) { return t.first == table; });
    if (!known) {
      local_tables_.emplace_back(table, table->stats());
      health_.local_law_corners_at_start += static_cast<std::int64_t>(table->numCorners());
      if (!scene_.drift_table_problem.empty()) ignoreSetting(scene_.drift_table_problem);
    }
  }
  return law;
}

double PartSimulation::partEfficiency(int spec) const {
  const std::size_t k = static_cast<std::size_t>(spec);
  return k < part_efficiency_.size() ? part_efficiency_[k] : 1.0;
}

PartSimulation::~PartSimulation() {
  if (ray_) dGeomDestroy(ray_);
}

void PartSimulation::addFixtureGeom(dGeomID geom, int fixture) {
  if (fixture_set_.insert(geom).second) fixture_geoms_.push_back(geom);
  fixture_of_geom_[geom] = fixture;
}

void PartSimulation::ignoreSetting(const std::string& message) {
  health_.ignored_settings.push_back(message);
  std::fprintf(stderr, "rheofeed: %s: %s\n", toString(method_), message.c_str());
}

void PartSimulation::reportFirst(const std::string& kind, const std::string& line) {
  if (std::find(reported_.begin(), reported_.end(), kind) != reported_.end()) return;
  reported_.push_back(kind);
  std::fprintf(stderr, "rheofeed: %s: %s (first %s of this run; all are counted)\n",
               toString(method_), line.c_str(), kind.c_str());
}

void PartSimulation::spawnDue() {
  while (next_ < instances_.size() && instances_[next_].spawn_time <= time_ + 1e-12) {
    const PartInstance& p = instances_[next_++];
    addPart(p);
    Track tr;
    partSizes(p.shape, tr.clearance, tr.radius);  // the clearance of a centre of mass
    if (p.shape.kind == Shape::Kind::Mesh) {
      // The anchor of the family's mesh at scale 1, found once, scaled to this part.
      auto found = unit_anchors_.find(p.spec);
      if (found == unit_anchors_.end()) {
        const PartSpec& spec = scene_.parts.at(static_cast<std::size_t>(p.spec));
        Shape unit;
        unit.kind = Shape::Kind::Mesh;
        unit.mesh_data = spec.mesh_data;
        unit.collision_mesh_data = spec.collision_mesh_data;
        found = unit_anchors_.emplace(p.spec, partAnchor(unit)).first;
      }
      tr.off_centre = found->second.point != Vec3{};
      if (tr.off_centre) {
        tr.anchor = p.shape.mesh_scale * found->second.point;
        tr.clearance = p.shape.mesh_scale * found->second.clearance;
      }
    }
    tr.last = partState(static_cast<int>(tracks_.size()));
    tr.beyond_exit = beyondExitPlane(scene_.outputs, tr.last.position);
    tracks_.push_back(tr);
  }
}

double PartSimulation::firstCrossing(const Vec3& a, const Vec3& b, Vec3* normal, int* fixture,
                                     dGeomID* geom) {
  const Vec3 d = b - a;
  const double length = norm(d);
  if (!(length > 0) || fixture_geoms_.empty()) return kInf;
  if (!ray_) {
    ray_ = dCreateRay(nullptr, length);
    dGeomRaySetClosestHit(ray_, 1);  // meshes: the nearest triangle, not any
  }
  dGeomRaySetLength(ray_, length);
  dGeomRaySet(ray_, a.x, a.y, a.z, d.x, d.y, d.z);
  dReal ray_box[6], box[6];
  dGeomGetAABB(ray_, ray_box);
  double first = kInf;
  for (dGeomID g : fixture_geoms_) {
    dGeomGetAABB(g, box);
    if (box[1] < ray_box[0] || box[0] > ray_box[1] || box[3] < ray_box[2] || box[2] > ray_box[3] ||
        box[5] < ray_box[4] || box[4] > ray_box[5]) {
      continue;
    }
    dContactGeom contact;
    if (dCollide(ray_, g, 1, &contact, sizeof contact) > 0 && contact.depth < first) {
      first = contact.depth;
      if (normal) *normal = {contact.normal[0], contact.normal[1], contact.normal[2]};
      if (fixture) *fixture = fixture_of_geom_.at(g);
      if (geom) *geom = g;
    }
  }
  return first;
}

bool PartSimulation::insideFixture(const Vec3& x, bool* unknown) const {
  *unknown = false;
  dReal box[6];
  for (dGeomID g : fixture_geoms_) {
    const int cls = dGeomGetClass(g);
    if (cls != dPlaneClass) {
      dGeomGetAABB(g, box);
      if (x.x < box[0] || x.x > box[1] || x.y < box[2] || x.y > box[3] || x.z < box[4] ||
          x.z > box[5]) {
        continue;
      }
    }
    switch (cls) {
      case dBoxClass:
        if (dGeomBoxPointDepth(g, x.x, x.y, x.z) > 0) return true;
        break;
      case dSphereClass:
        if (dGeomSpherePointDepth(g, x.x, x.y, x.z) > 0) return true;
        break;
      case dCapsuleClass:
        if (dGeomCapsulePointDepth(g, x.x, x.y, x.z) > 0) return true;
        break;
      case dPlaneClass:
        if (dGeomPlanePointDepth(g, x.x, x.y, x.z) > 0) return true;
        break;
      default:
        *unknown = true;
    }
  }
  return false;
}

Vec3 PartSimulation::anchorAt(std::size_t i, const PartState& s) const {
  const Track& tr = tracks_[i];
  if (!tr.off_centre) return s.position;
  Pose pose;  // the part's: body to world
  pose.position = s.position;
  std::copy(s.rotation, s.rotation + 9, pose.rotation);
  return pose.transform(tr.anchor);
}

void PartSimulation::trackCrossings(std::size_t i, const Vec3& from, const Vec3& to,
                                    const PartState& s) {
  Track& tr = tracks_[i];
  const double length = norm(to - from);
  Vec3 normal;
  int fixture = -1;
  dGeomID geom = nullptr;
  const double forward = firstCrossing(from, to, &normal, &fixture, &geom);
  if (!(forward <= length)) return;  // no surface crossed
  const Vec3 u = (1.0 / length) * (to - from);
  const char* kind = "part through a fixture";
  if (!tr.inside) {
    const double backward = firstCrossing(to, from);
    if (forward + backward < length - crossingTolerance(from, to)) {  // in and out in the step
      tr.entry_fixture = fixture;
      countLoss(i, "through_fixture", kind,
                "passed through a fixture within one step (tunnelled; kept)",
                health_.parts_through_fixture, s);
      return;
    }
    tr.inside = true;  // the anchor is inside a fixture now
    tr.entry_time = time_;
    tr.outside_point = from;
    tr.entry_point = from + forward * u;
    tr.entry_normal = dot(normal, u) < 0 ? normal : -normal;  // outward: against the motion
    tr.entry_fixture = fixture;
    tr.entry_geom = geom;
    return;
  }
  bool unknown = false;
  if (insideFixture(to, &unknown)) {
    // Crossed a surface but is still inside a fixture (out of a floor straight into a wall that
    // stands on it, say): still inside; the new entry is this crossing.
    tr.entry_point = from + forward * u;
    tr.entry_normal = dot(normal, u) < 0 ? normal : -normal;
    tr.entry_fixture = fixture;
    tr.entry_geom = geom;
    tr.entry_time = time_;
    return;
  }
  tr.inside = false;
  // Beyond the exit plane the part is out of the measurement (the metrics may have counted it
  // as an exit): coming out only ends its being inside, it is not counted.
  if (tr.beyond_exit) return;
  const Vec3 exit_normal = dot(normal, u) > 0 ? normal : -normal;  // outward: along the motion
  // Through: out on the far side, the exit surface facing away from the entry surface. Out on
  // the side it entered, or on a face beside it (a corner cut: into a wall's face near its
  // lower edge and out under it, where the flow goes anyway), the part sank and came back.
  if (dot(to - tr.entry_point, tr.entry_normal) > 0 ||
      dot(exit_normal, tr.entry_normal) > -kThroughCosine) {
    // ... but it may have travelled inside the fixture past another one (a plate sunk into a
    // belt that slides under a wall standing on it): the straight path from its last anchor
    // outside to this one then crosses that other geom in and out (crossing the geom it sank
    // into is the corner cut above).
    const double span = norm(to - tr.outside_point);
    dGeomID crossed = nullptr;
    const double in = firstCrossing(tr.outside_point, to, nullptr, nullptr, &crossed),
                 out = firstCrossing(to, tr.outside_point);
    if (span > 0 && in + out < span - crossingTolerance(tr.outside_point, to) &&
        crossed != tr.entry_geom) {
      countLoss(i, "through_fixture", kind,
                "passed under or through a fixture while sunk into another (kept)",
                health_.parts_through_fixture, s);
      return;
    }
    if (!tr.sunk_counted) {
      tr.sunk_counted = true;
      ++health_.parts_sunk;
      const bool corner = dot(to - tr.entry_point, tr.entry_normal) <= 0;
      // A centre sinks by more than the smallest half-size; an off-centre anchor by more than
      // its depth in the part.
      std::string what = corner ? "went into a fixture and came out on a face beside the one it "
                                  "entered (a corner cut, "
                                : "went into a fixture and came back out (a penetration ";
      what += tr.off_centre ? "deeper than the part's anchor lies in it)"
                            : "deeper than half the part)";
      recordEvent(i, "sunk", what, s);
      std::ostringstream line;
      line << "part " << i << " (" << familyName(i) << "): "
           << (tr.off_centre ? "its anchor (a point inside its material: its centre of mass lies "
                               "outside it) "
                             : "its centre ")
           << what << " at t = " << time_ << " s, "
           << (tr.off_centre ? "the anchor at x = " : "x = ") << formatPosition(to);
      reportFirst("part sunk into a fixture", line.str());
    }
    return;
  }
  countLoss(i, "through_fixture", kind,
            "passed through a fixture over several steps (tunnelled; kept)",
            health_.parts_through_fixture, s);
}

const std::string& PartSimulation::familyName(std::size_t i) const {
  return family_keys_.at(static_cast<std::size_t>(instances_.at(i).spec));
}

void PartSimulation::recordEvent(std::size_t i, const char* key, const std::string& what,
                                 const PartState& state) {
  if (health_.part_events.size() >= RunHealth::kMaxPartEvents) {
    ++health_.part_events_dropped;
    return;
  }
  const Track& tr = tracks_[i];
  const bool into_fixture =
      std::string_view(key) == "through_fixture" || std::string_view(key) == "sunk";
  PartEvent e;
  e.part = static_cast<int>(i);
  e.family = familyName(i);
  e.time = time_;
  e.kind = key;
  e.what = what;
  if (into_fixture && tr.entry_fixture >= 0 &&
      tr.entry_fixture < static_cast<int>(scene_.fixtures.size())) {
    e.fixture = scene_.fixtures[static_cast<std::size_t>(tr.entry_fixture)].name;
  }
  e.position = state.position;
  e.velocity = state.velocity;
  health_.part_events.push_back(std::move(e));
}

void PartSimulation::countLoss(std::size_t i, const char* key, const std::string& kind,
                               const std::string& what, int& counter, const PartState& state) {
  Track& tr = tracks_[i];
  if (tr.counted) return;
  tr.counted = true;
  tr.lost = true;
  ++counter;
  recordEvent(i, key, what, state);
  std::ostringstream line;
  line << "part " << i << " (" << familyName(i) << ") " << what << " at t = " << time_
       << " s, x = " << formatPosition(state.position) << ", v = " << formatPosition(state.velocity)
       << "/s, |w| = " << norm(state.angular_velocity) << " rad/s";
  reportFirst(kind, line.str());
}

void PartSimulation::remove(std::size_t i, PartCheck check, const PartState& state,
                            const PartState& park) {
  Track& tr = tracks_[i];
  tr.active = false;
  tr.last = park;
  removePart(static_cast<int>(i), park);
  switch (check) {
    case PartCheck::NonFinite:
      countLoss(i, "nonfinite", "non-finite part", "has a non-finite state (removed)",
                health_.parts_nonfinite, state);
      return;
    case PartCheck::TooFast: {
      std::ostringstream what;
      what << "moves faster (" << partSpeed(state, tr.radius)
           << " m/s at its fastest point) than the scene's speed bound " << limits_.speed_bound
           << " m/s (removed)";
      countLoss(i, "too_fast", "too-fast part", what.str(), health_.parts_too_fast, state);
      return;
    }
    case PartCheck::BelowRemovalHeight:
    case PartCheck::OutOfBounds:
      if (tr.inside && !tr.beyond_exit) {  // went into a fixture and out of the scene
        countLoss(i, "through_fixture", "part through a fixture",
                  "passed through a fixture and left the scene (removed)",
                  health_.parts_through_fixture, state);
      } else if (tr.beyond_exit) {
        if (!tr.counted) ++health_.parts_exited;
        tr.counted = true;
      } else if (check == PartCheck::BelowRemovalHeight) {
        countLoss(i, "fell", "fallen part",
                  "fell below the removal height without crossing an exit plane (removed)",
                  health_.parts_fell, state);
      } else {
        countLoss(i, "out_of_bounds", "part out of bounds", "left the scene bounds (removed)",
                  health_.parts_out_of_bounds, state);
      }
      return;
    case PartCheck::Ok:
      return;
  }
}

void PartSimulation::step() {
  const double h = scene_.solver.time_step;
  advance(h);
  if (stage_timing_) ++stage_times_.steps;
  const StageClock checks(stage_timing_ ? &stage_times_.checks : nullptr);  // to the end
  time_ = ++steps_ * h;
  health_.steps = steps_;
  if (!local_tables_.empty()) {
    LocalDriftStats sum;  // this run's share of each table's counts
    for (const auto& [table, start] : local_tables_) {
      const LocalDriftStats s = table->stats();
      sum.contacts += s.contacts - start.contacts;
      sum.wall_contacts += s.wall_contacts - start.wall_contacts;
      sum.cells_computed += s.cells_computed - start.cells_computed;
      sum.model_runs += s.model_runs - start.model_runs;
      sum.model_cpu_seconds += s.model_cpu_seconds - start.model_cpu_seconds;
      sum.corners_added += s.corners_added - start.corners_added;
    }
    health_.local_law = sum;
  }
  noteContacts();
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    Track& tr = tracks_[i];
    if (!tr.active) continue;
    const PartState s = partState(static_cast<int>(i));
    const PartCheck check =
        tr.engine_nonfinite ? PartCheck::NonFinite : checkPartState(s, limits_, tr.radius);
    if (check == PartCheck::NonFinite) {  // parked at its last finite state
      remove(i, check, s, tr.last);
      continue;
    }
    health_.max_part_speed = std::max(health_.max_part_speed, partSpeed(s, tr.radius));
    if (check == PartCheck::TooFast) {
      remove(i, check, s, s);
      continue;
    }
    checkPhysicalSpeed(i, s);
    tr.beyond_exit = tr.beyond_exit || beyondExitPlane(scene_.outputs, s.position);
    // Beyond the exit plane a part is out of the measurement, but one that crossed it inside a
    // fixture is followed until it comes out (else it would stay "inside" for the rest of the
    // run); coming out there is not counted (trackCrossings).
    if (!tr.counted && (!tr.beyond_exit || tr.inside)) {
      const Vec3 from = anchorAt(i, tr.last), to = anchorAt(i, s);
      if (tr.inside || norm(to - from) > kTunnelCheckFraction * tr.clearance) {
        trackCrossings(i, from, to, s);
      }
    }
    std::string where;
    if (!tr.counted && !tr.beyond_exit && leftFeeder(i, s, where)) {
      countLoss(i, "left_feeder", "part that left the feeder",
                "left the feeder " + where + " (kept)", health_.parts_left_feeder, s);
    }
    if (check != PartCheck::Ok) {
      remove(i, check, s, s);
      continue;
    }
    tr.last = s;
  }
  health_.parts_inside_fixture = 0;
  health_.inside_fixture_now.clear();
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    const Track& tr = tracks_[i];
    if (!tr.active || !tr.inside || tr.counted) continue;
    ++health_.parts_inside_fixture;
    PartEvent e;
    e.part = static_cast<int>(i);
    e.family = familyName(i);
    e.time = tr.entry_time;
    e.kind = "inside_fixture";
    e.what = "went into a fixture and is inside it now";
    if (tr.entry_fixture >= 0 && tr.entry_fixture < static_cast<int>(scene_.fixtures.size())) {
      e.fixture = scene_.fixtures[static_cast<std::size_t>(tr.entry_fixture)].name;
    }
    e.position = tr.last.position;
    e.velocity = tr.last.velocity;
    health_.inside_fixture_now.push_back(std::move(e));
  }
  totals_ = fixtureImpulses(h);
  spawnDue();
}

PartState PartSimulation::part(int index) const {
  const Track& tr = tracks_.at(static_cast<std::size_t>(index));
  if (!tr.active) {
    PartState s = tr.last;
    s.active = false;
    return s;
  }
  return partState(index);
}

double PartSimulation::partMass(int index) const {
  return instances_.at(static_cast<std::size_t>(index)).mass;
}

FrictionModel odeFrictionModel(const SolverSettings& solver) {
  if (!solver.friction) {
    return solver.ode_quickstep && odeHasFrictionCone() ? FrictionModel::Cone
                                                        : FrictionModel::Pyramid;
  }
  if (*solver.friction == FrictionModel::Cone) {
    if (!solver.ode_quickstep) {
      throw std::invalid_argument(
          "solver.friction = \"cone\" needs solver.ode_quickstep = true: dWorldStep (the "
          "Dantzig LCP) cannot express a friction cone");
    }
    requireFrictionModel(FrictionModel::Cone, "solver.friction");
  }
  return *solver.friction;
}

bool odeWarmStartsContacts(const Scene& scene, double time_step) {
  const SolverSettings& solver = scene.solver;
  if (!solver.ode_quickstep) return false;
  if (solver.warm_start) return *solver.warm_start;
  if (!odeHasContactWarmStart() || scene.parts.empty()) return false;
  double thinnest = kInf;
  for (const PartSpec& p : scene.parts) {
    thinnest = std::min(thinnest, checks::partRange(p).thinnest);
  }
  const double g = norm(scene.gravity), h = time_step;
  return g > 0 && h > 0 && thinnest / (g * h * h) < kWarmStartMaxX;
}

bool odeWarmStartsContacts(const Scene& scene) {
  return odeWarmStartsContacts(scene, scene.solver.time_step);
}

std::unique_ptr<Simulation> makeSimulation(const Scene& scene, Method method) {
  scene.validate();
  if (method == Method::OdeRheonomic || method == Method::OdeFullVibration) {
    return makeOdeSimulation(scene, method);
  }
  return makeReferenceSimulation(scene, method);
}

}  // namespace rheofeed::scene
