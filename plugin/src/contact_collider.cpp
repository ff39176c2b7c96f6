// SPDX-License-Identifier: MIT
#include "rheofeed/contact_collider.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>

#include "rheofeed/narrow_phase.hpp"
#include "rheofeed/number_format.hpp"
#include "stage_clock.hpp"

namespace rheofeed {

bool odeHasContactWarmStart() {
  static const bool has = dCheckConfiguration("ODE_EXT_contact_warm_start") != 0;
  return has;
}

ContactCollider::ContactCollider(dWorldID world, FeederSet& feeders)
    : ContactCollider(world, feeders, Settings{}) {}

ContactCollider::ContactCollider(dWorldID world, FeederSet& feeders, const Settings& settings)
    : world_(world), feeders_(feeders), settings_(settings), group_(nullptr) {
  if (!world) throw std::invalid_argument("rheofeed::ContactCollider: world is null");
  if (settings.max_contacts_per_pair < 1 || settings.max_contacts_per_pair > 0xffff) {
    throw std::invalid_argument("rheofeed::ContactCollider: Settings::max_contacts_per_pair = " +
                                std::to_string(settings.max_contacts_per_pair) +
                                " must be in 1..65535");
  }
  if (!(settings.speculative_fraction > 0) || !std::isfinite(settings.speculative_fraction)) {
    throw std::invalid_argument("rheofeed::ContactCollider: Settings::speculative_fraction = " +
                                std::to_string(settings.speculative_fraction) +
                                " must be finite and > 0");
  }
  if (!(settings.warm_start_distance > 0) || !std::isfinite(settings.warm_start_distance)) {
    throw std::invalid_argument("rheofeed::ContactCollider: Settings::warm_start_distance = " +
                                std::to_string(settings.warm_start_distance) +
                                " m must be finite and > 0");
  }
  if (!(settings.warm_start_factor > 0 && settings.warm_start_factor <= 1)) {
    throw std::invalid_argument("rheofeed::ContactCollider: Settings::warm_start_factor = " +
                                std::to_string(settings.warm_start_factor) + " must be in (0, 1]");
  }
  if (settings.warm_start && !odeHasContactWarmStart()) {
    throw std::invalid_argument(
        "rheofeed::ContactCollider: Settings::warm_start = true needs an ODE with rheofeed's "
        "warm-start patch (patches/0005, dCheckConfiguration(\"ODE_EXT_contact_warm_start\")), "
        "but the linked ODE reports \"" +
        std::string(dGetConfiguration()) + "\"");
  }
  const dSurfaceParameters& surface = settings.default_surface;
  const auto requireSurface = [](bool ok, const char* name, double value, const char* range) {
    if (ok) return;
    throw std::invalid_argument("rheofeed::ContactCollider: Settings::default_surface." +
                                std::string(name) + " = " + formatNumber(value) + " must be " +
                                range);
  };
  requireSurface(surface.mu >= 0, "mu", surface.mu, ">= 0 (dInfinity allowed): not NaN");
  if (surface.mode & dContactMu2) {
    requireSurface(surface.mu2 >= 0, "mu2", surface.mu2, ">= 0 (dInfinity allowed): not NaN");
  }
  if (surface.mode & dContactBounce) {
    requireSurface(surface.bounce >= 0 && surface.bounce <= 1, "bounce", surface.bounce,
                   "in [0, 1]");
    requireSurface(surface.bounce_vel >= 0 && std::isfinite(surface.bounce_vel), "bounce_vel",
                   surface.bounce_vel, "finite and >= 0 (m/s)");
  }
  requireFrictionModel(settings.friction, "rheofeed::ContactCollider: Settings::friction");
  settings_.default_surface.mode =
      withFrictionModel(settings.default_surface.mode, settings.friction);
  buffer_.resize(static_cast<std::size_t>(settings.max_contacts_per_pair));
  group_ = dJointGroupCreate(0);
}

ContactCollider::~ContactCollider() {
  if (ray_) dGeomDestroy(ray_);
  if (pass_ray_) dGeomDestroy(pass_ray_);
  for (dGeomID p : proxies_) dGeomDestroy(p);
  dJointGroupDestroy(group_);
}

void ContactCollider::setSurfaceCallback(SurfaceCallback callback) {
  surface_ = std::move(callback);
}

void ContactCollider::clearJoints() {
  dJointGroupEmpty(group_);
  joints_.clear();
  sweeps_.clear();
  sweep_of_proxy_.clear();
  sweep_of_geom_.clear();
  feedback_used_ = 0;
  speculative_count_ = 0;
  warm_started_count_ = 0;
  resting_count_ = 0;
}

void ContactCollider::rethrowPendingError() {
  if (!error_) return;
  std::exception_ptr error = std::move(error_);
  error_ = nullptr;
  std::rethrow_exception(error);
}

namespace {
// Orders geom pairs (a, b) by address: groups a pair's entries in a sorted list (the warm start's
// and the resting points'); within a pair, stable sorts keep the order of insertion.
bool pairBefore(dGeomID a1, dGeomID b1, dGeomID a2, dGeomID b2) {
  return std::less<dGeomID>()(a1, a2) || (a1 == a2 && std::less<dGeomID>()(b1, b2));
}
}  // namespace

void ContactCollider::collide(dSpaceID space, double time, double step) {
  rethrowPendingError();  // an error of a manual pass is not lost
  if (!space) throw std::invalid_argument("rheofeed::ContactCollider::collide: space is null");
  feeders_.beginStep(time, step);  // first: a refused time or step leaves everything as it was
  if (settings_.warm_start) keepWarmStarts();
  clearJoints();
  step_ = step;
  resting_.swap(resting_next_);
  resting_next_.clear();
  std::stable_sort(resting_.begin(), resting_.end(),
                   [](const RestingPoint& x, const RestingPoint& y) {
                     return pairBefore(x.part, x.fixture, y.part, y.fixture);
                   });
  if (settings_.clamp_passes) recordBodies(space);
  const bool speculative = settings_.speculative && step > 0;
  if (speculative) {
    try {
      placeSweeps(space, step);  // the fast bodies' swept boxes join the broad phase
    } catch (...) {
      error_ = std::current_exception();
    }
  }
  if (!error_) collideWithin(space);
  if (speculative) {
    for (const Sweep& s : sweeps_) {
      if (dSpaceID in = dGeomGetSpace(s.proxy)) dSpaceRemove(in, s.proxy);
    }
    if (!error_) {
      try {
        castSweeps(step);
      } catch (...) {
        error_ = std::current_exception();
      }
    }
  }
  if (error_) {
    // The pass stopped at the first exception: drop its partial joints and records, then
    // throw it here, outside ODE.
    clearJoints();
    feeders_.records().clear();
    rethrowPendingError();
  }
}

void ContactCollider::collideWithin(dSpaceID space) {
  // Pairs inside `space` (a sub-space against a geom or another sub-space is split further by
  // nearCallback), then the pairs inside each sub-space, each exactly once.
  dSpaceCollide(space, this, &ContactCollider::nearCallback);
  const int count = dSpaceGetNumGeoms(space);
  for (int i = 0; i < count && !error_; ++i) {
    dGeomID child = dSpaceGetGeom(space, i);
    if (dGeomIsSpace(child)) collideWithin(reinterpret_cast<dSpaceID>(child));
  }
}

void ContactCollider::nearCallback(void* data, dGeomID o1, dGeomID o2) {
  auto* self = static_cast<ContactCollider*>(data);
  if (self->error_) return;  // the pass already failed: no more work
  try {
    if (dGeomIsSpace(o1) || dGeomIsSpace(o2)) {
      dSpaceCollide2(o1, o2, data, &ContactCollider::nearCallback);
      return;
    }
    self->handlePair(o1, o2);
  } catch (...) {
    // ODE's frames must not be unwound: keep the first error for collide() to rethrow.
    if (!self->error_) self->error_ = std::current_exception();
  }
}

void ContactCollider::handlePair(dGeomID o1, dGeomID o2) {
  if (!sweep_of_proxy_.empty()) {
    const auto p1 = sweep_of_proxy_.find(o1), p2 = sweep_of_proxy_.find(o2);
    if (p1 != sweep_of_proxy_.end() || p2 != sweep_of_proxy_.end()) {
      if (p1 != sweep_of_proxy_.end() && p2 != sweep_of_proxy_.end()) return;  // two proxies
      Sweep& s = sweeps_[p1 != sweep_of_proxy_.end() ? p1->second : p2->second];
      s.candidates.push_back(p1 != sweep_of_proxy_.end() ? o2 : o1);
      return;
    }
  }
  dBodyID b1 = dGeomGetBody(o1);
  dBodyID b2 = dGeomGetBody(o2);
  // Two static or kinematic geoms (a vibrating fixture touching a static one in a full-vibration
  // run): nothing to constrain.
  if ((!b1 || dBodyIsKinematic(b1)) && (!b2 || dBodyIsKinematic(b2))) return;
  if (settings_.skip_connected_bodies && b1 && b2 &&
      dAreConnectedExcluding(b1, b2, dJointTypeContact)) {
    return;
  }
  dContact* contacts = buffer_.data();
  int n = collideSpanning(o1, o2, settings_.max_contacts_per_pair, &contacts[0].geom,
                          sizeof(dContact), mesh_buffer_);
  int gaps = 0;
  if (settings_.speculative && step_ > 0) n = addRestingContacts(o1, o2, contacts, n, gaps);
  if (n <= 0) return;
  if (!sweep_of_geom_.empty()) {  // a swept geom in contact already needs no ray to it
    if (const auto it = sweep_of_geom_.find(o1); it != sweep_of_geom_.end()) {
      sweeps_[it->second].touching.push_back(o2);
    }
    if (const auto it = sweep_of_geom_.find(o2); it != sweep_of_geom_.end()) {
      sweeps_[it->second].touching.push_back(o1);
    }
  }
  if (n > gaps) addContacts(o1, o2, contacts, n - gaps, nullptr);
  if (gaps > 0) {
    for (double& g : resting_gap_) g /= step_;  // the gap per step (m/s)
    addContacts(o1, o2, contacts + (n - gaps), gaps, resting_gap_.data());
  }
}

namespace {
double smallestHalfExtent(dGeomID g);
// Marks a resting candidate (addRestingContacts) in its part-side index until the reduction.
constexpr int kRestingTag = -2;
}  // namespace

int ContactCollider::addRestingContacts(dGeomID o1, dGeomID o2, dContact* contacts, int n,
                                        int& gaps) {
  gaps = 0;
  if (dGeomGetClass(o1) != dTriMeshClass || dGeomGetClass(o2) != dTriMeshClass) return n;
  dGeomID part = nullptr, fixture = nullptr;
  for (int k = 0; k < 2 && !part; ++k) {
    const dGeomID a = k == 0 ? o1 : o2, b = k == 0 ? o2 : o1;
    const dBodyID body = dGeomGetBody(a);
    if (body && !dBodyIsKinematic(body) && mesh_buffer_.fixture(b)) part = a, fixture = b;
  }
  if (!part) return n;
  const bool fixture_is_g2 = fixture == o2;
  const double out_sign = fixture_is_g2 ? 1.0 : -1.0;  // ODE's normal: out of g2 into g1
  // collideSpanning has just looked this table up (and checked it) for the pair
  const auto known = mesh_buffer_.edges.find(dGeomTriMeshGetTriMeshDataID(fixture));
  const MeshEdges& edges =
      known != mesh_buffer_.edges.end() ? known->second : mesh_buffer_.edgesOf(fixture);
  const dBodyID body = dGeomGetBody(part);
  const dReal* x = dBodyGetPosition(body);
  const dReal* r = dBodyGetRotation(body);  // row-major 3x4
  // Candidates: this pass's contacts, then the previous pass's points of the pair that are
  // still over the fixture's smooth surface within `margin` of it (above or below).
  resting_candidates_.assign(n, dContactGeom{});
  for (int i = 0; i < n; ++i) resting_candidates_[static_cast<std::size_t>(i)] = contacts[i].geom;
  const double margin = settings_.speculative_fraction * smallestHalfExtent(part);
  const auto first =
      std::lower_bound(resting_.begin(), resting_.end(), std::make_pair(part, fixture),
                       [](const RestingPoint& p, const std::pair<dGeomID, dGeomID>& key) {
                         return pairBefore(p.part, p.fixture, key.first, key.second);
                       });
  for (auto it = first; it != resting_.end() && it->part == part && it->fixture == fixture; ++it) {
    const Vec3& l = it->local;
    const double p[3] = {x[0] + r[0] * l.x + r[1] * l.y + r[2] * l.z,
                         x[1] + r[4] * l.x + r[5] * l.y + r[6] * l.z,
                         x[2] + r[8] * l.x + r[9] * l.y + r[10] * l.z};
    SurfacePoint at;
    if (!surfacePointOver(fixture, edges, it->triangle, p, at)) continue;
    if (!(std::abs(at.height) <= margin)) continue;
    dContactGeom c{};
    for (int k = 0; k < 3; ++k) {
      c.pos[k] = p[k] - at.height * at.normal[k];  // on the fixture's face
      c.normal[k] = out_sign * at.normal[k];
    }
    c.depth = -at.height;  // < 0: a gap, made a speculative contact below
    c.g1 = o1;
    c.g2 = o2;
    c.side1 = fixture_is_g2 ? kRestingTag : at.triangle;  // the part's side tags it
    c.side2 = fixture_is_g2 ? at.triangle : kRestingTag;
    resting_candidates_.push_back(c);
  }
  if (resting_candidates_.size() > static_cast<std::size_t>(n)) {
    n = detail::keepSpanningContacts(resting_candidates_, settings_.max_contacts_per_pair,
                                     &contacts[0].geom, sizeof(dContact));
    // the ones across a gap last, depth 0 and their gap kept (stable: the fixed order stays)
    std::stable_partition(contacts, contacts + n,
                          [](const dContact& c) { return !(c.geom.depth < 0); });
    resting_gap_.clear();
    for (int i = 0; i < n; ++i) {
      int& part_side = fixture_is_g2 ? contacts[i].geom.side1 : contacts[i].geom.side2;
      if (part_side == kRestingTag) {
        part_side = -1;
        ++resting_count_;
      }
      if (!(contacts[i].geom.depth < 0)) continue;
      resting_gap_.push_back(-contacts[i].geom.depth);
      contacts[i].geom.depth = 0;
      ++gaps;
    }
  }
  // Remember where the part touches the fixture (a gap's point on the part) for the next pass.
  for (int i = 0; i < n; ++i) {
    const dContactGeom& c = contacts[i].geom;
    const int triangle = fixture_is_g2 ? c.side2 : c.side1;
    if (triangle < 0) continue;
    const double lift =
        i >= n - gaps ? resting_gap_[static_cast<std::size_t>(i - (n - gaps))] : 0.0;
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = c.pos[k] + lift * out_sign * c.normal[k] - x[k];
    resting_next_.push_back(
        {part, fixture,
         Vec3{r[0] * d[0] + r[4] * d[1] + r[8] * d[2], r[1] * d[0] + r[5] * d[1] + r[9] * d[2],
              r[2] * d[0] + r[6] * d[1] + r[10] * d[2]},
         triangle});
  }
  return n;
}

void ContactCollider::addContacts(dGeomID o1, dGeomID o2, dContact* contacts, int n,
                                  const double* gap_speed) {
  const StageClock creation(
      contact_seconds_);  // contact creation, speculative too (setContactTimer)
  for (int i = 0; i < n; ++i) contacts[i].surface = settings_.default_surface;
  if (surface_ && !surface_(o1, o2, contacts, n)) return;
  if (gap_speed) {
    for (int i = 0; i < n; ++i) {
      contacts[i].surface.mode |= dContactMotionN;
      contacts[i].surface.motionN = -gap_speed[i];
    }
    speculative_count_ += n;
  }
  if (!odeHasFrictionCone()) {
    for (int i = 0; i < n; ++i) {
      if (contacts[i].surface.mode & kContactFrictionCone) {
        throw std::invalid_argument(
            "rheofeed::ContactCollider: the SurfaceCallback set dContactFrictionCone (mode "
            "bit 0x8000) but the linked ODE has no friction cone (a stock library would "
            "silently solve the pyramid): clear the bit, or link the patched ODE");
      }
    }
  }

  std::vector<ContactRecord>& records = feeders_.records();
  const std::size_t first_record = records.size();
  n = feeders_.driveContacts(contacts, n);
  const bool warm = settings_.warm_start && !gap_speed && !warm_.empty();
  if (warm) applyWarmStarts(o1, o2, contacts, n);
  const bool recorded = records.size() > first_record;
  std::size_t next_record = first_record;
  const bool feeder_pair = recorded && (feeders_.contains(o1) || feeders_.contains(o2));

  const bool g2_first = feeders_.options().attach_order == AttachOrder::G2First;
  for (int i = 0; i < n; ++i) {
    dBodyID a = dGeomGetBody(contacts[i].geom.g1);
    dBodyID b = dGeomGetBody(contacts[i].geom.g2);
    dJointID joint;
    if (g2_first) {
      // ODE's normal points into g1 and the joint pushes its first body along it: attaching
      // body(g2) first needs the negated normal, or the contact pulls the bodies together.
      dContact reversed = contacts[i];
      for (int k = 0; k < 3; ++k) reversed.geom.normal[k] = -reversed.geom.normal[k];
      joint = dJointCreateContact(world_, group_, &reversed);
      std::swap(a, b);
    } else {
      joint = dJointCreateContact(world_, group_, &contacts[i]);
    }
    dJointAttach(joint, a, b);
    // feedback f1 is the force on the joint's first body: a, or b when a is 0 (ODE keeps the
    // non-null body first); a is g1's body unless g2_first swapped them
    const bool first_body_is_g1 = (a != nullptr) != g2_first;
    dJointFeedback* fb = nullptr;
    if (settings_.feedback || settings_.warm_start) {
      if (feedback_used_ == feedback_.size()) feedback_.emplace_back();
      fb = &feedback_[feedback_used_++];
      *fb = dJointFeedback{};
      if (warm && warm_starts_[static_cast<std::size_t>(i)].has_force) {
        const Vec3 f = warm_starts_[static_cast<std::size_t>(i)].force;  // on g1's body
        const Vec3 f1 = first_body_is_g1 ? f : -f;
        fb->f1[0] = f1.x;
        fb->f1[1] = f1.y;
        fb->f1[2] = f1.z;
      }
      dJointSetFeedback(joint, fb);
    }
    const dReal* n_i = contacts[i].geom.normal;
    const dReal* p_i = contacts[i].geom.pos;
    const bool persisted = warm && warm_starts_[static_cast<std::size_t>(i)].persisted;
    joints_.push_back({contacts[i].geom.g1,
                       contacts[i].geom.g2,
                       {n_i[0], n_i[1], n_i[2]},
                       joint,
                       fb,
                       {p_i[0], p_i[1], p_i[2]},
                       first_body_is_g1,
                       persisted});
    if (feeder_pair && next_record < records.size()) {
      ContactRecord& r = records[next_record++];
      r.joint = joint;
      r.feedback = fb;
    }
  }
}

namespace {
// Warm start: a previous contact gives its force only to a new one whose normal is within
// about 18 degrees of its own (cos 0.95); a contact that changed feature (an edge of a thin
// blade instead of its face) starts from zero.
constexpr double kWarmStartNormalCos = 0.95;
}  // namespace

void ContactCollider::keepWarmStarts() {
  warm_.clear();
  for (const Joint& j : joints_) {
    if (!j.feedback) continue;
    const dReal* f1 = j.feedback->f1;
    Vec3 on_g1{f1[0], f1[1], f1[2]};
    if (!j.first_body_is_g1) on_g1 = -on_g1;
    if (!isFinite(on_g1)) continue;  // a diverged step gives no start
    const bool g1_lo = std::less<dGeomID>()(j.g1, j.g2);
    // the normal (from g2 into g1) turned to point into lo
    warm_.push_back({g1_lo ? j.g1 : j.g2, g1_lo ? j.g2 : j.g1, j.position,
                     g1_lo ? j.normal : -j.normal, g1_lo ? on_g1 : -on_g1, j.persisted, false});
  }
  // Stable: a pair's contacts keep the joints' order. An unstable sort left them in an order that
  // depended on how other pairs' addresses compared, and a new contact exactly as near to two of
  // them took the later one: mesh scenes ran differently from another folder
  // (BowlFeeder.MeshBowlRunsTheSameFromAnyFolder).
  std::stable_sort(warm_.begin(), warm_.end(), [](const WarmContact& x, const WarmContact& y) {
    return pairBefore(x.lo, x.hi, y.lo, y.hi);
  });
}

void ContactCollider::applyWarmStarts(dGeomID o1, dGeomID o2, dContact* contacts, int n) {
  warm_starts_.assign(static_cast<std::size_t>(n), WarmStart{});
  const bool o1_lo = std::less<dGeomID>()(o1, o2);
  const dGeomID lo = o1_lo ? o1 : o2, hi = o1_lo ? o2 : o1;
  const auto first =
      std::lower_bound(warm_.begin(), warm_.end(), std::make_pair(lo, hi),
                       [](const WarmContact& x, const std::pair<dGeomID, dGeomID>& key) {
                         return pairBefore(x.lo, x.hi, key.first, key.second);
                       });
  const double reach2 = settings_.warm_start_distance * settings_.warm_start_distance;
  for (int i = 0; i < n; ++i) {
    const dReal* p = contacts[i].geom.pos;
    const bool g1_lo = contacts[i].geom.g1 == lo;
    const dReal* nrm = contacts[i].geom.normal;
    const Vec3 normal_into_lo =
        g1_lo ? Vec3{nrm[0], nrm[1], nrm[2]} : Vec3{-nrm[0], -nrm[1], -nrm[2]};
    WarmContact* best = nullptr;
    double best2 = reach2;
    for (auto it = first; it != warm_.end() && it->lo == lo && it->hi == hi; ++it) {
      // the same point of the same feature: near, and with nearly the same normal
      if (it->used || dot(it->normal, normal_into_lo) < kWarmStartNormalCos) continue;
      const Vec3 d{p[0] - it->position.x, p[1] - it->position.y, p[2] - it->position.z};
      const double d2 = dot(d, d);
      if (d2 <= best2) {
        best2 = d2;
        best = &*it;
      }
    }
    if (!best) continue;
    best->used = true;
    WarmStart& w = warm_starts_[static_cast<std::size_t>(i)];
    w.persisted = true;
    if (!best->persisted) continue;  // its force was a first impact's
    // the force on the body of this contact's g1 (the previous force was on lo's body)
    const double f = settings_.warm_start_factor;
    w.has_force = true;
    w.force = f * (g1_lo ? best->force : -best->force);
    contacts[i].surface.mode |= kContactWarmStart;
    ++warm_started_count_;
  }
}

namespace {

// The smallest half extent (m) of a geom, and its leading points: where a ray along the motion
// starts (world frame). Boxes: the 8 corners; spheres: the point ahead; capsules: the point
// ahead of each cap; anything else: the corners of its axis-aligned bounding box.
double smallestHalfExtent(dGeomID g) {
  switch (dGeomGetClass(g)) {
    case dBoxClass: {
      dVector3 l;
      dGeomBoxGetLengths(g, l);
      return 0.5 * std::min({l[0], l[1], l[2]});
    }
    case dSphereClass:
      return dGeomSphereGetRadius(g);
    case dCapsuleClass: {
      dReal r, l;
      dGeomCapsuleGetParams(g, &r, &l);
      return r;
    }
    case dCylinderClass: {
      dReal r, l;
      dGeomCylinderGetParams(g, &r, &l);
      return std::min(r, 0.5 * l);
    }
    default: {
      dReal b[6];
      dGeomGetAABB(g, b);
      return 0.5 * std::min({b[1] - b[0], b[3] - b[2], b[5] - b[4]});
    }
  }
}

// The leading points of boxes and cylinders lie this fraction of the half extent inside the
// geom's surface. A ray cast from an exact corner of a box that lands flat on an equal box
// grazes that box's edge, and hits or misses by rounding: one or two of the four corners then
// stopped and the others not, and the cube landed spinning at 24 rad/s (10 mm cubes at h = 14 ms)
// and toppled off the one below. 1e-4 keeps the rays 0.5 um inside a 10 mm cube's faces.
constexpr double kLeadingPointInset = 1e-4;

// A swept part already touching a triangle mesh (a nut sliding down the bowl's wall) gets
// speculative contacts with it only where its motion runs into the surface at more than 30
// degrees from the surface's plane (cosine between motion and normal above 0.5: the ramp below),
// not along the touched wall, whose own contacts hold it.
constexpr double kTouchingMeshMinCosine = 0.5;
// ... and only where the surface lies ahead of the ray's start by more than this fraction of the
// part's smallest half extent (25 um for a 5 mm nut): a resting part's leading points sit on
// or just above the floor it touches (those below it see only its back faces, which the rays
// cull), and that floor is held by the regular contacts.
constexpr double kTouchingMeshMinGap = 0.01;

int leadingPoints(dGeomID g, const dReal dir[3], dReal out[8][3]) {
  const dReal* c = dGeomGetPosition(g);
  const dReal* r = dGeomGetRotation(g);  // row-major 3x4
  auto local = [&](double x, double y, double z, dReal p[3]) {
    for (int k = 0; k < 3; ++k) p[k] = c[k] + r[4 * k] * x + r[4 * k + 1] * y + r[4 * k + 2] * z;
  };
  switch (dGeomGetClass(g)) {
    case dBoxClass: {
      dVector3 l;
      dGeomBoxGetLengths(g, l);
      int n = 0;
      const double f = 0.5 * (1 - kLeadingPointInset);
      for (int i = 0; i < 8; ++i) {
        local((i & 1 ? f : -f) * l[0], (i & 2 ? f : -f) * l[1], (i & 4 ? f : -f) * l[2], out[n++]);
      }
      return n;
    }
    case dSphereClass: {
      const dReal rad = dGeomSphereGetRadius(g);
      for (int k = 0; k < 3; ++k) out[0][k] = c[k] + rad * dir[k];
      return 1;
    }
    case dCapsuleClass: {
      dReal rad, len;
      dGeomCapsuleGetParams(g, &rad, &len);
      for (int e = 0; e < 2; ++e) {
        local(0, 0, (e ? 0.5 : -0.5) * len, out[e]);
        for (int k = 0; k < 3; ++k) out[e][k] += rad * dir[k];
      }
      return 2;
    }
    case dCylinderClass: {
      // Four rim points of each end: the one furthest along the motion and its quarter turns
      // (a cylinder moving along its axis leads with a whole face).
      dReal rad, len;
      dGeomCylinderGetParams(g, &rad, &len);
      const double axis[3] = {r[2], r[6], r[10]};  // local z in world
      const double along = dir[0] * axis[0] + dir[1] * axis[1] + dir[2] * axis[2];
      double u[3] = {dir[0] - along * axis[0], dir[1] - along * axis[1], dir[2] - along * axis[2]};
      double nu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      if (nu < 1e-9) {  // along the axis: any radial direction
        u[0] = r[0], u[1] = r[4], u[2] = r[8];
        nu = 1;
      }
      for (double& x : u) x /= nu;
      const double w[3] = {axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2],
                           axis[0] * u[1] - axis[1] * u[0]};
      int n = 0;
      const double in = 1 - kLeadingPointInset;
      for (int e = 0; e < 2; ++e) {
        const double h = (e ? 0.5 : -0.5) * len * in;
        for (int q = 0; q < 4; ++q) {
          const double cu = q == 0 ? 1 : q == 2 ? -1 : 0, cw = q == 1 ? 1 : q == 3 ? -1 : 0;
          for (int k = 0; k < 3; ++k)
            out[n][k] = c[k] + h * axis[k] + rad * in * (cu * u[k] + cw * w[k]);
          ++n;
        }
      }
      return n;
    }
    default: {
      dReal b[6];
      dGeomGetAABB(g, b);
      for (int i = 0; i < 8; ++i) {
        out[i][0] = b[i & 1 ? 1 : 0];
        out[i][1] = b[i & 2 ? 3 : 2];
        out[i][2] = b[i & 4 ? 5 : 4];
      }
      return 8;
    }
  }
}

}  // namespace

