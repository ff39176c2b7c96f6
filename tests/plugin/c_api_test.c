/* SPDX-License-Identifier: MIT */
/*
 * The C API (rheofeed.h) used from a C translation unit: create a feeder set, register a belt,
 * drive the contacts dCollide makes, step ODE with them, and check the error codes and
 * messages of bad calls; a local vibration law on a plane against the classical model. Returns
 * nonzero if any check fails; every failure is printed.
 */
#include <math.h>
#include <ode/ode.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "rheofeed/rheofeed.h"

static int failures = 0;

#define CHECK(condition)                                                            \
  do {                                                                              \
    if (!(condition)) {                                                             \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #condition); \
      ++failures;                                                                   \
    }                                                                               \
  } while (0)

#define CHECK_NEAR(a, b, tolerance)                                                            \
  do {                                                                                         \
    double a_ = (a), b_ = (b);                                                                 \
    if (!(fabs(a_ - b_) <= (tolerance))) {                                                     \
      fprintf(stderr, "%s:%d: check failed: %s = %.17g, expected %.17g within %g\n", __FILE__, \
              __LINE__, #a, a_, b_, (double)(tolerance));                                      \
      ++failures;                                                                              \
    }                                                                                          \
  } while (0)

/* The message contains `part`. */
#define CHECK_MENTIONS(message, part)                                                        \
  do {                                                                                       \
    const char* m_ = (message);                                                              \
    if (!m_ || !strstr(m_, (part))) {                                                        \
      fprintf(stderr, "%s:%d: message \"%s\" does not mention \"%s\"\n", __FILE__, __LINE__, \
              m_ ? m_ : "(null)", (part));                                                   \
      ++failures;                                                                            \
    }                                                                                        \
  } while (0)

/* ODE's own messages are failures here too (as ode_message_guard.hpp makes them in the C++
 * tests): counted and printed; for errors and debug messages ODE ends the process after this
 * returns (exit(1) or abort()), so the message is printed first. */
static void odeMessage(int number, const char* format, va_list args) {
  fprintf(stderr, "c_api_test: ODE message %d: ", number);
  vfprintf(stderr, format, args);
  fprintf(stderr, "\n");
  fflush(stderr);
  ++failures;
}

/* fdir1 is c / |c| in double precision: unit and orthogonal to the normal up to round-off. */
#define ROUND_OFF 1e-14

static const double kSpeed = 0.3; /* m/s */

/* A field equal to a belt along +y at 0.2 m/s; counts its calls. */
static void yField(void* user, const double p[3], const double n[3], double t, double out[3]) {
  (void)p;
  (void)n;
  (void)t;
  ++*(int*)user;
  out[0] = 0.0;
  out[1] = 0.2;
  out[2] = 0.0;
}

struct Seen {
  int count;
  char kind[64];
  char message[512];
};

static void remember(void* user, const char* kind, dGeomID feeder, const char* message) {
  struct Seen* seen = (struct Seen*)user;
  (void)feeder;
  ++seen->count;
  snprintf(seen->kind, sizeof seen->kind, "%s", kind);
  snprintf(seen->message, sizeof seen->message, "%s", message);
}

/* ---- The local vibration law from C ------------------------------------------------------ */

#define PI 3.14159265358979323846
/* The classical straight-track model (Redford & Boothroyd; NOTES section 5), forward sliding
 * only (normal throw number below 1, above the forward and below the backward onset), on a
 * horizontal track, vibration angle beta, friction mu, in units of g / w (velocity) and w t
 * (phase): forward slip starts at sin(phi1) = mu / Q and the slip velocity relative to the
 * track is u(phi) = P (phi - phi1) - Q (cos(phi) - cos(phi1)), P = -mu,
 * Q = (A w^2 / g) (cos(beta) + mu sin(beta)), until it returns to 0 at phi2; the part sticks
 * otherwise. The drift is the mean of u over a cycle. Integrated here by Simpson's rule,
 * independently of the plugin's point-mass model (vibration_drift.cpp, a Moreau time stepper). */
static double slideU(double phi, double phi1, double P, double Q) {
  return P * (phi - phi1) - Q * (cos(phi) - cos(phi1));
}

static double classicalSlidingDrift(double amplitude, double beta, double mu, double frequency,
                                    double g) {
  const double w = 2 * PI * frequency, aw2 = amplitude * w * w / g;
  const double P = -mu, Q = aw2 * (cos(beta) + mu * sin(beta));
  const double phi1 = asin(mu / Q);
  double lo = phi1 + 1e-3, hi = lo, sum, h;
  int i, n = 20000;
  while (hi < phi1 + 2 * PI && slideU(hi, phi1, P, Q) > 0) hi += 1e-3;
  lo = hi - 1e-3;
  for (i = 0; i < 100; ++i) { /* bisect the root phi2 to rounding */
    const double mid = 0.5 * (lo + hi);
    if (slideU(mid, phi1, P, Q) > 0) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  h = (lo - phi1) / n;
  sum = slideU(phi1, phi1, P, Q) + slideU(lo, phi1, P, Q);
  for (i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * slideU(phi1 + i * h, phi1, P, Q);
  return (g / w) * (sum * h / 3) / (2 * PI);
}

/* Between the plugin's tabulated point-mass drift and the classical model: the point-mass
 * model's own error is at most 0.6 % of max(|drift|, 2 % of the peak tangential speed) at its
 * default 16384 steps per cycle (vibration_drift.hpp), and the table interpolates linearly over
 * a cell 0.025 wide in the normal and 0.05 in the tangential throw number. */
static const double kLocalDriftTolerance = 0.02; /* relative */
/* ODE's direct solver (dWorldStep) makes a sticking box move with the contact's motion1 to
 * its own rounding and the contact's CFM slack (1e-5 by default); a box that just started
 * also carries a little of its settling. */
static const double kBoxFollowsTolerance = 0.01; /* relative */

static void localVibrationFromC(void) {
  const double kBeta = 30 * PI / 180, kMu = 0.5, kF = 50, kG = 9.81;
  /* normal throw number Gamma = A w^2 sin(beta) / g = 0.3: forward sliding only for mu = 0.5
   * (onsets 0.224 and 0.406) */
  const double w = 2 * PI * kF, amplitude = 0.3 * kG / (w * w * sin(kBeta));
  const double a[3] = {amplitude * cos(kBeta), 0, amplitude * sin(kBeta)};
  const double gravity[3] = {0, 0, -kG}, origin[3] = {0, 0, 0}, up[3] = {0, 0, 1};
  const double expected = classicalSlidingDrift(amplitude, kBeta, kMu, kF, kG);
  dWorldID world = dWorldCreate();
  dJointGroupID joints = dJointGroupCreate(0);
  dGeomID plane = dCreatePlane(0, 0, 0, 1, 0), box_geom = dCreateBox(0, 0.02, 0.02, 0.01);
  dBodyID box = dBodyCreate(world);
  dMass mass;
  dContact contacts[8];
  rfFeederSetID set = rfFeederSetCreate();
  int n, i, step;
  const double h = 0.01;

  double driven_speed = 0;
  /* forward (along the throw's horizontal part), a small fraction of the peak track speed */
  CHECK(expected > 0 && expected < 0.2 * w * amplitude * cos(kBeta));
  dWorldSetGravity(world, 0, 0, -kG);
  dMassSetBoxTotal(&mass, 0.01, 0.02, 0.02, 0.01);
  dBodySetMass(box, &mass);
  dBodySetPosition(box, 0, 0, 0.005 - 1e-4);
  dGeomSetBody(box_geom, box);

  CHECK(rfFeederSetAddLocalVibration(set, plane, kF, a, 0, origin, up, gravity, 1.0) == rfOK);
  CHECK(strcmp(rfFeederSetGetLastError(set), "") == 0);
  CHECK(rfFeederSetBeginStepDt(set, 0.0, h) == rfOK);
  memset(contacts, 0, sizeof contacts);
  n = dCollide(plane, box_geom, 8, &contacts[0].geom, sizeof(dContact));
  CHECK(n == 4);
  for (i = 0; i < n; ++i) contacts[i].surface.mu = kMu;
  CHECK(rfFeederSetDriveContacts(set, contacts, n) == n);
  for (i = 0; i < n; ++i) {
    /* The plane is g1: ODE's joint moves the part relative to g1 by motion1 along fdir1. */
    CHECK((contacts[i].surface.mode & dContactMotion1) != 0);
    CHECK_NEAR(contacts[i].fdir1[0], 1.0, ROUND_OFF); /* along the throw's horizontal part */
    CHECK_NEAR(contacts[i].surface.motion1, expected, kLocalDriftTolerance * expected);
  }
  if (n > 0) driven_speed = contacts[0].surface.motion1;

  /* The part's own efficiency scales its drift exactly. */
  CHECK(rfFeederSetSetPartEfficiency(set, box, 0.5) == rfOK);
  memset(contacts, 0, sizeof contacts);
  n = dCollide(plane, box_geom, 8, &contacts[0].geom, sizeof(dContact));
  for (i = 0; i < n; ++i) contacts[i].surface.mu = kMu;
  CHECK(rfFeederSetDriveContacts(set, contacts, n) == n);
  CHECK(n > 0);
  if (n > 0) CHECK_NEAR(contacts[0].surface.motion1, 0.5 * driven_speed, ROUND_OFF);
  CHECK(rfFeederSetSetPartEfficiency(set, box, 1.0) == rfOK);

  /* Stepped: the box moves at the driven speed. */
  for (step = 0; step < 50; ++step) {
    CHECK(rfFeederSetBeginStepDt(set, step * h, h) == rfOK);
    memset(contacts, 0, sizeof contacts);
    n = dCollide(plane, box_geom, 8, &contacts[0].geom, sizeof(dContact));
    for (i = 0; i < n; ++i) contacts[i].surface.mu = kMu;
    n = rfFeederSetDriveContacts(set, contacts, n);
    for (i = 0; i < n; ++i) {
      dJointID j = dJointCreateContact(world, joints, &contacts[i]);
      dJointAttach(j, dGeomGetBody(contacts[i].geom.g1), dGeomGetBody(contacts[i].geom.g2));
    }
    dWorldStep(world, h);
    dJointGroupEmpty(joints);
  }
  CHECK_NEAR(dBodyGetLinearVel(box)[0], driven_speed, kBoxFollowsTolerance * driven_speed);
  CHECK_NEAR(dBodyGetLinearVel(box)[1], 0.0, kBoxFollowsTolerance * driven_speed);

  /* Bad values: an error code and a message naming the value. */
  CHECK(rfFeederSetSetPartEfficiency(set, box, -1.0) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "-1");
  CHECK(rfFeederSetSetPartEfficiency(set, 0, 0.5) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "null");
  CHECK(rfFeederSetSetLocalVibration(set, plane, 0.0, a, 0, origin, up, gravity, 1.0) ==
        rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "frequency = 0");
  CHECK(rfFeederSetSetLocalVibration(set, plane, kF, a, 0, origin, up, gravity, 500.0) ==
        rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "500");
  CHECK(rfFeederSetSetLocalVibration(set, plane, kF, a, 0.01, 0, 0, gravity, 1.0) ==
        rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "axis_origin");
  CHECK(rfFeederSetSetLocalVibration(set, plane, kF, 0, 0, origin, up, gravity, 1.0) ==
        rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "amplitude");
  CHECK(rfFeederSetAddLocalVibration(set, plane, kF, a, 0, 0, 0, gravity, 1.0) ==
        rfErrorInvalidArgument); /* registered already */
  CHECK(rfFeederSetSetLocalVibration(set, plane, kF, a, 0, 0, 0, gravity, 1.0) == rfOK);

  rfFeederSetDestroy(set);
  dGeomDestroy(box_geom);
  dGeomDestroy(plane);
  dJointGroupDestroy(joints);
  dWorldDestroy(world);
}

/* The objects the checks of main share: a world, a static belt (top face at z = 0) with a
 * box part on it, three spare geoms and the feeder set. */
struct Fixture {
  dWorldID world;
  dJointGroupID joints;
  dGeomID belt, part_geom, other, field_geom, table_geom;
  dBodyID part;
  rfFeederSetID set;
};
static const double x_axis[3] = {1, 0, 0};
static const double zero[3] = {0, 0, 0};

/* Register the belt, drive its contacts, step ODE until the part is carried at V. */
static void driveAndCarry(struct Fixture* fx) {
  dContact contacts[8];
  int n, driven, i, step;
  rfFeederSetID set = fx->set;
  dWorldID world = fx->world;
  dJointGroupID joints = fx->joints;
  dGeomID belt = fx->belt, part_geom = fx->part_geom, other = fx->other;
  dBodyID part = fx->part;
  /* Register and drive. */
  CHECK(rfFeederSetAddBelt(set, belt, x_axis, kSpeed, rfFrameWorld) == rfOK);
  CHECK(strcmp(rfFeederSetGetLastError(set), "") == 0);
  CHECK(rfFeederSetContains(set, belt) == 1);
  CHECK(rfFeederSetContains(set, other) == 0);
  CHECK(rfFeederSetBeginStep(set, 0.0) == rfOK);
  n = dCollide(belt, part_geom, 8, &contacts[0].geom, sizeof(dContact));
  CHECK(n == 4); /* a box face on a face: four corners */
  for (i = 0; i < n; ++i) {
    memset(&contacts[i].surface, 0, sizeof contacts[i].surface);
    contacts[i].surface.mu = 0.5;
  }
  driven = rfFeederSetDriveContacts(set, contacts, n);
  CHECK(driven == n);
  CHECK(rfFeederSetGetContactsDriven(set, belt) == n);
  for (i = 0; i < driven; ++i) {
    const dReal* f = contacts[i].fdir1;
    const dReal* nn = contacts[i].geom.normal;
    CHECK((contacts[i].surface.mode & dContactFDir1) != 0);
    CHECK((contacts[i].surface.mode & dContactMotion1) != 0);
    CHECK((contacts[i].surface.mode & dContactApprox1) == dContactApprox1);
    CHECK_NEAR(sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), 1.0, ROUND_OFF);
    CHECK_NEAR(f[0] * nn[0] + f[1] * nn[1] + f[2] * nn[2], 0.0, ROUND_OFF);
    /* Static belt: the part is the joint's first body, driven at +V along x. */
    CHECK_NEAR(contacts[i].surface.motion1 * f[0], kSpeed, ROUND_OFF);
    CHECK_NEAR(contacts[i].surface.motion1 * f[1], 0.0, ROUND_OFF);
  }

  /* Step ODE with those contacts: friction mu g h along +x in the first step. */
  for (i = 0; i < driven; ++i) {
    dJointID j = dJointCreateContact(world, joints, &contacts[i]);
    dJointAttach(j, dGeomGetBody(contacts[i].geom.g1), dGeomGetBody(contacts[i].geom.g2));
  }
  dWorldStep(world, 0.001);
  dJointGroupEmpty(joints);
  CHECK(dBodyGetLinearVel(part)[0] > 0.0);
  /* ...and on until it is carried at V (V / (mu g) = 0.061 s). */
  for (step = 1; step < 200; ++step) {
    CHECK(rfFeederSetBeginStep(set, step * 0.001) == rfOK);
    n = dCollide(belt, part_geom, 8, &contacts[0].geom, sizeof(dContact));
    for (i = 0; i < n; ++i) {
      memset(&contacts[i].surface, 0, sizeof contacts[i].surface);
      contacts[i].surface.mu = 0.5;
    }
    n = rfFeederSetDriveContacts(set, contacts, n);
    for (i = 0; i < n; ++i) {
      dJointID j = dJointCreateContact(world, joints, &contacts[i]);
      dJointAttach(j, dGeomGetBody(contacts[i].geom.g1), dGeomGetBody(contacts[i].geom.g2));
    }
    dWorldStep(world, 0.001);
    dJointGroupEmpty(joints);
  }
  CHECK_NEAR(dBodyGetLinearVel(part)[0], kSpeed, 1e-6);
}

/* The belt's contacts with the part at time t (s), driven; their number (> 0 checked). */
static int driveBeltAt(struct Fixture* fx, double t, dContact contacts[8]) {
  int n, i;
  CHECK(rfFeederSetBeginStep(fx->set, t) == rfOK);
  n = dCollide(fx->belt, fx->part_geom, 8, &contacts[0].geom, sizeof(dContact));
  for (i = 0; i < n; ++i) contacts[i].surface.mu = 0.5;
  n = rfFeederSetDriveContacts(fx->set, contacts, n);
  CHECK(n > 0);
  return n;
}

/* Ramp and on/off profiles on the belt. */
static void profiles(struct Fixture* fx) {
  dContact contacts[8];
  rfFeederSetID set = fx->set;
  dGeomID belt = fx->belt;
  /* A ramp profile: halfway through, half the speed. */
  CHECK(rfFeederSetSetRamp(set, belt, 1.0, 2.0, 0.0, 1.0) == rfOK);
  if (driveBeltAt(fx, 1.5, contacts) > 0) {
    CHECK_NEAR(contacts[0].surface.motion1, 0.5 * kSpeed, ROUND_OFF);
  }
  /* An on/off window multiplies it: off at 1.5 s. */
  CHECK(rfFeederSetSetOnOff(set, belt, 5.0, 6.0) == rfOK);
  if (driveBeltAt(fx, 1.5, contacts) > 0) {
    CHECK((contacts[0].surface.mode & dContactMotion1) == 0);
    CHECK(contacts[0].surface.motion1 == 0.0);
  }
  /* A new window replaces the feeder's window and keeps multiplying its ramp: on over [0, 10) s,
   * at 1.5 s the ramp's half speed (the window [5, 6) s is gone). */
  CHECK(rfFeederSetSetOnOff(set, belt, 0.0, 10.0) == rfOK);
  if (driveBeltAt(fx, 1.5, contacts) > 0) {
    CHECK_NEAR(contacts[0].surface.motion1, 0.5 * kSpeed, ROUND_OFF);
  }
  /* Setting the law again drops both profiles. */
  {
    const double x[3] = {1, 0, 0};
    CHECK(rfFeederSetSetBelt(set, belt, x, kSpeed, rfFrameWorld) == rfOK);
  }
  if (driveBeltAt(fx, 1.5, contacts) > 0) {
    CHECK_NEAR(contacts[0].surface.motion1, kSpeed, ROUND_OFF);
  }
}

/* A C field function, and a turntable with and without the step. */
static void fieldAndTurntable(struct Fixture* fx) {
  dContact contacts[8];
  int i, step, field_calls = 0;
  rfFeederSetID set = fx->set;
  dGeomID field_geom = fx->field_geom, part_geom = fx->part_geom, table_geom = fx->table_geom;
  dBodyID part = fx->part;
  /* A C field function, called once per contact. */
  CHECK(rfFeederSetAddField(set, field_geom, yField, &field_calls, 0) == rfOK);
  CHECK(rfFeederSetBeginStep(set, 0.0) == rfOK);
  memset(contacts, 0, sizeof contacts);
  for (i = 0; i < 3; ++i) {
    contacts[i].geom.g1 = field_geom;
    contacts[i].geom.g2 = part_geom;
    contacts[i].geom.normal[2] = 1.0;
    contacts[i].surface.mu = 0.5;
  }
  CHECK(rfFeederSetDriveContacts(set, contacts, 3) == 3);
  CHECK(field_calls == 3);
  CHECK_NEAR(contacts[0].surface.motion1 * contacts[0].fdir1[1], 0.2, ROUND_OFF);

  /* A turntable (w = 1 rad/s about +z through the origin) with the step given: a contact at
   * p = (r, 0, 0) is driven at the chord to the point turned by w h, (R(w h) p - p) / h =
   * r (cos(w h) - 1, sin(w h), 0) / h, so that the part lands on its circle; without the step
   * at the tangent w x p = (0, w r, 0). h = 0.1 s makes the two differ by 5e-4 m/s. */
  {
    const double w_axis[3] = {0, 0, 1};
    const double h = 0.1, r = 0.1;
    CHECK(rfFeederSetAddTwist(set, table_geom, zero, w_axis, zero, rfFrameWorld) == rfOK);
    /* The part's centre of mass right above the contact point: the part is carried rigidly
     * along its centre of mass's chord, which is then the contact point's chord. */
    dBodySetPosition(part, r, 0, 0.05);
    for (step = 0; step < 2; ++step) {
      if (step == 0) {
        CHECK(rfFeederSetBeginStepDt(set, 0.0, h) == rfOK);
      } else {
        CHECK(rfFeederSetBeginStep(set, 0.0) == rfOK);
      }
      memset(contacts, 0, sizeof contacts);
      contacts[0].geom.g1 = table_geom;
      contacts[0].geom.g2 = part_geom;
      contacts[0].geom.pos[0] = r;
      contacts[0].geom.normal[2] = 1.0;
      contacts[0].surface.mu = 0.5;
      CHECK(rfFeederSetDriveContacts(set, contacts, 1) == 1);
      /* The part's body is the joint's first body (the table is static): c_rel = c_table. */
      CHECK_NEAR(contacts[0].surface.motion1 * contacts[0].fdir1[0],
                 step == 0 ? r * (cos(h) - 1.0) / h : 0.0, ROUND_OFF);
      CHECK_NEAR(contacts[0].surface.motion1 * contacts[0].fdir1[1], step == 0 ? r * sin(h) / h : r,
                 ROUND_OFF);
    }
    /* A bad step is refused with its value named. */
    CHECK(rfFeederSetBeginStepDt(set, 0.0, -0.01) == rfErrorInvalidArgument);
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "step = -0.01");
    CHECK(rfFeederSetBeginStepDt(set, 0.0, INFINITY) == rfErrorInvalidArgument);
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "step = inf");
    CHECK(rfFeederSetBeginStepDt(set, 0.0, NAN) == rfErrorInvalidArgument);
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "step = nan");
    CHECK(rfFeederSetBeginStepDt(0, 0.0, h) == rfErrorInvalidArgument);
    CHECK(rfFeederSetRemove(set, table_geom) == rfOK);
  }
}

