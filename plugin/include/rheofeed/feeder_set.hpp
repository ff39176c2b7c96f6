// SPDX-License-Identifier: MIT
/// @file feeder_set.hpp
/// The C++ entry point of the ODE plugin: a set of feeder geoms, each with a motion law, that
/// turns the application's feeder contacts into ODE surface motion (`fdir1` / `motion1`).
///
/// ## Use (inside the application's own near callback)
///
///     rheofeed::FeederSet feeders;
///     feeders.add(belt_geom, rheofeed::MotionLaw::belt({1, 0, 0}, 0.3));
///     // each step of h seconds:
///     feeders.beginStep(time, h);                    // once, before dSpaceCollide
///     // in the near callback, after dCollide filled `contact[0..n)` and the surface params:
///     n = feeders.driveContacts(contact, n);         // feeder contacts get fdir1/motion1
///     for (int i = 0; i < n; ++i) dJointAttach(dJointCreateContact(w, g, &contact[i]),
///                                              dGeomGetBody(o1), dGeomGetBody(o2));
///     dWorldQuickStep(world, h);                     // the same h as given to beginStep
///
/// Pass the step h that the world is stepped with: rotating laws then give the secant of the
/// surface motion over the step (motion_law.hpp), and a part sticking to a turntable stays on
/// its circle. Without it (step = 0) they give the instantaneous w x r, and such a part spirals
/// outwards by sqrt(1 + (w h)^2) per step.
///
/// ## What a driven contact gets
/// With c_F the tangential surface velocity (motion_law.hpp) of a feeder geom F at the contact
/// (for a rotating law given the step: the secant that carries the other geom's body, whose
/// position is its centre of mass, rigidly with the surface), and c = 0 for a geom that is no
/// feeder, the contact between geoms g1 and g2 asks that the
/// material points in contact move together: (v_g1 + c_g1) - (v_g2 + c_g2) has no tangential
/// part, where v is the velocity of the geom's body at the contact point (0 for a static geom).
/// ODE's friction row 1 enforces (v_node0 - v_node1) . fdir1 = motion1, where node0 is the
/// body attached first. So the plugin sets, with c_rel = c_node1 - c_node0:
///   - `fdir1` = c_rel / |c_rel| (world frame, unit, orthogonal to the contact normal),
///   - `motion1` = |c_rel| (m/s, >= 0), `motion2` = 0,
///   - `mode |= dContactFDir1 | dContactMotion1` and, unless disabled, `dContactApprox1`
///     (mu then is a friction coefficient, not a force in newtons),
///   - the friction model of Options::friction: dContactFrictionCone set (cone, patched ODE)
///     or cleared (pyramid, ODE's own).
/// The normal row (depth, ERP/CFM, bounce, motionN) is never touched.
///
/// ## Attach order
/// `node0` is decided as ODE does it: the joint is assumed attached as
/// `dJointAttach(j, dGeomGetBody(g1), dGeomGetBody(g2))` (Options::attach_order = G1First, ODE's
/// convention and what ContactCollider does); if that first body is 0, ODE swaps the bodies, so
/// node0 is g2's body. An application that attaches (body(g2), body(g1)) sets
/// Options::attach_order = G2First. The result is then right in every layout: static feeder,
/// feeder on a kinematic or dynamic body, feeder as g1 or as g2, and feeder against feeder.
///
/// ## Bad input
/// Registration errors throw std::invalid_argument with a message naming the value and the
/// allowed range (speed limits: motion_law.hpp). Inside driveContacts (called from an ODE
/// callback) nothing throws: a bad contact is reported through the diagnostic handler, counted
/// in FeederStats, and either removed from the array (bad data ODE would abort on) or left
/// undriven (a law that gave a non-finite value or one beyond kMaxSurfaceSpeed, or a user
/// function - field, twist function, profile - that threw). A bad call (a null array with a
/// positive count, a negative count) drives nothing, returns 0 and is reported (InvalidCall).
#pragma once

#include <ode/ode.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "rheofeed/friction_model.hpp"
#include "rheofeed/motion_law.hpp"

