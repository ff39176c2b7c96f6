// SPDX-License-Identifier: MIT
/// @file contact_collider.hpp
/// A ready near callback that does the collision bookkeeping for the application: it collides
/// geom pairs, lets the application fill the surface parameters, drives feeder contacts through
/// a FeederSet and creates and attaches the contact joints itself, in ODE's attach order
/// `dJointAttach(j, dGeomGetBody(g1), dGeomGetBody(g2))` (or the reverse, with the joint's copy
/// of the normal negated, when the FeederSet's Options::attach_order is G2First).
///
///     rheofeed::ContactCollider collider(world, feeders);
///     collider.setSurfaceCallback([](dGeomID, dGeomID, dContact* c, int n) {
///       for (int i = 0; i < n; ++i) { c[i].surface.mode = 0; c[i].surface.mu = 0.5; }
///       return true;                                  // false: no joints for this pair
///     });
///     // each step of h seconds:
///     collider.collide(space, time, h);               // beginStep + dSpaceCollide + joints
///     dWorldQuickStep(world, h);
///
/// Applications that call dSpaceCollide themselves pass `&collider` and
/// `ContactCollider::nearCallback` to it (after `beginStep(time, h)` and `clearJoints()`), and
/// call `rethrowPendingError()` after dSpaceCollide returns.
///
/// ## Speculative contacts
/// ODE makes contacts only where geoms already overlap, so a part that moves more than its own
/// thickness in a step (a box falling from a hopper at h = 0.01 s) can land with its centre
/// inside a fixture, or pass through a thin one. With Settings::speculative, collide() sweeps
/// each fast body (Settings::speculative_fraction) along its velocity at the end of the step:
/// rays from its leading points (a box's 8 corners and four rim points of each end of a cylinder,
/// each 1e-4 of the half extent inside the surface so that a ray from a corner of a box landing
/// flat on an equal box cannot graze that box's edge; a sphere's or capsule's point ahead; for
/// other shapes (meshes, convex hulls) the corners of the
/// geom's bounding box, which may stop a part up to that box's
/// slack short of the surface for one step) over the travel |v + g h| h, against every geom of
/// the space that the regular pass did not already pair with it. A ray that hits at distance t
/// gives a contact at the hit point, normal n the hit surface's (out of the obstacle, against
/// the motion), depth 0, and the gap d = t |v^ . n| as a velocity bound: the surface mode gains
/// dContactMotionN with motionN = -d / h, so the normal row lets the bodies close at most the
/// gap within the step (J v >= -d / h; stock ODE, no patch) and pushes only if they would
/// overlap at its end. Friction on such a contact is bounded by its normal impulse, zero unless
/// it closes. The contacts go through the SurfaceCallback and the FeederSet like any other
/// (the motionN is set after the callback) and are counted (speculativeContactCount).
///
/// Resting contacts (also Settings::speculative): ODE's trimesh-trimesh test makes contacts
/// only where triangles cross, so a mesh part lying flat on a fixture mesh, one side of its face
/// lifted a nanometre by rounding, gets contacts on the other side only; gravity then swings the
/// free side down by g h within the step (a flat mesh nut on 1 mm triangles spun at 13-18 rad/s at
/// h = 0.01 s). So each point where a mesh part touched a fixture mesh (MeshCollisionScratch::
/// fixture) is kept, in the part's body frame with the fixture triangle under it, for the next
/// pass: there, the pair's points that are still over the fixture's smooth surface
/// (surfacePointOver) within speculative_fraction times the part's smallest half extent of it
/// join the new contacts (at the point's foot on the face, with the face's normal), the union is
/// reduced to max_contacts_per_pair spanning it (collideSpanning's rule), and the kept ones that
/// lie across a gap become speculative contacts (the gap as above). They are counted
/// (restingContactCount).
///
/// ## Passes stopped
/// Speculative contacts see a body's velocity before the solve. A part struck by another within
/// the step (a crowd landing: a box knocked down at 1-2 m/s, spinning at 200 rad/s) gets its
/// speed from the solve and can cross a thin fixture (a 2 mm floor) in one step, with no contact
/// to stop it. With Settings::clamp_passes, collide() records each dynamic body's centre of mass
/// and orientation, and stopPassesThroughStaticGeoms(), called after the step, finds the bodies
/// whose centre went in through a static geom's surface and out through another within the step
/// (ODE rays, both ways), puts each back where it was before the step, with the velocity into the
/// entry surface and the spin removed: an inelastic stop at the surface, one step early. A body
/// stopped in one step is not stopped in the next (its state was put back, so the pass could
/// repeat for ever): that pass stands, for the caller's own checks to count. The caller counts
/// the stops. Limits: only static geoms (no body) are tested, so a vibrating fixture of a
/// full-vibration run (a kinematic body) is not; a single open sheet (a mesh with no inside), a
/// centre that ends inside the geom (left to the contacts), a pass through another part, and a
/// body's centre of mass lying outside its material (a ring around a bar) are not told apart
/// from the geom's inside; geom category and collide bits and the SurfaceCallback are not
/// consulted; a body whose centre moves less than speculative_fraction times its geom's smallest
/// half extent in the step is not tested.
///
/// ## Warm start
/// ODE's quickstep starts every row from zero, so a heap's weight is rebuilt from nothing each
/// step, one layer per Gauss-Seidel sweep, and stays short of it at a fixed iteration count.
/// With Settings::warm_start (the patched ODE: patches/0005, odeHasContactWarmStart()),
/// collide() first reads the force each contact joint of the previous pass applied in the step
/// between (its dJointFeedback), and gives each new contact of the same geom pair whose point
/// lies within Settings::warm_start_distance of a previous one whose normal is within about 18
/// degrees of its own (the nearest, each used once) that force, times
/// Settings::warm_start_factor, as its starting point: the surface mode gains
/// dContactWarmStart and the joint's feedback f1 holds the force before the step. A contact's
/// first force is not passed on: it holds the impulse of an impact (a part landing), which
/// repeated in the next step throws the part back up; a contact passes its force on from its
/// second step. The iterations go
/// on from there, with the same bounds (the result is still a quickstep solution, reached from a
/// nearer start). Contacts warm-started are counted (warmStartedContactCount). Only collide() reads
/// the previous pass: a manual dSpaceCollide pass starts from zero.
///
/// ## Friction model
/// Settings::friction sets dContactFrictionCone (cone) or clears it (pyramid) on every contact
/// before the SurfaceCallback, which may choose per contact. A contact that asks for the cone
/// when the linked ODE has none (a stock libode, which would silently solve the pyramid) is an
/// error: std::invalid_argument naming the bit, rethrown by collide() (Exceptions below).
///
/// ## Exceptions
/// No exception crosses ODE: the near callback catches everything thrown inside it (by the
/// SurfaceCallback, by an allocation for the joint list), keeps the first exception, and does
/// no more work for the rest of the pass (every later pair is skipped). collide() then empties
/// the joint group and the FeederSet's records (a world stepped anyway has no contact joints
/// from the failed pass, and no record points at a destroyed joint) and rethrows that
/// exception after dSpaceCollide has returned. The collider and the world stay usable: the next
/// collide() starts afresh.
#pragma once

