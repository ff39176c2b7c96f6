// SPDX-License-Identifier: MIT
// ContactCollider: the ready near callback. Joint attach order, sub-spaces, the surface
// callback, and contact forces read back through dJointFeedback.
#include "rheofeed/contact_collider.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {

constexpr double kStep = 0.001;  // s
constexpr double kMu = 0.4;
constexpr double kSpeed = 0.3;   // m/s
constexpr double kMass = 2.0;    // kg
constexpr double kLayer = 1e-4;  // m, contact surface layer; parts start at this depth

/// Net contact force (N, world) on `part` from the feedback of the recorded feeder contacts.
/// The feeder is static, so the part is the joint's only body and its force is f1 + f2 (the
/// other one is zero whichever slot ODE uses after swapping a 0 first body).
Vec3 contactForceOnPart(const FeederSet& feeders) {
  Vec3 sum;
  for (const ContactRecord& r : feeders.records()) {
    if (!r.feedback) return {NAN, NAN, NAN};
    sum = sum + Vec3{r.feedback->f1[0] + r.feedback->f2[0], r.feedback->f1[1] + r.feedback->f2[1],
                     r.feedback->f1[2] + r.feedback->f2[2]};
  }
  return sum;
}

struct FeedbackScene {
  FeedbackScene() : w(recording(), withFeedback()) {
    w.setSurface(dContactApprox1, kMu);
    dWorldSetContactSurfaceLayer(w.world, kLayer);
    belt = w.staticBox(4.0, 1.0, 0.1, 0, 0, -0.05);
    part = w.box(0.1, 0.1, 0.1, kMass, -1.0, 0, 0.05 - kLayer);
    w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kSpeed));
  }
  static FeederSet::Options recording() {
    FeederSet::Options o;
    o.record_contacts = true;
    return o;
  }
  static ContactCollider::Settings withFeedback() {
    ContactCollider::Settings s;
    s.feedback = true;
    return s;
  }
  OdeWorld w;
  dGeomID belt;
  dBodyID part;
};

// At rest in contact the step's impulses balance gravity up to the velocity change of the
// step (~1e-15 m/s here) times m / h, and CFM = 1e-9 compliance.
constexpr double kForceTolerance = 1e-6;  // N

}  // namespace

TEST(ContactFeedback, SlidingPartFeelsMuMgAlongTheBeltAndMgUp) {
  FeedbackScene s;
  s.w.run(0.02, kStep);  // sliding until V / (mu g) = 0.076 s
  ASSERT_EQ(s.w.feeders->records().size(), 4u);
  const Vec3 f = contactForceOnPart(*s.w.feeders);
  // Friction is exactly mu N along fdir1 = +x (the Approx1 bound of row 1), N = m g.
  EXPECT_NEAR(f.x, kMu * kMass * kGravity, kForceTolerance);
  EXPECT_NEAR(f.y, 0.0, kForceTolerance);
  EXPECT_NEAR(f.z, kMass * kGravity, kForceTolerance);
}

TEST(ContactFeedback, RestingPartCarriedAtBeltSpeedFeelsOnlyMg) {
  FeedbackScene s;
  s.w.run(0.5, kStep);  // stuck at V since 0.076 s
  ASSERT_NEAR(linearVelocity(s.part).x, kSpeed, 1e-7);
  ASSERT_EQ(s.w.feeders->records().size(), 4u);
  for (const ContactRecord& r : s.w.feeders->records()) {
    EXPECT_NE(r.joint, nullptr);
    EXPECT_EQ(dJointGetType(r.joint), dJointTypeContact);
  }
  const Vec3 f = contactForceOnPart(*s.w.feeders);
  EXPECT_NEAR(f.x, 0.0, kForceTolerance);
  EXPECT_NEAR(f.y, 0.0, kForceTolerance);
  EXPECT_NEAR(f.z, kMass * kGravity, kForceTolerance);
}