namespace rheofeed {

/// Throws std::runtime_error unless the ODE library in use is double precision
/// (dCheckConfiguration("ODE_double_precision")). FeederSet's constructor calls it.
void requireDoublePrecisionOde();

/// Which body the application attaches first to its contact joints.
enum class AttachOrder {
  G1First,  ///< dJointAttach(j, body(g1), body(g2)): ODE's convention (the default).
  G2First,  ///< dJointAttach(j, body(g2), body(g1)), the normal negated (ODE's points into g1).
};

/// What a diagnostic is about.
enum class DiagnosticKind {
  InvalidContact,    ///< non-finite position/normal/depth, a normal that is not a unit vector
                     ///< (|n|^2 off 1 by more than 1e-4), or mu NaN or negative: contact removed
  ZeroFriction,      ///< mu = 0 on a feeder contact: ODE ignores motion1 then (contact kept)
  LawNotFinite,      ///< the law (profile, twist function or field) gave a non-finite value,
                     ///< or one beyond the limits of motion_law.hpp: contact left undriven
  ForceCapFriction,  ///< the contact opted out of dContactApprox1: mu is a force cap (N)
  LawThrew,          ///< a field, twist function or profile threw: contact left undriven
  InvalidCall,       ///< driveContacts called with a null array and count > 0, or count < 0
                     ///< (Diagnostic::feeder is null): nothing driven, 0 returned
};
/// Printable name of a DiagnosticKind ("invalid_contact", ...).
const char* toString(DiagnosticKind kind);

/// One report from the plugin; `message` names the value and the feeder geom.
struct Diagnostic {
  DiagnosticKind kind;
  dGeomID feeder;       ///< the feeder geom involved (null for InvalidCall)
  std::string message;  ///< e.g. "feeder geom 0x55..: contact mu = -0.2 is negative; ..."
};

/// Per-feeder counters. "last step": the collision pass since the latest beginStep call
/// (beginStep sets those two counters to 0; read them after the pass, before the next
/// beginStep); "all steps": since the feeder was added.
struct FeederStats {
  int contacts_driven = 0;             ///< feeder contacts given fdir1/motion1 (last step)
  int contacts_undriven = 0;           ///< feeder contacts left with c = 0 (tiny c_rel or bad law)
  std::uint64_t invalid_contacts = 0;  ///< contacts removed for bad data (all steps)
  std::uint64_t zero_friction = 0;     ///< contacts with mu = 0 (all steps)
  /// contacts left undriven by a law value that was not finite or beyond the limits (all steps)
  std::uint64_t law_not_finite = 0;
  std::uint64_t law_threw = 0;     ///< contacts left undriven by a throwing law (all steps)
  std::uint64_t bodies_woken = 0;  ///< disabled parts woken by a law change (all steps)
};

/// A driven contact as seen in the last collision pass (recorded on request).
struct ContactRecord {
  dGeomID feeder;  ///< the feeder geom (for a feeder-feeder contact: g1)
  dGeomID part;    ///< the other geom
  Vec3 position;   ///< contact point (m, world)
  Vec3 normal;     ///< unit contact normal (world; ODE's: points from g2 into g1)
  /// Imposed tangential velocity of the feeder surface relative to the part's own surface:
  /// c_feeder - c_part (m/s, world; c_part = 0 unless the part is a feeder too).
  Vec3 surface_velocity;
  dJointID joint = nullptr;            ///< set by ContactCollider (or the application)
  dJointFeedback* feedback = nullptr;  ///< forces after the step, if the joint has feedback
};

/// The set of feeders. The application owns it; it owns nothing of the application's (no
/// geom, body or world data slots, no globals). Not thread-safe: drive contacts from one thread.
class FeederSet {
 public:
  /// Behaviour switches; defaults are what a feeder simulation wants.
  struct Options {
    /// Set dContactApprox1 on feeder contacts (mu as a coefficient: friction <= mu * normal
    /// force per axis). With false the application's mode is kept; a contact without Approx1
    /// is reported once per feeder (mu then is a force cap in newtons).
    bool force_approx1 = true;
    /// How the application attaches contact joints (see the file comment).
    AttachOrder attach_order = AttachOrder::G1First;
    /// |c_rel| below this (m/s) counts as zero: no fdir1 or motion1 is set.
    double min_surface_speed = 1e-9;
    /// Record every driven contact (ContactRecord) for slip / force observation.
    bool record_contacts = false;
    /// Friction law of feeder contacts (friction_model.hpp): Pyramid clears, Cone sets
    /// dContactFrictionCone on every feeder contact. Cone needs the patched ODE (the
    /// constructor throws std::invalid_argument naming this setting on a stock library) and
    /// dWorldQuickStep. Changed later with setFrictionModel.
    FrictionModel friction = FrictionModel::Pyramid;
  };

  FeederSet();
  /// Throws std::invalid_argument naming the option for a bad min_surface_speed, or for
  /// friction = Cone when the linked ODE has no cone (odeHasFrictionCone()).
  explicit FeederSet(const Options& options);
  ~FeederSet();
  FeederSet(const FeederSet&) = delete;
  FeederSet& operator=(const FeederSet&) = delete;
  FeederSet(FeederSet&&) noexcept;
  FeederSet& operator=(FeederSet&&) noexcept;