#include <ode/ode.h>

#include <deque>
#include <exception>
#include <functional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "rheofeed/feeder_set.hpp"
#include "rheofeed/narrow_phase.hpp"

namespace rheofeed {

/// Fills `contacts[0..count)` (produced by dCollide for geoms o1, o2) with the application's
/// surface parameters (mode, mu, bounce, soft_erp, ...). Return false to reject the pair. Called
/// from inside dSpaceCollide, never for a pair of two static or kinematic geoms (no body ODE
/// moves: nothing to constrain; those pairs are not collided at all). If it throws, the exception
/// is kept and rethrown by ContactCollider::collide after dSpaceCollide returns (file comment),
/// never through ODE.
using SurfaceCallback = std::function<bool(dGeomID o1, dGeomID o2, dContact* contacts, int count)>;

/// Collides a space and creates the step's contact joints. Owns its contact joint group.
class ContactCollider {
 public:
  struct Settings {
    /// Contacts kept per geom pair, 1..65535: dCollide's limit for pairs of primitives; for a
    /// pair with a triangle mesh every contact is asked for and this many spanning the set
    /// are kept (collideSpanning, narrow_phase.hpp).
    int max_contacts_per_pair = 8;
    /// Skip pairs whose bodies are already connected by a non-contact joint.
    bool skip_connected_bodies = true;
    /// Attach a dJointFeedback to every contact joint: forces readable after the step through
    /// joints(), and through FeederSet::records() for feeder contacts when the FeederSet has
    /// Options::record_contacts.
    bool feedback = false;
    /// Surface every contact starts from (the SurfaceCallback may change it): Approx1 friction
    /// with mu = 0.5. The constructor refuses a NaN or negative mu (and mu2 with dContactMu2), a
    /// bounce outside [0, 1] or a negative bounce_vel (m/s) with dContactBounce.
    dSurfaceParameters default_surface = {
        dContactApprox1, 0.5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    /// Friction law of every contact (friction_model.hpp), set in default_surface's mode
    /// before the SurfaceCallback runs (which may change it per contact, with
    /// kContactFrictionCone); feeder contacts then get the FeederSet's friction model
    /// (FeederSet::frictionModel). Cone needs the patched ODE and dWorldQuickStep.
    FrictionModel friction = FrictionModel::Pyramid;
    /// Speculative contacts (file comment): collide() also sweeps every body whose travel in
    /// the step, |v + g h| h (m; v its linear velocity, g the world's gravity when the body
    /// feels it), exceeds `speculative_fraction` times its geom's smallest half extent, and gives
    /// it a contact with each geom its leading points would reach within the step. Off by default.
    bool speculative = false;
    /// Travel per step, as a fraction of a geom's smallest half extent, above which its body is
    /// swept (finite, > 0); 0.25 catches a part well before it can pass through anything as
    /// thick as itself.
    double speculative_fraction = 0.25;
    /// Passes stopped (file comment): collide() records every body's centre, and
    /// stopPassesThroughStaticGeoms() puts back a body whose centre passed through a static
    /// geom in the step. Off by default.
    bool clamp_passes = false;
    /// Warm start (file comment): each contact starts from the force (N) of the previous
    /// step's contact of the same geom pair nearest to its point, within warm_start_distance.
    /// Needs the patched ODE (odeHasContactWarmStart()) and dWorldQuickStep on one thread;
    /// attaches a dJointFeedback to every contact joint. Off by default.
    bool warm_start = false;
    /// Largest distance (m, finite, > 0) between a contact point and the previous step's point
    /// it takes its warm start from: 1 mm, well above a resting part's motion in a step and
    /// below the distance between the corners of the smallest parts in the demos (5 mm).
    double warm_start_distance = 1e-3;
    /// Fraction (0, 1] of the previous force a contact starts from. A full start (1) lets a
    /// column of 12 cubes at 10 iterations oscillate for good (the previous step's force
    /// includes ERP's push against the overlap, which it then repeats), as 0.95 does, and 0.9
    /// let it jump once at 20 iterations; 0.8 held every column measured (6-20 cubes, 10-40
    /// iterations; tests/plugin/contact_collider_test.cpp), each settling less than from zero.
    double warm_start_factor = 0.8;
  };