void ContactCollider::placeSweeps(dSpaceID space, double step) {
  if (space == nullptr) return;
  const int count = dSpaceGetNumGeoms(space);
  std::vector<dGeomID> geoms;
  geoms.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) geoms.push_back(dSpaceGetGeom(space, i));
  for (dGeomID g : geoms) {
    if (dGeomIsSpace(g)) {
      placeSweeps(reinterpret_cast<dSpaceID>(g), step);
      continue;
    }
    dBodyID body = dGeomGetBody(g);
    if (!body || !dBodyIsEnabled(body) || dBodyIsKinematic(body)) continue;
    const dReal* v = dBodyGetLinearVel(body);
    double end_v[3] = {v[0], v[1], v[2]};
    if (dBodyGetGravityMode(body)) {
      dVector3 gravity;
      dWorldGetGravity(world_, gravity);
      for (int k = 0; k < 3; ++k) end_v[k] += gravity[k] * step;
    }
    const double speed = std::sqrt(end_v[0] * end_v[0] + end_v[1] * end_v[1] + end_v[2] * end_v[2]);
    const double travel = speed * step;
    if (!(travel > settings_.speculative_fraction * smallestHalfExtent(g))) continue;

    // The swept box: the geom's box and that box moved by the travel. It joins the geom's space
    // for the regular pass, which finds its candidates (handlePair) at the broad phase's cost.
    Sweep s;
    s.geom = g;
    s.travel = travel;
    for (int k = 0; k < 3; ++k) s.dir[k] = end_v[k] / speed;
    dReal b[6];
    dGeomGetAABB(g, b);
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(b[2 * k], b[2 * k] + s.dir[k] * travel);
      hi[k] = std::max(b[2 * k + 1], b[2 * k + 1] + s.dir[k] * travel);
    }
    if (sweeps_.size() == proxies_.size()) proxies_.push_back(dCreateBox(nullptr, 1, 1, 1));
    s.proxy = proxies_[sweeps_.size()];
    dGeomBoxSetLengths(s.proxy, hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    dGeomSetPosition(s.proxy, 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]));
    sweep_of_proxy_[s.proxy] = sweeps_.size();
    sweep_of_geom_[g] = sweeps_.size();
    const dGeomID proxy = s.proxy;
    sweeps_.push_back(std::move(s));
    dSpaceAdd(space, proxy);  // last: collide() takes out every proxy that is in a space
  }
}