  /// Register `geom` as a feeder with `law`. Throws std::invalid_argument if geom is null,
  /// already registered, the law is invalid (names the value), or the law uses Frame::Body and
  /// the geom has no body. The set knows feeders by the geom's address and ODE tells it nothing
  /// of a destroyed geom: remove(geom) before dGeomDestroy(geom), or a new geom that ODE puts at
  /// the freed address becomes that feeder.
  void add(dGeomID geom, MotionLaw law);
  /// Replace the law of a registered feeder (throws if unregistered or invalid). Parts that
  /// ODE auto-disabled and that touch this feeder are woken at the next collision pass.
  void setLaw(dGeomID geom, MotionLaw law);
  /// Unregister (throws if unregistered).
  void remove(dGeomID geom);
  /// The part's own efficiency under local vibration laws (MotionLaw::localVibration): the
  /// drift on every contact of `body` with such a feeder is multiplied by `factor`
  /// (dimensionless, in [0, 100]; 1 = the law's point-mass drift times its own efficiency).
  /// Measured per part family by a sampling run (issue 8). Throws std::invalid_argument naming
  /// the value if body is null or factor is out of range. Other laws ignore it.
  void setPartEfficiency(dBodyID body, double factor);
  /// Forget a body's factor (call when the body is destroyed; unknown bodies are ignored).
  void clearPartEfficiency(dBodyID body);
  /// Whether `geom` is a registered feeder.
  bool contains(dGeomID geom) const;
  /// The law of a registered feeder (throws if unregistered).
  const MotionLaw& law(dGeomID geom) const;
  /// Number of registered feeders.
  int size() const;

  /// Start a step at simulation time `time` (s) of length `step` (s, the h the world is then
  /// stepped with): call once per step before collision. Every law is frozen anew each step,
  /// lazily at this time on its first contact. With `step` > 0 a rotating law gives the secant
  /// surface velocity over the step, so a part sticking to a turntable stays on its circle;
  /// `step` = 0 gives the instantaneous w x r (and its outward drift). A change of step counts
  /// as a change of motion (parts asleep on a rotating feeder are woken). Throws
  /// std::invalid_argument naming the value if time is not finite or step is negative or not
  /// finite (nothing is changed then).
  void beginStep(double time, double step = 0.0);
  /// The time given to the latest beginStep (s).
  double time() const;

  /// Drive the feeder contacts among `contacts[0..count)` (each dContact's geom.g1/g2 tell its
  /// geoms). Contacts that touch no feeder are left exactly as they were. Returns the number of
  /// contacts to create joints for: contacts with invalid data on a feeder are removed and the
  /// rest moved forward in order. Never throws (user functions that throw leave their contact
  /// undriven: DiagnosticKind::LawThrew). A null `contacts` with count > 0, or count < 0, is a
  /// caller bug: nothing is read or driven, 0 is returned (no joint to create) and it is
  /// reported as DiagnosticKind::InvalidCall and counted (invalidCalls).
  int driveContacts(dContact* contacts, int count) noexcept;
  /// Number of driveContacts calls refused as InvalidCall since construction.
  std::uint64_t invalidCalls() const;

  /// Counters of one feeder (throws if unregistered).
  FeederStats stats(dGeomID geom) const;
  /// Driven contacts of the last collision pass (empty unless Options::record_contacts).
  const std::vector<ContactRecord>& records() const;
  /// Mutable access to the records, to attach joints and feedback (ContactCollider does).
  std::vector<ContactRecord>& records();
  /// Slip of a recorded contact, read after the step: the velocity of the part's material point
  /// minus that of the feeder's (its body motion plus surface_velocity), tangential part only
  /// (m/s, world). Zero while the part sticks to the moving surface.
  Vec3 slip(const ContactRecord& record) const;

  /// Receive diagnostics (the default prints the first of each kind per feeder to stderr).
  /// The handler must not throw.
  void setDiagnosticHandler(std::function<void(const Diagnostic&)> handler);

  const Options& options() const;
  /// Change Options::friction (from the next driveContacts on). Throws std::invalid_argument
  /// naming the setting for Cone when the linked ODE has no cone (nothing is changed then).
  void setFrictionModel(FrictionModel model);
  /// The friction model feeder contacts get (Options::friction or setFrictionModel).
  FrictionModel frictionModel() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rheofeed