  /// `world` receives the joints; `feeders` must outlive the collider. Throws
  /// std::invalid_argument for a null world, max_contacts_per_pair outside 1..65535, a bad
  /// speculative_fraction, warm_start_distance or warm_start_factor, friction = Cone on an ODE
  /// without the cone, or warm_start on an ODE without warm starts.
  ContactCollider(dWorldID world, FeederSet& feeders);
  ContactCollider(dWorldID world, FeederSet& feeders, const Settings& settings);
  ~ContactCollider();
  ContactCollider(const ContactCollider&) = delete;
  ContactCollider& operator=(const ContactCollider&) = delete;

  /// The application's surface callback (optional).
  void setSurfaceCallback(SurfaceCallback callback);

  /// One step's collision at simulation time `time` (s) for a step of `step` (s; the h the
  /// world is then stepped with, see FeederSet::beginStep; 0 gives rotating laws'
  /// instantaneous field): empties the joint group, calls feeders.beginStep(time, step),
  /// collides `space` (recursing into sub-spaces) and creates joints. Throws
  /// std::invalid_argument for a null space and (from beginStep) for a non-finite time or a bad
  /// step. Rethrows the first exception thrown inside the pass (by the SurfaceCallback or an
  /// allocation) after dSpaceCollide has returned, with the joint group and the feeders'
  /// records emptied (file comment). An error left pending by a manual dSpaceCollide pass is
  /// rethrown first, before anything is done.
  void collide(dSpaceID space, double time, double step = 0.0);
  /// Empties the contact joint group (collide does it). Does not clear a pending error.
  void clearJoints();
  /// Forgets what the collider learnt of a fixture mesh's edges (collideSpanning's edge table,
  /// narrow_phase.hpp): call it before destroying `data` (dGeomTriMeshDataDestroy), or after
  /// moving its vertices (dGeomTriMeshDataUpdate), while the collider lives on.
  void forgetMesh(dTriMeshDataID data) { mesh_buffer_.forget(data); }
  /// A dNearCallback; `data` must be a ContactCollider*. Never throws: an exception inside is
  /// kept (the first one) and the rest of the pass is skipped; see rethrowPendingError.
  static void nearCallback(void* data, dGeomID o1, dGeomID o2);
  /// Whether a near callback caught an exception that is not rethrown yet.
  bool hasPendingError() const { return static_cast<bool>(error_); }
  /// Rethrows (and clears) the first exception caught by nearCallback since the last call;
  /// does nothing if there is none. Applications that call dSpaceCollide with nearCallback
  /// themselves call it after dSpaceCollide returns (until then every pair is skipped).
  void rethrowPendingError();