TEST(ContactColliderAttach, G2FirstAttachOrderRestsAndCarriesLikeG1First) {
  // Options::attach_order = G2First makes the collider attach (body(g2), body(g1)). ODE's
  // normal points into g1 and a contact joint pushes its first body along the normal, so the
  // joint must get the negated normal; otherwise the contact pulls the part into the belt.
  BodyState result[2];
  for (AttachOrder order : {AttachOrder::G1First, AttachOrder::G2First}) {
    FeederSet::Options options;
    options.attach_order = order;
    OdeWorld w(options);
    w.setSurface(dContactApprox1, kMu);
    dWorldSetContactSurfaceLayer(w.world, kLayer);
    dGeomID belt = w.staticBox(4.0, 1.0, 0.1, 0, 0, -0.05);
    dBodyID part = w.box(0.1, 0.1, 0.1, kMass, 0, 0, 0.05 - kLayer);
    dGeomID plain = w.staticBox(1.0, 1.0, 0.1, 3.0, 0, -0.05);  // plain ground, no feeder
    (void)plain;
    dBodyID resting = w.box(0.1, 0.1, 0.1, kMass, 3.0, 0, 0.05 - kLayer);
    w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kSpeed));
    w.run(0.3, kStep);
    SCOPED_TRACE(order == AttachOrder::G1First ? "g1 first" : "g2 first");
    EXPECT_NEAR(position(resting).z, 0.05 - kLayer, 1e-6);
    EXPECT_NEAR(position(part).z, 0.05 - kLayer, 1e-6);
    EXPECT_NEAR(linearVelocity(part).x, kSpeed, 1e-7);
    result[order == AttachOrder::G1First ? 0 : 1] = stateOf(part);
  }
  EXPECT_LT(maxDifference(result[0], result[1]), 1e-9);
}

TEST(ContactColliderSpaces, PartsInASubSpaceAreDrivenToo) {
  OdeWorld w;
  w.setSurface(dContactApprox1, kMu);
  dWorldSetContactSurfaceLayer(w.world, kLayer);
  dGeomID belt = w.staticBox(4.0, 1.0, 0.1, 0, 0, -0.05);
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kSpeed));
  dSpaceID parts = dSimpleSpaceCreate(w.space);
  dBodyID a = w.box(0.1, 0.1, 0.1, 1.0, -0.5, 0, 0.05 - kLayer);
  dBodyID b = w.box(0.1, 0.1, 0.1, 1.0, 0.5, 0, 0.05 - kLayer);
  for (dBodyID body : {a, b}) {
    dGeomID g = dBodyGetFirstGeom(body);
    dSpaceRemove(w.space, g);
    dSpaceAdd(parts, g);
  }
  w.run(0.3, kStep);
  EXPECT_EQ(w.feeders->stats(belt).contacts_driven, 8);
  EXPECT_EQ(w.collider->contactCount(), 8);
  EXPECT_NEAR(linearVelocity(a).x, kSpeed, 1e-7);
  EXPECT_NEAR(linearVelocity(b).x, kSpeed, 1e-7);
}

TEST(ContactColliderSurface, RejectedPairGetsNoJoints) {
  OdeWorld w;
  dGeomID belt = w.staticBox(4.0, 1.0, 0.1, 0, 0, -0.05);
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kSpeed));
  dBodyID part = w.box(0.1, 0.1, 0.1, 1.0, 0, 0, 0.05);
  w.collider->setSurfaceCallback([](dGeomID, dGeomID, dContact*, int) { return false; });
  w.step(kStep);
  EXPECT_EQ(w.collider->contactCount(), 0);
  EXPECT_EQ(w.feeders->stats(belt).contacts_driven, 0);
  EXPECT_NEAR(linearVelocity(part).z, -kGravity * kStep, 1e-12);  // free fall
}

TEST(ContactColliderSurface, DefaultSurfaceIsApprox1WithMuHalf) {
  // No callback: mu = 0.5 as a coefficient, so a sliding part accelerates at 0.5 g.
  OdeWorld w;
  dWorldSetContactSurfaceLayer(w.world, kLayer);
  w.collider->setSurfaceCallback(nullptr);
  dGeomID belt = w.staticBox(4.0, 1.0, 0.1, 0, 0, -0.05);
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kSpeed));
  dBodyID part = w.box(0.1, 0.1, 0.1, 3.0, 0, 0, 0.05 - kLayer);
  w.run(0.02, kStep);
  EXPECT_NEAR(linearVelocity(part).x, 0.5 * kGravity * 0.02, 1e-9);
}

