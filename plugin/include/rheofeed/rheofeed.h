/* SPDX-License-Identifier: MIT */
/**
 * @file rheofeed.h
 * C API of the rheofeed ODE plugin, in ODE's Object-Verb style with the prefix `rf`.
 * It wraps rheofeed::FeederSet (feeder_set.hpp), which documents the physics and sign rules:
 * each feeder contact gets fdir1 = unit(c_rel) and motion1 = |c_rel| (m/s) so that the part moves
 * with the feeder surface, whatever the geom order or body layout, assuming the application
 * attaches joints as dJointAttach(j, dGeomGetBody(g1), dGeomGetBody(g2)) (ODE's convention).
 *
 *     rfFeederSetID feeders = rfFeederSetCreate();
 *     double dir[3] = {1, 0, 0};
 *     rfFeederSetAddBelt(feeders, belt_geom, dir, 0.3, rfFrameWorld);
 *     // each step of h seconds: rfFeederSetBeginStepDt(feeders, t, h); then in the near
 *     // callback:
 *     n = rfFeederSetDriveContacts(feeders, contact, n);
 *     // and step the world with the same h: dWorldQuickStep(world, h);
 *
 * Units: metres, seconds, m/s, rad/s. Vectors are double[3] in the world frame unless the law's
 * frame is rfFrameBody (then in the frame of the feeder geom's body).
 *
 * Errors: functions returning int give rfOK (0) or a negative rfError code; the message, which
 * names the bad value, is then read with rfFeederSetGetLastError. Nothing here throws or aborts.
 */
#ifndef RHEOFEED_RHEOFEED_H_
#define RHEOFEED_RHEOFEED_H_

#include <ode/ode.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Opaque handle of a feeder set. */
typedef struct rfFeederSet* rfFeederSetID;

/** Result codes. */
enum {
  rfOK = 0,
  rfErrorInvalidArgument = -1, /**< a value was refused; see rfFeederSetGetLastError */
  rfErrorOutOfMemory = -2,
  rfErrorInternal = -3
};

/** Frame of a law's vectors. */
enum { rfFrameWorld = 0, rfFrameBody = 1 };

/** Which body the application attaches first (rfFeederSetCreateWithOptions). */
enum { rfAttachG1First = 0, rfAttachG2First = 1 };

/** A direct tangential field: write into `out` the surface velocity (m/s, world) at point `p`
 *  (m, world) with unit normal `n` at time `t` (s); the normal part is discarded. */
typedef void rfFieldFunction(void* user, const double p[3], const double n[3], double t,
                             double out[3]);

/** A diagnostic: `kind` is one of "invalid_contact", "zero_friction", "law_not_finite" (not
 *  finite or beyond the speed limits of motion_law.hpp), "force_cap_friction", "law_threw" (a
 *  C++ user function threw), "invalid_call" (rfFeederSetDriveContacts with a null array and
 *  count > 0, or count < 0; `feeder` is 0 then); `message` names the value. Valid during the
 *  call only. */
typedef void rfDiagnosticFunction(void* user, const char* kind, dGeomID feeder,
                                  const char* message);

/** Create a feeder set with default options (dContactApprox1 forced, attach order g1 first).
 *  Returns 0 if ODE is not double precision or memory ran out. */
rfFeederSetID rfFeederSetCreate(void);
/** Create with options: force_approx1 (0/1), attach_order (rfAttach*), min_surface_speed (m/s,
 *  >= 0). Returns 0 on a bad option or failure. */
rfFeederSetID rfFeederSetCreateWithOptions(int force_approx1, int attach_order,
                                           double min_surface_speed);
void rfFeederSetDestroy(rfFeederSetID set);

/** Register `geom` with twist v = linear (m/s), w = angular (rad/s) about origin (m):
 *  surface velocity v + w x (p - origin). The set knows feeders by the geom's address:
 *  rfFeederSetRemove(set, geom) before dGeomDestroy(geom), or a new geom at the freed address
 *  becomes that feeder (every rfFeederSetAdd* function). */
int rfFeederSetAddTwist(rfFeederSetID set, dGeomID geom, const double linear[3],
                        const double angular[3], const double origin[3], int frame);
/** Register `geom` as a belt: `speed` (m/s, negative reverses) along `direction`. */
int rfFeederSetAddBelt(rfFeederSetID set, dGeomID geom, const double direction[3], double speed,
                       int frame);
/** Register `geom` with a direct field (world frame); time_varying != 0 if it depends on t. */
int rfFeederSetAddField(rfFeederSetID set, dGeomID geom, rfFieldFunction* field, void* user,
                        int time_varying);