  /// A contact joint created since the last clearJoints.
  struct Joint {
    dGeomID g1, g2;                      ///< the contact's geoms
    Vec3 normal;                         ///< unit contact normal (world, from g2 into g1)
    dJointID joint;                      ///< attached (body(g1), body(g2)) or the reverse
    dJointFeedback* feedback = nullptr;  ///< forces (N, world) after the step if Settings::feedback
                                         ///< or Settings::warm_start
    Vec3 position;                       ///< contact point (m, world)
    bool first_body_is_g1 = true;        ///< whether feedback->f1 acts on g1's body (else g2's)
    bool persisted = false;  ///< Settings::warm_start: matched to a contact of the previous pass
  };
  /// Contact joints created since the last clearJoints.
  int contactCount() const { return static_cast<int>(joints_.size()); }
  /// Of those, the speculative ones (Settings::speculative): contacts across a gap.
  int speculativeContactCount() const { return speculative_count_; }
  /// Resting contacts kept in this pass (Settings::speculative, file comment): points where a mesh
  /// part touched a fixture mesh in the previous pass, kept for this one, counted when kept (before
  /// the SurfaceCallback or the FeederSet, which may still drop them); the joints among them that
  /// lie across a gap are also counted as speculative contacts.
  int restingContactCount() const { return resting_count_; }
  /// Of those, the ones that started from a previous contact's force (Settings::warm_start).
  int warmStartedContactCount() const { return warm_started_count_; }

  /// A body whose centre of mass passed through a static geom (no body: a fixture) in the step
  /// just taken: it went in through a surface and out through another within the step.
  struct ThroughPass {
    dBodyID body = nullptr;
    dGeomID geom = nullptr;  ///< the static geom it passed through
    Vec3 from, to;           ///< its centre before and after the step (m, world)
    Vec3 normal;             ///< the entry surface's normal, out of the geom (world)
  };
  /// Settings::clamp_passes (file comment, "Passes stopped"): after dWorldStep or
  /// dWorldQuickStep, finds every body of the last collide()'s space whose centre passed
  /// through a static geom in the step (a ray from its centre before the step, recorded by
  /// collide(), to its centre now, in through one surface and out through another), puts it
  /// back where it was before the step (centre and orientation), removes its velocity into the
  /// entry surface (v -= min(0, v . n) n) and its spin, unless it was stopped by the previous
  /// call. Returns the passes it stopped (empty when off). Call it once per step, after the step
  /// and before anything moves the bodies again; it uses the records of the last collide() once
  /// (a second call finds none). Bodies must not be destroyed between collide() and this call.
  std::vector<ThroughPass> stopPassesThroughStaticGeoms();
  const std::vector<Joint>& joints() const { return joints_; }
  dJointGroupID jointGroup() const { return group_; }

  /// Stage timing (the simulation's StageTimes, rheofeed/simulation/simulation.hpp): every later
  /// pass adds to `*seconds` the wall-clock time (s) spent on the pairs dCollide found touching
  /// after dCollide returned - the SurfaceCallback, FeederSet::driveContacts and the creation
  /// and attachment of the joints. nullptr (the default) switches it off; no clock is read then.
  /// `seconds` must outlive the passes that use it.
  void setContactTimer(double* seconds) { contact_seconds_ = seconds; }

 private:
  void handlePair(dGeomID o1, dGeomID o2);
  // Surface callback, cone check, FeederSet and joints for contacts[0..n) of the pair (o1, o2);
  // `gap_speed` (m/s, one per contact) non-null marks speculative contacts (motionN = -gap/h).
  void addContacts(dGeomID o1, dGeomID o2, dContact* contacts, int n, const double* gap_speed);
  void collideWithin(dSpaceID space);
  // Speculative contacts: the swept box of each fast body's geom joins its space for the
  // regular pass (placeSweeps), which collects the geoms it meets; then the rays (castSweeps).
  void placeSweeps(dSpaceID space, double step);
  void castSweeps(double step);
  // Warm start: keeps the forces of the previous pass's joints (before clearJoints), and gives
  // the new contacts of a pair their nearest previous force.
  void keepWarmStarts();
  void applyWarmStarts(dGeomID o1, dGeomID o2, dContact* contacts, int n);
  // Resting contacts: for a mesh part against a fixture mesh, adds to contacts[0..n) the
  // previous pass's points of the pair still over the fixture's smooth surface, reduces the
  // union to max_contacts_per_pair spanning it, puts the ones across a gap last (their gaps
  // (m) in resting_gap_) and returns the count; `gaps` receives how many lie across a gap.
  // Remembers the pair's contacts for the next pass.
  int addRestingContacts(dGeomID o1, dGeomID o2, dContact* contacts, int n, int& gaps);

