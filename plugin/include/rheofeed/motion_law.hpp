// SPDX-License-Identifier: MIT
/// @file motion_law.hpp
/// Motion laws of a feeder surface: what tangential velocity the surface imposes on a part at a
/// contact point. One piece of code serves the ODE plugin and the reference solver.
///
/// ## Sign convention (read this once)
/// A twist `v_a = [v; w]` about an origin `O` gives the surface velocity at a point `p`
///
///     v_p = v + w x (p - O)                                   (the ordinary rigid-body field)
///
/// Fusai & Tasora print eq. 4 as `v_p = v + r x w` with `r = p - O`, which is the opposite
/// rotation sense: `r x w = -(w x r)`. We use `w x (p - O)`, as Project Chrono's implementation of
/// the paper (ChFeeder) does, because only then does a turntable spinning with `w = +z` move parts
/// counter-clockwise seen from above, and a part climbs a helical ramp whose handedness agrees with
/// `w` (tests/plugin pin both down). To enter a twist written with the paper's form, negate `w`.
///
/// The normal part is discarded: the rheonomic term is `c_t = v_p - (v_p . n) n`, where n is the
/// unit contact normal. Penetration recovery, restitution and any normal motion stay as the
/// application set them.
///
/// ## Pass the step length: the secant of a rotation
/// A time stepper moves a sticking part by `h c` per step. With the instantaneous field
/// `c = w x (p - O)` that is a move along the tangent, off the circle: a part resting on a
/// turntable spirals outwards by a factor sqrt(1 + (w h)^2) per step (x1.35 in 60 s at
/// w = 1 rad/s, h = 0.01 s). Given the step h (s) (MotionLaw::evaluate, FeederSet::beginStep,
/// ContactCollider::collide, rfFeederSetBeginStepDt), a law with w != 0 instead gives the secant
/// of the motion over the step. The twist, frozen at the start of the step (world frame), is the
/// screw field `v_par + w x (p - O')`, with v_par = (v . w) w / |w|^2 the part of v along w and
/// O' = O + (w x v) / |w|^2 a point on the screw axis; its flow over h maps p to
/// `O' + R(w h) (p - O') + v_par h` (R(w h): rotation by |w| h about w), so the secant is
///
///     c = v_par + (R(w h) - I) (p - O') / h                  (-> v + w x (p - O) as h -> 0)
///
/// and a point carried at `c` lands exactly on the rotated (for a screw: helical) point. The
/// tangential part is taken as above. These point secants are not a rigid field (they contract
/// towards the axis at (1 - cos(|w| h)) / h times the distance to it), so the contacts of one part
/// would ask for incompatible motions; FeederSet and the reference world therefore give every
/// contact of a part with centre of mass x_c the rigid motion `c(x_c) + w x (p - x_c)`, which lands
/// x_c on its rotated point and turns the part at w (StepLaw::tangentialVelocity with `carried`).
/// Always pass the step your integrator takes; step = 0 keeps the instantaneous field (bitwise as
/// before issue 7), and its outward drift. Translations, belts and fields do not depend on the
/// step.
///
/// All vectors are in metres, m/s and rad/s; "world" means the ODE world frame, "body" means the
/// frame of the body that carries the feeder geom (the law then follows the body).
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "rheofeed/vec3.hpp"
#include "rheofeed/vibration_drift.hpp"