/* Bad calls: error codes and messages naming the value. */
static void errors(struct Fixture* fx) {
  rfFeederSetID set = fx->set;
  dGeomID belt = fx->belt, other = fx->other;
  /* Errors: a NaN speed, named in the message. */
  CHECK(rfFeederSetAddBelt(set, other, x_axis, NAN, rfFrameWorld) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "belt.speed");
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "nan");
  CHECK(rfFeederSetContains(set, other) == 0);
  /* An unregistered geom. */
  CHECK(rfFeederSetSetBelt(set, other, x_axis, kSpeed, rfFrameWorld) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "not a registered feeder");
  CHECK(rfFeederSetRemove(set, other) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "not a registered feeder");
  CHECK(rfFeederSetGetContactsDriven(set, other) == rfErrorInvalidArgument);
  CHECK(rfFeederSetSetRamp(set, other, 0, 1, 0, 1) == rfErrorInvalidArgument);
  /* The same geom twice, a bad frame, a null vector, a NaN twist, a NaN time. */
  CHECK(rfFeederSetAddBelt(set, belt, x_axis, kSpeed, rfFrameWorld) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "already registered");
  CHECK(rfFeederSetAddBelt(set, other, x_axis, kSpeed, 7) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "frame = 7");
  CHECK(rfFeederSetAddBelt(set, other, 0, kSpeed, rfFrameWorld) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "direction");
  {
    const double bad[3] = {0, INFINITY, 0};
    CHECK(rfFeederSetAddTwist(set, other, zero, bad, zero, rfFrameWorld) == rfErrorInvalidArgument);
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "twist.angular.y");
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "inf");
  }
  CHECK(rfFeederSetAddBelt(set, other, x_axis, kSpeed, rfFrameBody) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "Frame::Body");
  CHECK(rfFeederSetBeginStep(set, NAN) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "time = nan");
  CHECK(rfFeederSetSetRamp(set, belt, 2.0, 1.0, 0.0, 1.0) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "profile.ramp.t_end");
  /* A good call clears the message. */
  CHECK(rfFeederSetBeginStep(set, 0.0) == rfOK);
  CHECK(strcmp(rfFeederSetGetLastError(set), "") == 0);
}