/** Register `geom` (a stationary feeder, world frame) with the local vibration law
 *  (vibration_drift.hpp, MotionLaw::localVibration): at each contact the cycle-averaged drift
 *  of a point mass on the contact plane vibrating with the feeder's real local vibration, for
 *  the contact's own mu and the normal pointing out of the feeder. The feeder's vibration, as
 *  in a full-vibration run: its displacement at a point p (m, world) is
 *      x(t) = (amplitude + torsion_amplitude axis_direction x (p - axis_origin))
 *             sin(2 pi frequency t)
 *  (first order in the torsion; the phase does not change a steady drift).
 *    frequency          f (Hz, in (0, 1e5])
 *    amplitude          peak translation displacement vector (m, world; |amplitude| <= 1e3)
 *    torsion_amplitude  peak rotation about the axis (rad, in [0, pi], right-hand rule)
 *    axis_origin        a point of the torsion axis (m, world; may be null with no torsion)
 *    axis_direction     unit torsion axis (world; may be null with no torsion: +z)
 *    gravity            g (m/s^2, world, finite and non-zero, e.g. {0, 0, -9.81})
 *    efficiency         factor on every drift of this feeder (dimensionless, in [0, 100]; 1 =
 *                       a point mass); per part use rfFeederSetSetPartEfficiency.
 *  Drifts are tabulated lazily: the first contacts of a new surface orientation cost
 *  milliseconds, later ones well under a microsecond. rfErrorInvalidArgument names the bad
 *  value (nothing is registered). */
int rfFeederSetAddLocalVibration(rfFeederSetID set, dGeomID geom, double frequency,
                                 const double amplitude[3], double torsion_amplitude,
                                 const double axis_origin[3], const double axis_direction[3],
                                 const double gravity[3], double efficiency);
/** Replace the law of a registered feeder with a local vibration law (parameters as
 *  rfFeederSetAddLocalVibration). */
int rfFeederSetSetLocalVibration(rfFeederSetID set, dGeomID geom, double frequency,
                                 const double amplitude[3], double torsion_amplitude,
                                 const double axis_origin[3], const double axis_direction[3],
                                 const double gravity[3], double efficiency);
/** The part's own efficiency under local vibration laws (FeederSet::setPartEfficiency): every
 *  contact of `body` with a local-vibration feeder gets the drift times `factor`
 *  (dimensionless, in [0, 100]; 1 = the law's own drift), e.g. as measured per part family by
 *  a sampling run (issue 8). Other laws ignore it. rfErrorInvalidArgument for a null body or a
 *  factor out of range (the message names it). Call with factor 1 to forget a body before
 *  destroying it. */
int rfFeederSetSetPartEfficiency(rfFeederSetID set, dBodyID body, double factor);

/** Replace the law of a registered feeder (same parameters as the Add functions). Sleeping
 *  parts on it are woken at the next collision pass. */
int rfFeederSetSetTwist(rfFeederSetID set, dGeomID geom, const double linear[3],
                        const double angular[3], const double origin[3], int frame);
int rfFeederSetSetBelt(rfFeederSetID set, dGeomID geom, const double direction[3], double speed,
                       int frame);

/** Scale the feeder's law by a linear ramp from `from` at t_start to `to` at t_end (s). A
 *  feeder has at most one ramp and one on/off window (rfFeederSetSetOnOff): a second ramp
 *  replaces the first, and the ramp and the window multiply (a ramp that switches off). Setting
 *  the law again (rfFeederSetSetTwist, rfFeederSetSetBelt, ...) drops both. */
int rfFeederSetSetRamp(rfFeederSetID set, dGeomID geom, double t_start, double t_end, double from,
                       double to);
/** Switch the feeder's law on for t_on <= t < t_off (s), off otherwise; replaces the
 *  feeder's previous window and multiplies its ramp (rfFeederSetSetRamp). */
int rfFeederSetSetOnOff(rfFeederSetID set, dGeomID geom, double t_on, double t_off);

/** Unregister a feeder. */
int rfFeederSetRemove(rfFeederSetID set, dGeomID geom);
/** 1 if `geom` is a registered feeder, else 0. */
int rfFeederSetContains(rfFeederSetID set, dGeomID geom);

/** Start a step at simulation time `time` (s) of length `step` (s, finite and >= 0: the h the
 *  world is then stepped with), once per step before collision. Rotating laws then give the
 *  secant of the surface motion over the step, so a part sticking to a turntable stays on its
 *  circle (motion_law.hpp). rfErrorInvalidArgument for a non-finite time or a negative or
 *  non-finite step (the message names the value; nothing is changed). */