TEST(ContactColliderJoints, ConnectedBodiesDoNotCollide) {
  OdeWorld w;
  dBodyID a = w.box(0.1, 0.1, 0.1, 1.0, 0, 0, 1.0);
  dBodyID b = w.box(0.1, 0.1, 0.1, 1.0, 0.05, 0, 1.0);  // overlapping
  dJointID hinge = dJointCreateHinge(w.world, nullptr);
  dJointAttach(hinge, a, b);
  w.collider->collide(w.space, 0.0);
  EXPECT_EQ(w.collider->contactCount(), 0);
  dJointDestroy(hinge);
  w.collider->collide(w.space, 0.0);
  EXPECT_GT(w.collider->contactCount(), 0);
}

// Speculative contacts (contact_collider.hpp): a 20 mm cube falling at 3 m/s onto a 2 mm plate
// moves 30 mm per step of 10 ms, more than cube and plate together: ODE's contacts, made only
// where geoms overlap, never see the plate. Swept, the cube lands on it: at rest on its top,
// centre 10 mm above it (the geometry), within ERP's correction of a step's residual.
namespace speculative {

constexpr double kH = 0.01;         // s
constexpr double kEdge = 0.02;      // m, cube
constexpr double kPlate = 0.002;    // m, plate thickness; its top at z = 0
constexpr double kDropSpeed = 3.0;  // m/s, downwards

struct Drop {
  explicit Drop(bool speculative, bool clamp_passes = false)
      : w({}, settings(speculative, clamp_passes)) {
    w.setSurface(dContactApprox1, kMu);
    plate = w.staticBox(1.0, 1.0, kPlate, 0, 0, -0.5 * kPlate);
    cube = w.box(kEdge, kEdge, kEdge, 0.01, 0, 0, 0.05);
    dBodySetLinearVel(cube, 0, 0, -kDropSpeed);
  }
  static ContactCollider::Settings settings(bool speculative, bool clamp_passes) {
    ContactCollider::Settings s;
    s.speculative = speculative;
    s.clamp_passes = clamp_passes;
    return s;
  }
  void run(double seconds) {
    for (double t = 0; t < seconds - 0.5 * kH; t += kH) {
      w.collider->collide(w.space, t, kH);
      speculative_contacts += w.collider->speculativeContactCount();
      dWorldQuickStep(w.world, kH);
      for (const ContactCollider::ThroughPass& p : w.collider->stopPassesThroughStaticGeoms()) {
        passes.push_back(p);
      }
    }
  }
  OdeWorld w;
  dGeomID plate;
  dBodyID cube;
  long speculative_contacts = 0;
  std::vector<ContactCollider::ThroughPass> passes;
};

TEST(ContactCollider, FastCubePassesThroughAThinPlateWithoutSpeculativeContacts) {
  Drop drop(false);
  drop.run(0.2);
  EXPECT_LT(position(drop.cube).z, -kPlate - kEdge) << "the premise: ODE alone misses the plate";
  EXPECT_EQ(drop.speculative_contacts, 0);
}

// Passes stopped (contact_collider.hpp): without speculative contacts the cube's centre passes
// the plate within one step (semi-implicit Euler from z = 50 mm at 3 m/s: 19 mm after the first
// step, -13 mm after the second, below the plate's bottom at -2 mm). Put back where it was
// before that step, its downward velocity removed, it then falls at g (1 mm in the next step)
// and lands on the plate by ODE's own contacts: one pass, through the plate, in by its top face.
TEST(ContactCollider, PassThroughAThinPlateIsPutBackAndTheCubeLandsOnIt) {
  Drop drop(false, true);
  drop.run(0.3);
  EXPECT_EQ(drop.speculative_contacts, 0);
  ASSERT_EQ(drop.passes.size(), 1u);
  const ContactCollider::ThroughPass& p = drop.passes[0];
  EXPECT_EQ(p.body, drop.cube);
  EXPECT_EQ(p.geom, drop.plate);
  EXPECT_GT(p.from.z, 0);      // above the plate's top before the step
  EXPECT_LT(p.to.z, -kPlate);  // below its bottom after it
  EXPECT_NEAR(p.normal.z, 1.0, 1e-9);
  EXPECT_NEAR(position(drop.cube).z, 0.5 * kEdge, 2e-4);  // resting on the top face
  EXPECT_LT(norm(linearVelocity(drop.cube)), 1e-3);
}

// ... but not twice in a row: a stop gives the body back its pre-step state, so a solve that
// gave it the same speed again would repeat the pass in every step and freeze the body. Here the
// cube is thrown down at 3 m/s again right after its stop (as a striking part would): that second
// pass stands (the caller's checks count it), and the cube ends below the plate.
TEST(ContactCollider, ABodyStoppedInOneStepIsNotStoppedInTheNext) {
  Drop drop(false, true);
  int stops_seen = 0;
  for (int k = 0; k < 10 && stops_seen == 0; ++k) {
    drop.w.collider->collide(drop.w.space, k * kH, kH);
    dWorldQuickStep(drop.w.world, kH);
    stops_seen = static_cast<int>(drop.w.collider->stopPassesThroughStaticGeoms().size());
  }
  ASSERT_EQ(stops_seen, 1);
  EXPECT_GT(position(drop.cube).z, 0);  // put back above the plate
  dBodySetLinearVel(drop.cube, 0, 0, -kDropSpeed);
  drop.w.collider->collide(drop.w.space, 1.0, kH);
  dWorldQuickStep(drop.w.world, kH);
  EXPECT_TRUE(drop.w.collider->stopPassesThroughStaticGeoms().empty());
  EXPECT_LT(position(drop.cube).z, -kPlate);  // through: the pass stands
}

TEST(ContactCollider, SpeculativeContactsLandAFastCubeOnAThinPlate) {
  Drop drop(true);
  drop.run(0.3);
  EXPECT_GT(drop.speculative_contacts, 0);
  EXPECT_NEAR(position(drop.cube).z, 0.5 * kEdge, 2e-4);  // resting on the top face
  EXPECT_LT(norm(linearVelocity(drop.cube)), 1e-3);
}

// A 10 mm cube dropped flat from 8 mm above a static cube of its own size, exactly aligned, at
// h = 14.3 ms (a tenth of its edge is g h^2 / 2: the step of the mass-ratio probe at X = 5,
// check_mass_ratio.cpp): it moves 4.4 mm in its landing step, so it lands on speculative
// contacts, whose rays from its four lower corners meet the other cube's top face at its four
// corners. Landing square on a face it must not turn (the symmetry; the solver's row order
// leaves some 0.1 rad/s) and must come to rest on it. Rays cast from the exact corners grazed
// the edges and hit or missed by rounding: the cube landed spinning at 24 rad/s and toppled.
TEST(ContactCollider, SpeculativeContactsLandACubeFlatOnAnEqualCubeWithoutTurningIt) {
  constexpr double edge = 0.01, h = 0.0143, gap = 0.8 * edge;
  ContactCollider::Settings s;
  s.speculative = true;
  OdeWorld w({}, s);
  w.setSurface(dContactApprox1, kMu);
  w.staticBox(edge, edge, edge, 0, 0, -0.5 * edge);  // its top face at z = 0
  dBodyID cube = w.box(edge, edge, edge, 0.003, 0, 0, gap + 0.5 * edge);
  double max_turn = 0;
  long speculative_contacts = 0;
  for (double t = 0; t < 0.5; t += h) {
    w.collider->collide(w.space, t, h);
    speculative_contacts += w.collider->speculativeContactCount();
    dWorldQuickStep(w.world, h);
    max_turn = std::max(max_turn, norm(angularVelocity(cube)));
  }
  EXPECT_GT(speculative_contacts, 0);
  EXPECT_LT(max_turn, 1.0);  // rad/s
  EXPECT_NEAR(position(cube).z, 0.5 * edge, 2e-4);
  EXPECT_LT(norm(linearVelocity(cube)), 1e-3);
}

// A sphere thrown sideways at a 2 mm wall at 4 m/s (40 mm per step) stops against it.
TEST(ContactCollider, SpeculativeContactsStopASphereAtAThinWall) {
  ContactCollider::Settings s;
  s.speculative = true;
  OdeWorld w({}, s);
  w.setSurface(dContactApprox1, 0.0);
  dWorldSetGravity(w.world, 0, 0, 0);
  w.staticBox(kPlate, 1.0, 1.0, 0.1, 0, 0);  // its near face at x = 0.099
  dBodyID ball = dBodyCreate(w.world);
  dMass m;
  dMassSetSphereTotal(&m, 0.01, 0.01);
  dBodySetMass(ball, &m);
  dBodySetPosition(ball, 0, 0, 0);
  dBodySetLinearVel(ball, 4.0, 0, 0);
  dGeomSetBody(dCreateSphere(w.space, 0.01), ball);
  for (double t = 0; t < 0.1; t += kH) {
    w.collider->collide(w.space, t, kH);
    dWorldQuickStep(w.world, kH);
  }
  EXPECT_NEAR(position(ball).x, 0.1 - 0.5 * kPlate - 0.01, 2e-4);  // touching the near face
  EXPECT_LT(linearVelocity(ball).x, 1e-3);
}

TEST(ContactCollider, RefusesANonPositiveSpeculativeFraction) {
  dInitODE2(0);
  dWorldID world = dWorldCreate();
  FeederSet feeders;
  for (double bad : {0.0, -1.0, double(NAN), double(INFINITY)}) {
    ContactCollider::Settings s;
    s.speculative_fraction = bad;
    EXPECT_THROW(ContactCollider(world, feeders, s), std::invalid_argument) << bad;
  }
  dWorldDestroy(world);
}

}  // namespace speculative