/* Diagnostics, invalid calls, speed limits, removal, null handles and bad options. */
static void diagnosticsAndBadCalls(struct Fixture* fx) {
  dContact contacts[8];
  struct Seen seen;
  rfFeederStats before, after;
  rfFeederSetID set = fx->set;
  dGeomID belt = fx->belt, part_geom = fx->part_geom;
  /* Diagnostics: a negative mu on a feeder contact is removed and reported. */
  memset(&seen, 0, sizeof seen);
  rfFeederSetSetDiagnosticFunction(set, remember, &seen);
  memset(contacts, 0, sizeof contacts);
  contacts[0].geom.g1 = belt;
  contacts[0].geom.g2 = part_geom;
  contacts[0].geom.normal[2] = 1.0;
  contacts[0].surface.mu = -1.0;
  memset(&before, 0, sizeof before);
  memset(&after, 0, sizeof after);
  CHECK(rfFeederSetGetStats(set, belt, &before) == rfErrorInvalidArgument); /* size not set */
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "out->size = 0: set it to sizeof(rfFeederStats)");
  before.size = after.size = sizeof(rfFeederStats);
  CHECK(rfFeederSetGetStats(set, belt, &before) == rfOK);
  CHECK(rfFeederSetDriveContacts(set, contacts, 1) == 0);
  CHECK(seen.count == 1);
  CHECK(strcmp(seen.kind, "invalid_contact") == 0);
  CHECK_MENTIONS(seen.message, "mu = -1");
  /* ... and counted in the feeder's totals */
  CHECK(rfFeederSetGetStats(set, belt, &after) == rfOK);
  CHECK(after.invalid_contacts == before.invalid_contacts + 1);
  CHECK(after.zero_friction == before.zero_friction);
  CHECK(rfFeederSetGetStats(set, belt, 0) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "out is a null pointer");
  CHECK(rfFeederSetGetStats(set, part_geom, &after) == rfErrorInvalidArgument); /* no feeder */

  /* A null array with a positive count, or a negative count, is a caller bug: an error code
   * (never the count), a message naming the value, an "invalid_call" diagnostic. */
  memset(&seen, 0, sizeof seen);
  CHECK(rfFeederSetDriveContacts(set, 0, 3) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "null");
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "count = 3");
  CHECK(seen.count == 1);
  CHECK(strcmp(seen.kind, "invalid_call") == 0);
  CHECK(rfFeederSetDriveContacts(set, contacts, -2) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "count = -2");
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "negative");
  CHECK(seen.count == 2);
  CHECK(rfFeederSetDriveContacts(set, 0, 0) == 0); /* nothing to drive: fine */
  CHECK(strcmp(rfFeederSetGetLastError(set), "") == 0);
  CHECK(seen.count == 2);
  rfFeederSetSetDiagnosticFunction(set, 0, 0);

  /* Speeds beyond the limit (1e100 m/s: ODE squares them) are refused with the value. */
  {
    const double huge[3] = {1e154, 0, 0};
    CHECK(rfFeederSetSetBelt(set, belt, x_axis, 1e154, rfFrameWorld) == rfErrorInvalidArgument);
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "belt.speed = 1e+154");
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "1e+100");
    CHECK(rfFeederSetSetTwist(set, belt, huge, zero, zero, rfFrameWorld) == rfErrorInvalidArgument);
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "|twist.linear| = 1e+154");
    CHECK(rfFeederSetSetTwist(set, belt, zero, huge, zero, rfFrameWorld) == rfErrorInvalidArgument);
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "|twist.angular| = 1e+154 rad/s");
  }

  /* Remove, then it is unknown. */
  CHECK(rfFeederSetRemove(set, belt) == rfOK);
  CHECK(rfFeederSetContains(set, belt) == 0);

  /* Null handles and bad options never crash. */
  CHECK(rfFeederSetBeginStep(0, 0.0) == rfErrorInvalidArgument);
  CHECK(rfFeederSetDriveContacts(0, contacts, 1) == rfErrorInvalidArgument);
  CHECK(rfFeederSetContains(0, belt) == 0);
  CHECK(rfFeederSetGetLastError(0) != 0);
  CHECK(rfFeederSetCreateWithOptions(1, 5, 1e-9) == 0); /* no such attach order */
  CHECK(rfFeederSetCreateWithOptions(1, 0, -1.0) == 0); /* negative threshold */
  CHECK(rfFeederSetCreateWithOptions(1, 0, NAN) == 0);
  {
    rfFeederSetID g2_first = rfFeederSetCreateWithOptions(0, rfAttachG2First, 1e-6);
    CHECK(g2_first != 0);
    rfFeederSetDestroy(g2_first);
  }
  rfFeederSetDestroy(0);
}