int rfFeederSetBeginStepDt(rfFeederSetID set, double time, double step);
/** rfFeederSetBeginStepDt with step = 0: rotating laws give the instantaneous w x r, and a part
 *  sticking to a turntable spirals outwards by sqrt(1 + (w h)^2) per step of h seconds. Kept for
 *  existing callers; prefer rfFeederSetBeginStepDt. */
int rfFeederSetBeginStep(rfFeederSetID set, double time);
/** Drive the feeder contacts of `contacts[0..count)`; returns how many contacts to create
 *  joints for (invalid feeder contacts are removed, the rest kept in order), or a negative
 *  rfError code: rfErrorInvalidArgument for a null set, a negative count, or a null `contacts`
 *  with count > 0 (a caller bug: nothing is driven; the message is in rfFeederSetGetLastError
 *  and the diagnostic function gets "invalid_call"). A loop `for (i = 0; i < n; ++i)` over
 *  the result then creates no joint. Safe to call from a near callback.
 *  Speeds: every law value at a contact must be finite and at most 1e100 m/s (kMaxSurfaceSpeed
 *  of motion_law.hpp; twists: |w| <= 1e100 rad/s, origin coordinates within +-1e100 m), or the
 *  contact is left undriven and reported as "law_not_finite"; the Add and Set functions refuse
 *  such constant laws with rfErrorInvalidArgument. */
int rfFeederSetDriveContacts(rfFeederSetID set, dContact* contacts, int count);

/** Feeder contacts given fdir1/motion1 since the last rfFeederSetBeginStep, or a negative
 *  rfError code for an unregistered geom. */
int rfFeederSetGetContactsDriven(rfFeederSetID set, dGeomID geom);

/** One feeder's counters (rfFeederSetGetStats). "This pass": since the last
 *  rfFeederSetBeginStep; "in all": since the feeder was added. Counts of contacts. */
typedef struct rfFeederStats {
  /** Set by the caller to sizeof(rfFeederStats) before the call: a later library that adds
   *  counters at the end writes only what this size holds, so a program built against this
   *  header keeps working. */
  unsigned int size;
  int contacts_driven;                 /**< given fdir1/motion1 (this pass) */
  int contacts_undriven;               /**< left with no surface velocity (this pass) */
  unsigned long long invalid_contacts; /**< removed for bad data (in all) */
  unsigned long long zero_friction;    /**< with mu = 0: ODE ignores motion1 (in all) */
  unsigned long long law_not_finite;   /**< left undriven: law value not finite or too large */
  unsigned long long law_threw;        /**< left undriven: a C++ law threw (in all) */
  unsigned long long bodies_woken;     /**< disabled parts woken by a law change (in all) */
} rfFeederStats;

/** Writes `geom`'s counters into `out`: what the diagnostic function reports one by one, as
 *  totals. Returns rfOK, or a negative rfError code for an unregistered geom, a null `out` or
 *  an `out->size` smaller than this header's rfFeederStats (the message names it). */
int rfFeederSetGetStats(rfFeederSetID set, dGeomID geom, rfFeederStats* out);

/** Friction models (rfFeederSetSetFrictionModel). */
enum { rfFrictionPyramid = 0, rfFrictionCone = 1 };
/** The friction law of this set's feeder contacts: rfFrictionPyramid (stock ODE's per-axis
 *  limit mu N, the default) or rfFrictionCone (the two friction impulses limited together to
 *  mu N: rheofeed's patched ODE only, and dWorldQuickStep only). rfErrorInvalidArgument (the
 *  message names the setting and the library's configuration) for an unknown model or for
 *  rfFrictionCone when the linked ODE has no cone; nothing is changed then. */
int rfFeederSetSetFrictionModel(rfFeederSetID set, int model);
/** 1 if the linked ODE has rheofeed's friction cone (dCheckConfiguration(
 *  "ODE_EXT_friction_cone")), else 0. */
int rfOdeHasFrictionCone(void);

/** Receive diagnostics (0 restores the default: first report per kind and feeder on stderr). */
void rfFeederSetSetDiagnosticFunction(rfFeederSetID set, rfDiagnosticFunction* fn, void* user);

/** The message of the latest failed call on `set` ("" if none); valid until the next call. */
const char* rfFeederSetGetLastError(rfFeederSetID set);

#ifdef __cplusplus
}
#endif

#endif /* RHEOFEED_RHEOFEED_H_ */