namespace rheofeed {

/// ## Limits (MotionLaw::validate, MotionLaw::evaluate, FeederSet::driveContacts)
/// ODE receives the relative surface velocity c_rel as `motion1 = |c_rel|` and `fdir1 =
/// c_rel / |c_rel|`. |c_rel| is a sum of squares, and a double overflows at 1.8e308 = (1.3e154)^2:
/// speeds near 1e154 m/s gave motion1 = inf and fdir1 = 0 with no word. ODE's step then divides
/// motion1 by h and multiplies it by masses and Jacobian entries, and squares body speeds (the
/// auto-disable test). The limits below keep every such square at most 1e200, leaving a factor
/// 1e108 for those products; they are far beyond any feeder (the speed of light is 3e8 m/s), so
/// they only refuse numbers that cannot be simulated. A law is checked against them where it
/// is made (validate: constant speeds times the largest constant or ramp profile value), when
/// it is frozen for a step (twist functions and function profiles), and at every contact (a
/// field's value, and w x (p - O) over a long lever arm): a contact whose c_t is not finite or
/// is beyond kMaxSurfaceSpeed is left undriven, reported and counted (FeederStats).

/// Largest surface speed |v|, |belt speed| and |c_t| at a contact (unit: m/s).
constexpr double kMaxSurfaceSpeed = 1e100;
/// Largest angular speed |w| of a twist (unit: rad/s).
constexpr double kMaxAngularSpeed = 1e100;
/// Largest |coordinate| of a twist's origin (unit: m); with |w| <= kMaxAngularSpeed the product
/// w x (p - O) stays finite (<= ~1e200) and is then checked against kMaxSurfaceSpeed.
constexpr double kMaxOriginCoordinate = 1e100;

/// The frame a law's vectors are given in.
enum class Frame {
  World,  ///< World frame; the law does not move.
  Body,   ///< Frame of the feeder geom's body (x_world = R x_body + body position); the law
          ///< moves and turns with the body. A geom without a body cannot use it.
};

/// The motion "eigenvalues" of a feeder: linear velocity `linear` (m/s), angular velocity
/// `angular` (rad/s), about the point `origin` (m). Frame: that of the owning law.
struct Twist {
  Vec3 linear;   ///< v (unit: m/s)
  Vec3 angular;  ///< w (unit: rad/s); the surface turns by the right-hand rule about w.
  Vec3 origin;   ///< O (unit: m), the point whose surface velocity is `linear`.
};

/// A direct tangential field, for when the speed map is known: given the contact point `p`
/// (m, world), the unit contact normal `n` (world) and the simulation time `t` (s), return the
/// surface velocity (m/s, world). Any normal component of the result is discarded. It must be
/// safe to call from the near callback. It should not throw; if it does (or returns a value that
/// is not finite or beyond kMaxSurfaceSpeed), FeederSet::driveContacts leaves the contact
/// undriven, reports and counts it; the exception never reaches ODE.
using SurfaceField = std::function<Vec3(const Vec3& p, const Vec3& n, double t)>;

/// A dimensionless scale `s(t)` applied to every velocity of a law (time `t` in seconds).
/// The default is the constant 1.
class TimeProfile {
 public:
  /// s(t) = 1.
  TimeProfile() = default;
  /// s(t) = scale.
  static TimeProfile constant(double scale);
  /// s(t) = from for t <= t_start, to for t >= t_end, linear in between (s); t_end > t_start.
  static TimeProfile ramp(double t_start, double t_end, double from, double to);
  /// s(t) = 1 for t_on <= t < t_off, 0 otherwise (s); t_off may be +infinity.
  static TimeProfile onOff(double t_on, double t_off = std::numeric_limits<double>::infinity());
  /// s(t) = scale(t), a user function; it is evaluated once per step per feeder.
  static TimeProfile function(std::function<double(double t)> scale);
  /// s(t) = a(t) b(t): a ramp that starts a feeder times an on/off window that stops it, say.
  static TimeProfile product(TimeProfile a, TimeProfile b);

  /// The scale at time t (s). A user function may return a non-finite value; callers check.
  double operator()(double t) const;
  /// True when s(t) cannot change with t (only the constant profile; a product of constants is
  /// one).
  bool isConstant() const { return kind_ == Kind::Constant; }
  /// Throws std::invalid_argument naming the bad parameter (prefix names where it came from).
  void validate(const std::string& where) const;
  /// The largest |s(t)| known without calling a user function: |scale|, max(|from|, |to|) of a
  /// ramp, 1 for on/off and for a function profile (checked at every step instead), the
  /// product of its factors' for a product.
  double largestConstantValue() const;

 private:
  enum class Kind { Constant, Ramp, OnOff, Function, Product };
  Kind kind_ = Kind::Constant;
  double a_ = 1.0, b_ = 0.0, c_ = 0.0, d_ = 0.0;
  std::function<double(double)> function_;
  std::vector<TimeProfile> factors_;  // Product: s(t) is their product (none a product)
};

class StepLaw;

/// How a feeder surface moves. A value type: build it with one of the named constructors, then
/// optionally `withProfile`. The plugin freezes it once per step (`evaluate`) and then computes
/// only what the law needs per contact: a pure translation does no cross product, a field skips
/// the twist, a belt only projects its direction.
class MotionLaw {
 public:
  /// What the law is made of.
  enum class Kind {
    Twist,          ///< constant twist v + w x (p - O)
    TwistFunction,  ///< twist given as a user function of time
    Belt,   ///< a belt: speed s along a direction, kept at |s| on any face it is not normal to
    Field,  ///< a user field c(p, n, t)
    /// A vibrating feeder's local drift (vibration_drift.hpp): at each contact the point-mass
    /// drift of the feeder's real vibration at that point, for that contact normal and mu.
    LocalVibration,
  };