/* The friction model from C: the cone where the linked ODE has it, else an error naming it. */
static void frictionModelFromC(void) {
  rfFeederSetID set = rfFeederSetCreate();
  CHECK(set != 0);
  if (!set) return;
  CHECK(rfFeederSetSetFrictionModel(set, rfFrictionPyramid) == rfOK);
  CHECK(rfFeederSetSetFrictionModel(set, 7) == rfErrorInvalidArgument);
  CHECK_MENTIONS(rfFeederSetGetLastError(set), "model = 7");
  if (rfOdeHasFrictionCone()) {
    CHECK(rfFeederSetSetFrictionModel(set, rfFrictionCone) == rfOK);
  } else {
    CHECK(rfFeederSetSetFrictionModel(set, rfFrictionCone) == rfErrorInvalidArgument);
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "friction");
    CHECK_MENTIONS(rfFeederSetGetLastError(set), "ODE_EXT_friction_cone");
  }
  CHECK(rfFeederSetSetFrictionModel(0, rfFrictionPyramid) == rfErrorInvalidArgument);
  rfFeederSetDestroy(set);
}

int main(void) {
  struct Fixture fx;
  dMass mass;

  dInitODE2(0);
  dSetErrorHandler(odeMessage);
  dSetDebugHandler(odeMessage);
  dSetMessageHandler(odeMessage);
  fx.world = dWorldCreate();
  dWorldSetGravity(fx.world, 0, 0, -9.81);
  fx.joints = dJointGroupCreate(0);
  fx.belt = dCreateBox(0, 2.0, 1.0, 0.1); /* static, top face at z = 0 */
  dGeomSetPosition(fx.belt, 0, 0, -0.05);
  fx.part = dBodyCreate(fx.world);
  dMassSetBoxTotal(&mass, 1.0, 0.1, 0.1, 0.1);
  dBodySetMass(fx.part, &mass);
  dBodySetPosition(fx.part, 0, 0, 0.05 - 1e-3); /* 1 mm deep */
  fx.part_geom = dCreateBox(0, 0.1, 0.1, 0.1);
  dGeomSetBody(fx.part_geom, fx.part);
  fx.other = dCreateBox(0, 1, 1, 1);
  fx.field_geom = dCreateBox(0, 1, 1, 1);
  fx.table_geom = dCreateBox(0, 1, 1, 1);
  fx.set = rfFeederSetCreate();
  CHECK(fx.set != 0);
  if (!fx.set) return 1;

  driveAndCarry(&fx);
  profiles(&fx);
  fieldAndTurntable(&fx);
  errors(&fx);
  diagnosticsAndBadCalls(&fx);
  localVibrationFromC();
  frictionModelFromC();

  rfFeederSetDestroy(fx.set);
  dGeomDestroy(fx.table_geom);
  dGeomDestroy(fx.field_geom);
  dGeomDestroy(fx.other);
  dGeomDestroy(fx.part_geom);
  dGeomDestroy(fx.belt);
  dJointGroupDestroy(fx.joints);
  dWorldDestroy(fx.world);
  dCloseODE();

  if (failures) {
    fprintf(stderr, "c_api_test: %d check(s) failed\n", failures);
    return 1;
  }
  printf("c_api_test: all checks passed\n");
  return 0;
}