// A bad default surface is refused when the collider is made (a NaN mu made every feeder
// contact invalid, and the parts fell through the feeders), and a null space by collide (it
// reached dSpaceCollide, which aborts).
TEST(ContactCollider, RefusesABadDefaultSurfaceAndANullSpace) {
  dInitODE2(0);
  dWorldID world = dWorldCreate();
  FeederSet feeders;
  const auto refused = [&](void (*spoil)(dSurfaceParameters&), const char* mention) {
    ContactCollider::Settings s;
    spoil(s.default_surface);
    try {
      ContactCollider collider(world, feeders, s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what()).find(mention) != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(refused([](dSurfaceParameters& p) { p.mu = NAN; }, "default_surface.mu = nan"));
  EXPECT_TRUE(refused([](dSurfaceParameters& p) { p.mu = -0.1; }, "default_surface.mu = -0.1"));
  EXPECT_TRUE(refused(
      [](dSurfaceParameters& p) {
        p.mode |= dContactMu2;
        p.mu2 = NAN;
      },
      "default_surface.mu2 = nan"));
  EXPECT_TRUE(refused(
      [](dSurfaceParameters& p) {
        p.mode |= dContactBounce;
        p.bounce = 1.5;
      },
      "default_surface.bounce = 1.5"));
  EXPECT_FALSE(refused([](dSurfaceParameters& p) { p.mu = dInfinity; }, "mu"));  // allowed
  ContactCollider collider(world, feeders);
  EXPECT_THROW(collider.collide(nullptr, 0.0, 0.01), std::invalid_argument);
  dWorldDestroy(world);
}

// Warm start (contact_collider.hpp): a column of kCount equal cubes on a static floor, stepped
// at h = 10 ms with quickstep at kIterations sweeps; the cubes cannot turn (maximum angular speed
// 0) and the contacts have no friction, so the column can only settle, not topple. From zero,
// each sweep carries the load about one contact further down, so the sweeps cannot carry the
// column's weight within a step and ERP has to push it back up from an overlap: it settles by
// about an edge. Started from the previous step's forces, the weight carries over from step to
// step. Statics and geometry: the floor carries the whole weight, kCount m g, and each cube rests
// at (i + 1/2) edge.
namespace warm_start {

constexpr double kH = 0.01;         // s
constexpr double kEdge = 0.01;      // m
constexpr double kCubeMass = 0.01;  // kg
constexpr int kCount = 12;
constexpr int kIterations = 20;

struct Column {
  explicit Column(bool warm) : w({}, settings(warm)) {
    dRandSetSeed(1);  // quickstep shuffles its rows with ODE's generator
    w.setSurface(0, 0.0);
    dWorldSetQuickStepNumIterations(w.world, kIterations);
    floor = w.staticBox(1.0, 1.0, 0.1, 0, 0, -0.05);
    for (int i = 0; i < kCount; ++i) {
      cubes.push_back(w.box(kEdge, kEdge, kEdge, kCubeMass, 0, 0, (i + 0.5) * kEdge));
      dBodySetMaxAngularSpeed(cubes.back(), 0);
    }
  }
  static ContactCollider::Settings settings(bool warm) {
    ContactCollider::Settings s;
    s.warm_start = warm;
    s.feedback = true;
    return s;
  }
  // Runs `seconds`; returns the largest settling (m) of any cube below its resting height
  // (i + 1/2) edge over the steps after `after` seconds.
  double run(double seconds, double after) {
    double worst = 0;
    for (double t = 0; t < seconds - 0.5 * kH; t += kH) {
      w.collider->collide(w.space, t, kH);
      warm_started += w.collider->warmStartedContactCount();
      dWorldQuickStep(w.world, kH);
      if (t < after) continue;
      for (int i = 0; i < kCount; ++i) {
        const double z = position(cubes[static_cast<std::size_t>(i)]).z;
        worst = std::max(worst, (i + 0.5) * kEdge - z);
      }
    }
    return worst;
  }
  // Upward force (N) of the floor's contacts in the last step.
  double floorForce() const {
    double up = 0;
    for (const ContactCollider::Joint& j : w.collider->joints()) {
      if (j.g1 != floor && j.g2 != floor) continue;
      // the cube is the joint's only body: f1 + f2 is the force on it
      up += j.feedback->f1[2] + j.feedback->f2[2];
    }
    return up;
  }
  OdeWorld w;
  dGeomID floor;
  std::vector<dBodyID> cubes;
  long warm_started = 0;
};

TEST(ContactCollider, WarmStartCarriesAColumnsWeightThatTheSweepsFromZeroCannot) {
  if (!odeHasContactWarmStart()) GTEST_SKIP() << "the linked ODE has no warm start (stock ODE)";
  const double weight = kCount * kCubeMass * kGravity;
  Column cold(false);
  const double cold_settling = cold.run(4.0, 1.0);
  EXPECT_GT(cold_settling, 0.6 * kEdge) << "the premise: from zero the column settles";
  EXPECT_EQ(cold.warm_started, 0);

  Column warm(true);
  const double warm_settling = warm.run(4.0, 1.0);
  std::printf("column of %d cubes, %d iterations: settles %.3g mm from zero, %.3g mm warm\n",
              kCount, kIterations, 1e3 * cold_settling, 1e3 * warm_settling);
  EXPECT_LT(warm_settling, 0.4 * kEdge);
  EXPECT_GT(warm.warm_started, 0);
  EXPECT_NEAR(warm.floorForce(), weight, 0.02 * weight);
}

TEST(ContactCollider, WarmStartIsRefusedWithoutThePatchAndForBadSettings) {
  dInitODE2(0);
  dWorldID world = dWorldCreate();
  FeederSet feeders;
  ContactCollider::Settings s;
  s.warm_start = true;
  if (odeHasContactWarmStart()) {
    EXPECT_NO_THROW(ContactCollider(world, feeders, s));
  } else {
    EXPECT_THROW(ContactCollider(world, feeders, s), std::invalid_argument);
  }
  for (double bad : {0.0, -1e-3, double(NAN), double(INFINITY)}) {
    ContactCollider::Settings b;
    b.warm_start_distance = bad;
    EXPECT_THROW(ContactCollider(world, feeders, b), std::invalid_argument) << bad;
  }
  for (double bad : {0.0, -0.5, 1.5, double(NAN)}) {
    ContactCollider::Settings b;
    b.warm_start_factor = bad;
    EXPECT_THROW(ContactCollider(world, feeders, b), std::invalid_argument) << bad;
  }
  dWorldDestroy(world);
}

}  // namespace warm_start

}  // namespace rheofeed::test