  /// The default law: a stationary surface (zero twist, world frame).
  MotionLaw() = default;

  /// Rigid twist about `twist.origin`, in `frame`.
  static MotionLaw twist(const Twist& twist, Frame frame = Frame::World);
  /// Pure translation: v_p = velocity (m/s) everywhere.
  static MotionLaw translation(const Vec3& velocity, Frame frame = Frame::World);
  /// Pure rotation with angular velocity `angular_velocity` (rad/s) about `origin` (m).
  static MotionLaw rotation(const Vec3& angular_velocity, const Vec3& origin,
                            Frame frame = Frame::World);
  /// A belt moving at `speed` (m/s; negative reverses it) along `direction` (any length > 0).
  /// At a contact, c_t = speed * unit(direction projected on the contact plane), so a belt laid
  /// on an incline still runs at |speed| along its surface; where the direction is (nearly)
  /// normal to the contact plane (the belt's end faces) c_t = 0.
  static MotionLaw belt(const Vec3& direction, double speed, Frame frame = Frame::World);
  /// A direct tangential field in the world frame. `time_varying` says that the field itself
  /// depends on t (besides any profile), so sleeping parts are woken every step it is in use.
  static MotionLaw field(SurfaceField field, bool time_varying = false);
  /// A twist that varies with time: `twist_of_time(t)` (t in s) is called once per step.
  static MotionLaw twistFunction(std::function<Twist(double t)> twist_of_time,
                                 Frame frame = Frame::World);

  /// The local vibration law of a stationary vibrating feeder (world frame; issue 8): at a
  /// contact at p with the feeder's outward unit normal n and friction mu, c_t is the
  /// cycle-averaged drift of a point mass on the plane (p, n) vibrating with the feeder's real
  /// local vibration, times vibration.efficiency (vibration_drift.hpp). Drifts are tabulated
  /// lazily (LocalDriftTable, shared by the copies of this law). FeederSet passes the contact's
  /// own mu and the normal turned out of the feeder; the two-argument
  /// StepLaw::tangentialVelocity takes n as that outward normal and uses vibration.mu.
  static MotionLaw localVibration(const LocalVibration& vibration,
                                  const PointMassSettings& settings = {});
  /// The same law on a given drift table (e.g. LocalDriftTable::shared(), or one filled from a
  /// saved table), shared with its other users. Throws std::invalid_argument when `table` is
  /// null.
  static MotionLaw localVibration(const LocalVibration& vibration,
                                  std::shared_ptr<LocalDriftTable> table);

  /// A copy of this law whose velocities are multiplied by `profile(t)`, on top of any profile
  /// the law has already (law.withProfile(a).withProfile(b) scales by a(t) b(t)).
  MotionLaw withProfile(TimeProfile profile) const;

  Kind kind() const { return kind_; }
  Frame frame() const { return frame_; }
  /// The constant twist (Twist kind); for the Belt kind, `linear` is the unit belt direction
  /// and beltSpeed() its speed.
  const Twist& constantTwist() const { return twist_; }
  /// Belt speed (m/s; Belt kind, else 0).
  double beltSpeed() const { return kind_ == Kind::Belt ? belt_speed_ : 0.0; }
  const TimeProfile& profile() const { return profile_; }
  /// The vibration of a LocalVibration law (nullptr for other kinds).
  const LocalVibration* localVibration() const { return local_.get(); }
  /// Contact counts and table size of a LocalVibration law (zeros for other kinds); the table's
  /// counts, summed over every law that shares it.
  LocalDriftStats localStats() const;
  /// The drift table of a LocalVibration law (nullptr for other kinds).
  const std::shared_ptr<LocalDriftTable>& localTable() const { return table_; }
  /// True if the law's values can change with time (a profile, a twist function, a time-varying
  /// field). Constant laws are evaluated once and cached.
  bool isTimeVarying() const;