void ContactCollider::castSweeps(double step) {
  if (!ray_) {
    ray_ = dCreateRay(nullptr, 1);
    dGeomRaySetClosestHit(ray_, 1);
    // A ray that starts inside a triangle mesh (a bounding-box corner of a mesh part inside a
    // neighbour) must not hit that mesh's far side from within: only faces seen from outside.
    dGeomRaySetBackfaceCull(ray_, 1);
  }
  std::vector<dContact>& contacts = buffer_;
  for (const Sweep& s : sweeps_) {
    if (s.candidates.empty()) continue;
    const dGeomID geom = s.geom;
    const dBodyID body = dGeomGetBody(geom);
    dReal points[8][3];
    const int np = leadingPoints(geom, s.dir, points);
    dGeomRaySetLength(ray_, s.travel);
    double gap_speed[8];
    for (dGeomID other : s.candidates) {
      if (other == geom || dGeomGetBody(other) == body) continue;
      // A geom the regular pass already gave contacts with needs no ray, unless it is a triangle
      // mesh: one mesh holds a whole bowl, so a nut sliding down its wall touches it and would
      // never be swept onto the ramp below. Against a touching mesh only a ray that runs into
      // the surface steeply (kTouchingMeshMinCosine) and hits it ahead of the part
      // (kTouchingMeshMinGap) counts: not the touched wall it grazes, nor the floor it rests on.
      const bool touching =
          std::find(s.touching.begin(), s.touching.end(), other) != s.touching.end();
      if (touching && dGeomGetClass(other) != dTriMeshClass) continue;
      const double min_along = touching ? kTouchingMeshMinCosine : 1e-6;
      const double min_distance = touching ? kTouchingMeshMinGap * smallestHalfExtent(geom) : 0.0;
      int n = 0;
      for (int i = 0; i < np && n < static_cast<int>(contacts.size()) && n < 8; ++i) {
        if (dGeomGetClass(other) == dBoxClass &&
            dGeomBoxPointDepth(other, points[i][0], points[i][1], points[i][2]) >= 0) {
          continue;  // starts inside the box (a bounding-box corner): no gap to measure
        }
        dGeomRaySet(ray_, points[i][0], points[i][1], points[i][2], s.dir[0], s.dir[1], s.dir[2]);
        dContactGeom hit;
        if (dCollide(ray_, other, 1, &hit, sizeof hit) < 1) continue;
        if (!(hit.depth > min_distance)) continue;  // a touched mesh's surface at the part
        double along =
            hit.normal[0] * s.dir[0] + hit.normal[1] * s.dir[1] + hit.normal[2] * s.dir[2];
        const double sign =
            along > 0 ? -1.0 : 1.0;  // the normal out of `other`, against the motion
        along = std::fabs(along);
        if (!(along > min_along)) continue;  // grazing: the motion does not close it
        dContactGeom& c = contacts[static_cast<std::size_t>(n)].geom;
        for (int k = 0; k < 3; ++k) {
          c.pos[k] = hit.pos[k];
          c.normal[k] = sign * hit.normal[k];  // into g1 = the swept geom
        }
        c.depth = 0;
        c.g1 = geom;
        c.g2 = other;
        c.side1 = c.side2 = -1;
        gap_speed[n] = hit.depth * along / step;  // the gap along the normal, per step
        ++n;
      }
      if (n > 0) addContacts(geom, other, contacts.data(), n, gap_speed);
    }
  }
}