  dWorldID world_;
  FeederSet& feeders_;
  Settings settings_;
  dJointGroupID group_;
  SurfaceCallback surface_;
  std::vector<dContact> buffer_;
  MeshCollisionScratch mesh_buffer_;  // collideSpanning's memory for pairs with a mesh
  std::deque<dJointFeedback> feedback_;
  std::size_t feedback_used_ = 0;
  std::vector<Joint> joints_;
  std::exception_ptr error_;  // first exception caught in the near callback, not yet rethrown
  // Speculative pass: each fast geom's sweep (its swept box, a proxy geom of ours; the geoms
  // the box met and those the regular pass already gave it contacts with), looked up by proxy
  // and by geom; the proxies' pool and the ray (created on first use); the count of
  // speculative contacts.
  struct Sweep {
    dGeomID geom = nullptr, proxy = nullptr;
    double dir[3] = {0, 0, 0};  // unit direction of the motion (world)
    double travel = 0;          // m in the step
    std::vector<dGeomID> candidates;
    std::vector<dGeomID> touching;  // geoms the regular pass gave it contacts with
  };
  std::vector<Sweep> sweeps_;
  // Settings::clamp_passes: the dynamic bodies of the last collide()'s space and their centres
  // before the step; the space's static geoms.
  struct BodyBefore {
    dBodyID body;
    Vec3 centre;
    dQuaternion orientation;
    double min_travel;  // m: a centre moving less is not tested
  };
  std::vector<BodyBefore> bodies_before_;
  std::vector<dBodyID> stopped_last_;  // bodies stopped by the previous call (not again)
  std::vector<dGeomID> static_geoms_;
  dGeomID pass_ray_ = nullptr;  // no backface culling: a pass leaves through a back face
  void recordBodies(dSpaceID space);
  std::unordered_map<dGeomID, std::size_t> sweep_of_proxy_, sweep_of_geom_;
  std::vector<dGeomID> proxies_;
  dGeomID ray_ = nullptr;
  int speculative_count_ = 0;
  double* contact_seconds_ = nullptr;  // setContactTimer
  double step_ = 0;                    // s, the step of the current pass (collide)
  // Resting contacts: each point where a mesh part touched a fixture mesh in a pass, in the part
  // body's frame (m), with the fixture triangle under it; the previous pass's (grouped by pair:
  // sorted by the geoms' addresses, each pair's points in their order) and the current one's;
  // the working candidates and gaps; the count.
  struct RestingPoint {
    dGeomID part, fixture;
    Vec3 local;
    int triangle;
  };
  std::vector<RestingPoint> resting_, resting_next_;
  std::vector<dContactGeom> resting_candidates_;
  std::vector<double> resting_gap_;
  int resting_count_ = 0;
  // Warm start: the previous pass's contacts, sorted by geom pair (lo < hi by address), each
  // with the force (N, world) it applied to lo's body; the force each new contact starts from,
  // on its joint's first body (set into its feedback once the joint exists).
  struct WarmContact {
    dGeomID lo, hi;
    Vec3 position, normal, force;  // normal: unit, into lo
    bool persisted;                // it was itself matched: its force is no first impact
    bool used;
  };
  std::vector<WarmContact> warm_;
  // Per contact of the pair being added: matched (persisted), and the force it starts from
  // (on its g1's body) when it has one.
  struct WarmStart {
    bool persisted = false, has_force = false;
    Vec3 force;
  };
  std::vector<WarmStart> warm_starts_;
  int warm_started_count_ = 0;
};

/// ODE's surface mode bit for a warm start (dContactWarmStart of the patched contact.h), defined
/// here so that rheofeed compiles against stock headers.
constexpr int kContactWarmStart = 0x10000;

/// Whether the ODE library linked at run time has contact warm starts: dCheckConfiguration(
/// "ODE_EXT_contact_warm_start"), the token patches/0005 adds to dGetConfiguration().
bool odeHasContactWarmStart();

}  // namespace rheofeed