  /// Throws std::invalid_argument with a message naming the bad value, `where` it came from and
  /// the allowed range, e.g. "feeder 0x55d0: twist.linear.x = nan is not finite" or
  /// "...: |twist.angular| = 1e+200 rad/s is beyond the limit: must be in [0, 1e+100] rad/s".
  /// Every value must be finite and within the limits above (kMaxSurfaceSpeed, ...), also when
  /// multiplied by the largest value of a constant or ramp profile. Twist functions, function
  /// profiles and fields cannot be checked here: they are checked at every step and contact.
  void validate(const std::string& where) const;

  /// Freeze the law at time `t` (s) for a step of `step` seconds (finite, >= 0; any other value
  /// gives a law that is not finite(), whose problem() names it). Never throws for a user
  /// function: a profile or twist function that throws, or returns a value that is not finite
  /// or beyond the limits, gives a law that is not finite() (threw() tells the first case).
  /// `body_pose` is the pose of the body carrying the feeder at time t (needed for Frame::Body,
  /// ignored otherwise; nullptr means the world frame). The twist (profile applied; Frame::Body and
  /// twist functions first turned into a world twist at t) is then held constant over the step.
  /// With `step` > 0 a law with w != 0 gives the secant surface velocity over the step (file
  /// comment); `step` = 0 gives the instantaneous field v + w x (p - O).
  StepLaw evaluate(double t, const Pose* body_pose, double step = 0.0) const;

 private:
  Kind kind_ = Kind::Twist;
  Frame frame_ = Frame::World;
  Twist twist_{};
  double belt_speed_ = 0.0;
  SurfaceField field_;
  bool field_time_varying_ = false;
  std::function<Twist(double)> twist_function_;
  std::shared_ptr<const LocalVibration> local_;
  std::shared_ptr<LocalDriftTable> table_;
  TimeProfile profile_;
};

/// A law frozen at one time step in the world frame: what the per-contact evaluation reads.
/// Not thread-safe (a local vibration law keeps its last contact's result): use one StepLaw
/// per thread.
class StepLaw {
 public:
  /// Tangential surface velocity c_t (m/s, world) at contact point `p` (m, world) with unit
  /// normal `n`: the instantaneous field, or for a rotating law frozen with a step h > 0 the
  /// secant over the step (file comment). Not finite, or beyond kMaxSurfaceSpeed, when a field
  /// returned such a value or a long lever arm w x (p - O) exceeds the limit: the caller checks
  /// and leaves the contact undriven. An exception thrown by a field propagates (FeederSet
  /// catches it).
  Vec3 tangentialVelocity(const Vec3& p, const Vec3& n) const;
  /// The same for a contact of a rigid part whose centre of mass is at `carried` (m, world, at
  /// the start of the step): for a secant law, the velocity at `p` of the rigid motion that
  /// carries the centre of mass along its secant and turns the part at w,
  /// c = secant(carried) + w x (p - carried). A part sticking to a turntable then has its
  /// centre of mass land exactly on the rotated point, and every one of its contacts asks for
  /// the same rigid motion (the secants of the contact points themselves differ from a rigid
  /// field by -(1 - cos(w h)) / h times their in-plane spread, which no rigid part can follow).
  /// Equal to the two-argument form for every other law, and for carried = p.
  Vec3 tangentialVelocity(const Vec3& p, const Vec3& n, const Vec3& carried) const;
  /// True if `carried` changes tangentialVelocity (a secant law): callers may skip looking up
  /// the carried body otherwise.
  bool usesCarriedPoint() const { return eval_ == Eval::Secant; }
  /// True for a local vibration law: its value depends on which side of the contact the
  /// feeder is and on the contact's mu (contactVelocity).
  bool needsContactSide() const { return eval_ == Eval::Local; }
  /// Local vibration law: the drift c_t (m/s, world) at `p` (m, world) where `n_out` is the unit
  /// normal pointing out of the feeder into the part and `mu` the contact's friction
  /// coefficient; `efficiency` multiplies it (a part family's own factor, 1 = the law's own).
  /// With `carried` (the part's centre of mass, m, world) the law is evaluated at the centre's
  /// projection on the contact plane, q = x_c - ((x_c - p) . n_out) n_out, instead of at p: every
  /// contact of a part on one face then asks for the same motion (a rigid part cannot follow
  /// different drifts at its corners; on a bowl ramp the per-corner drifts cost the part 4-8 %
  /// of its speed, tests/validation/local_drift_test.cpp). Any other law:
  /// tangentialVelocity(p, n_out).
  Vec3 contactVelocity(const Vec3& p, const Vec3& n_out, double mu, double efficiency = 1,
                       const Vec3* carried = nullptr) const;