void ContactCollider::recordBodies(dSpaceID space) {
  bodies_before_.clear();
  static_geoms_.clear();
  if (space == nullptr) return;
  std::vector<dSpaceID> spaces{space};
  while (!spaces.empty()) {
    const dSpaceID sp = spaces.back();
    spaces.pop_back();
    const int count = dSpaceGetNumGeoms(sp);
    for (int i = 0; i < count; ++i) {
      const dGeomID g = dSpaceGetGeom(sp, i);
      if (dGeomIsSpace(g)) {
        spaces.push_back(reinterpret_cast<dSpaceID>(g));
        continue;
      }
      const dBodyID b = dGeomGetBody(g);
      if (!b) {
        if (dGeomIsEnabled(g)) static_geoms_.push_back(g);
      } else if (dBodyIsEnabled(b) && !dBodyIsKinematic(b) &&
                 (bodies_before_.empty() || bodies_before_.back().body != b)) {
        const dReal* c = dBodyGetPosition(b);
        const dReal* q = dBodyGetQuaternion(b);
        // A centre that moves less than this cannot have crossed a fixture from outside it
        // (it starts at least the geom's smallest half extent from any surface it rests on).
        bodies_before_.push_back({b,
                                  {c[0], c[1], c[2]},
                                  {q[0], q[1], q[2], q[3]},
                                  settings_.speculative_fraction * smallestHalfExtent(g)});
      }
    }
  }
}