  /// Whether the frozen values are all finite and within the limits (kMaxSurfaceSpeed, ...; a
  /// profile or twist function can fail, or throw).
  bool finite() const { return finite_; }
  /// True if the law is not finite() because a profile or twist function threw.
  bool threw() const { return threw_; }
  /// Short description of the first bad value (or of the exception), empty if finite.
  const std::string& problem() const { return problem_; }
  /// True if every contact would get c_t = 0 (zero scale or zero twist).
  bool isZero() const { return eval_ == Eval::Zero; }
  /// Whether two frozen laws impose the same surface velocities (for waking sleeping parts).
  bool sameMotionAs(const StepLaw& other) const;

 private:
  friend class MotionLaw;
  enum class Eval { Zero, Translation, Twist, Secant, Belt, Field, Local };
  // Turns a Twist (w != 0) into its secant over a step of h > 0 seconds: c = M (p - O) + d.
  void freezeSecant(double h);
  // The (untruncated) secant velocity at p: M (p - O) + d.
  Vec3 secant(const Vec3& p) const;

  Eval eval_ = Eval::Zero;
  Vec3 v_, w_, o_;     // world frame; Belt: v_ = unit direction, w_.x = speed
  double m_[9] = {};   // Secant: (R(w h) - I) / h (1/s, row-major, world)
  Vec3 d_;             // Secant: c at p = O (m/s, world)
  double step_ = 0.0;  // h (s) of a Secant, else 0
  const SurfaceField* field_ = nullptr;
  const LocalVibration* local_ = nullptr;  // Local: the law's vibration and table
  LocalDriftTable* table_ = nullptr;
  // Local, translation only: the value does not depend on p, so the last contact's inputs and
  // result are kept (a flat translating feeder computes its drift once per step).
  mutable bool memo_valid_ = false;
  mutable Vec3 memo_n_, memo_value_;
  mutable double memo_mu_ = 0;
  mutable bool memo_wall_ = false;
  double scale_ = 1.0;
  double time_ = 0.0;
  bool time_varying_field_ = false;
  bool finite_ = true;
  bool threw_ = false;
  std::string problem_;
};

/// Angular velocity (rad/s, world frame) that turns `p0`'s rotation into `p1`'s in `h` seconds
/// (h > 0): the axis-angle of `R1 R0^T` divided by h, the secant of a prescribed rotation, as a
/// kinematic body's velocity over a step (ODE's kinematic bodies and the reference world). The
/// positions of the poses are not used. An angle is taken in [0, pi]; zero rotation gives zero.
Vec3 secantAngularVelocity(const Pose& p0, const Pose& p1, double h);

/// The surface velocity c_t (m/s, world) of the frozen `law` of one feeder at a contact: the one
/// dispatch over the kinds of law that FeederSet and the reference world share.
///   p        contact point (m, world)
///   n        unit contact normal handed to laws that need no side (tangentialVelocity: the
///            tangential projection, and a SurfaceField receives it as given)
///   n_out    unit normal pointing out of this feeder into the other geom (a local vibration
///            law's side: StepLaw::contactVelocity)
///   mu       the contact's friction coefficient (local vibration laws)
///   efficiency  the other body's own efficiency factor (local vibration laws; 1 = the law's)
///   carried  centre of mass (m, world) of the body on the other side of the contact, null for
///            a static geom: a secant law carries it rigidly, a local law is evaluated at its
///            projection on the contact plane (StepLaw::contactVelocity).
/// Propagates what a user function (field, twist function) throws; the caller checks the value
/// against the limits (StepLaw::tangentialVelocity).
Vec3 contactSurfaceVelocity(const StepLaw& law, const Vec3& p, const Vec3& n, const Vec3& n_out,
                            double mu, double efficiency, const Vec3* carried);

}  // namespace rheofeed