std::vector<ContactCollider::ThroughPass> ContactCollider::stopPassesThroughStaticGeoms() {
  std::vector<ThroughPass> passes;
  std::vector<dBodyID> stopped;  // this step's, for the next call's no-repeat rule
  if (settings_.clamp_passes && !static_geoms_.empty()) {
    if (!pass_ray_) {
      pass_ray_ = dCreateRay(nullptr, 1);
      dGeomRaySetClosestHit(pass_ray_, 1);
    }
    const auto cast = [this](const Vec3& from, const Vec3& dir, double length, dGeomID g,
                             dContactGeom* hit) {
      dGeomRaySetLength(pass_ray_, length);
      dGeomRaySet(pass_ray_, from.x, from.y, from.z, dir.x, dir.y, dir.z);
      return dCollide(pass_ray_, g, 1, hit, sizeof *hit) > 0;
    };
    for (const BodyBefore& before : bodies_before_) {
      // A body stopped in the previous step is not stopped again: the stop gave it back its
      // pre-step state, so a second pass would repeat for ever and freeze it. The pass stands,
      // and the caller's own checks count it.
      if (std::find(stopped_last_.begin(), stopped_last_.end(), before.body) !=
          stopped_last_.end()) {
        continue;
      }
      const dReal* c = dBodyGetPosition(before.body);
      const Vec3 to{c[0], c[1], c[2]};
      const Vec3 d = to - before.centre;
      const double length = norm(d);
      if (!(length > before.min_travel) || !isFinite(to)) continue;
      const Vec3 u = (1.0 / length) * d;
      // The segment's bounding box, to skip geoms it cannot reach.
      const Vec3 lo{std::min(before.centre.x, to.x), std::min(before.centre.y, to.y),
                    std::min(before.centre.z, to.z)};
      const Vec3 hi{std::max(before.centre.x, to.x), std::max(before.centre.y, to.y),
                    std::max(before.centre.z, to.z)};
      for (dGeomID g : static_geoms_) {
        if (dGeomGetClass(g) != dPlaneClass) {  // a plane's box is infinite, and it has no far side
          dReal box[6];
          dGeomGetAABB(g, box);
          if (hi.x < box[0] || lo.x > box[1] || hi.y < box[2] || lo.y > box[3] || hi.z < box[4] ||
              lo.z > box[5]) {
            continue;
          }
        }
        dContactGeom in, out;
        if (!cast(before.centre, u, length, g, &in)) continue;
        if (!cast(to, -1.0 * u, length, g, &out)) continue;
        // In and out within the step; crossings within a micrometre are one surface (a ray
        // grazing an edge), not a pass.
        if (!(in.depth + out.depth < length - 1e-6)) continue;
        Vec3 n{in.normal[0], in.normal[1], in.normal[2]};
        if (dot(n, u) > 0) n = -1.0 * n;  // out of the geom, against the motion
        ThroughPass p;
        p.body = before.body;
        p.geom = g;
        p.from = before.centre;
        p.to = to;
        p.normal = n;
        passes.push_back(p);
        stopped.push_back(before.body);
        // Back to the pre-step pose, stopped against the surface: the velocity into it and the
        // spin (which would turn the part into it again) removed.
        dBodySetPosition(before.body, before.centre.x, before.centre.y, before.centre.z);
        dBodySetQuaternion(before.body, before.orientation);
        const dReal* v = dBodyGetLinearVel(before.body);
        Vec3 vel{v[0], v[1], v[2]};
        const double into = dot(vel, n);
        if (into < 0) vel = vel - into * n;
        dBodySetLinearVel(before.body, vel.x, vel.y, vel.z);
        dBodySetAngularVel(before.body, 0, 0, 0);
        break;  // put back: no other geom to test
      }
    }
  }
  // The records are this step's only: a second call, or a step without collide(), finds none.
  bodies_before_.clear();
  stopped_last_ = std::move(stopped);
  return passes;
}

}  // namespace rheofeed
