// SPDX-License-Identifier: MIT
// Body layouts: a feeder must impose the same surface motion whether its geom is static or on
// a body, g1 or g2 of the contact, whatever order the application attaches the joint in, and
// against another feeder; a feeder that does not move must be a plain geom.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {

constexpr double kStep = 0.005;  // s
constexpr double kMu = 0.5;
constexpr double kLayer = 1e-4;  // m, contact surface layer; parts start at this depth
constexpr double kPart = 0.1;    // m, cubic part
// dWorldStep solves each step's LCP exactly up to CFM = 1e-9 and round-off.
constexpr double kLcpTolerance = 1e-9;

enum class Carrier {
  Static,     // the feeder geom has no body
  Kinematic,  // on a kinematic body at rest
  Heavy,      // on a dynamic body 1e4 times the part's mass, resting on a static ground
};
const char* name(Carrier c) {
  return c == Carrier::Static ? "static" : c == Carrier::Kinematic ? "kinematic" : "heavy";
}

constexpr double kHeavyMass = 1e4;  // kg, against a 1 kg part

/// A feeder with a twist law (translation plus a turn about a point off the part, so the part
/// moves in x and y and spins) and a part released on it; stepped with a forced geom order.
struct LayoutRun {
  LayoutRun(Carrier carrier_kind, bool g1_is_feeder, AttachOrder order)
      : w(options(order)), carrier(carrier_kind), feeder_g1(g1_is_feeder) {
    dWorldSetContactSurfaceLayer(w.world, kLayer);
    feeder = dCreateBox(w.space, 2.0, 1.0, 0.1);
    if (carrier == Carrier::Static) {
      dGeomSetPosition(feeder, 0, 0, -0.05);
    } else {
      carrier_body = dBodyCreate(w.world);
      dGeomSetBody(feeder, carrier_body);
      dBodySetPosition(carrier_body, 0, 0, -0.05);
      if (carrier == Carrier::Kinematic) {
        dBodySetKinematic(carrier_body);
      } else {
        dMass m;
        dMassSetBoxTotal(&m, kHeavyMass, 2.0, 1.0, 0.2);
        dBodySetMass(carrier_body, &m);
        // A second, non-feeder geom of the same body rests on the ground.
        base = dCreateBox(w.space, 2.0, 1.0, 0.1);
        dGeomSetBody(base, carrier_body);
        dGeomSetOffsetPosition(base, 0, 0, -0.1);
        // The ground starts at the depth where the heavy body rests: CFM lets a contact row
        // yield CFM * lambda (m/s per N) and ERP pushes back (erp / h) * (depth - layer), so
        // at rest depth - layer = CFM * lambda * h / erp, with lambda = (M + m) g / 4.
        const double rest = kWorldCfm * (kHeavyMass + 1.0) * kGravity / 4 * kStep / kWorldErp;
        ground = w.staticBox(3.0, 2.0, 0.1, 0, 0, -0.25 + kLayer + rest);
      }
    }
    part = w.box(kPart, kPart, kPart, 1.0, 0.1, -0.05, kPart / 2 - kLayer);
    part_geom = dBodyGetFirstGeom(part);
    w.feeders->add(feeder, MotionLaw::twist({{0.2, 0.1, 0}, {0, 0, 0.5}, {0.3, -0.2, 0}}));
  }
  static FeederSet::Options options(AttachOrder order) {
    FeederSet::Options o;
    o.attach_order = order;
    return o;
  }
  void step() {
    const auto pair =
        feeder_g1 ? std::make_pair(feeder, part_geom) : std::make_pair(part_geom, feeder);
    if (carrier == Carrier::Heavy) {
      // Approx1 on the ground contacts too: with mode 0 there (mu = a 0.5 N force cap per
      // row) under the part's Approx1 rows, ODE 0.16's Dantzig solver reports "LCP internal
      // error, s <= 0" and returns garbage; reproduced without the plugin (hand-set motion1
      // or a plain push force), so it is ODE's, and not what this test is about.
      w.stepPairs({pair, {base, ground}}, kStep, kMu, dContactApprox1);
    } else {
      w.stepPairs({pair}, kStep, kMu, dContactApprox1);
    }
  }

  OdeWorld w;
  Carrier carrier;
  bool feeder_g1;
  dGeomID feeder;
  dBodyID carrier_body = nullptr;
  dGeomID base = nullptr;
  dGeomID ground = nullptr;
  dBodyID part;
  dGeomID part_geom;
};

// The heavy body is held by its ground contacts, whose rows yield CFM * lambda (m/s per N):
// the part's load and friction (m g ~ 10 N) move it at ~1e-8 m/s; the part follows.
constexpr double kHeavyTolerance = 2 * kWorldCfm * 1.0 * kGravity;

constexpr int kLayoutSteps = 100;  // 0.5 s: spin-up (~0.05 s) and sticking

std::vector<BodyState> trajectory(Carrier carrier, bool feeder_g1, AttachOrder order) {
  LayoutRun run(carrier, feeder_g1, order);
  std::vector<BodyState> states;
  for (int i = 0; i < kLayoutSteps; ++i) {
    run.step();
    states.push_back(stateOf(run.part));
  }
  return states;
}

double worstDifference(const std::vector<BodyState>& a, const std::vector<BodyState>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::fmax(worst, maxDifference(a[i], b[i]));
  return worst;
}

}  // namespace

TEST(Layouts, StaticAndKinematicFeederAsG1OrG2GiveTheSameTrajectory) {
  const std::vector<BodyState> reference = trajectory(Carrier::Static, true, AttachOrder::G1First);
  // The part really moves: x, y and yaw all change (so the comparison covers every component).
  const BodyState& last = reference.back();
  ASSERT_GT(std::fabs(last.linear[0]), 0.01);
  ASSERT_GT(std::fabs(last.linear[1]), 0.01);
  ASSERT_GT(std::fabs(last.angular[2]), 0.1);
  // ...and the reference itself is right: stuck to the twist field v + w x (p - O), taken at
  // the position where the last step's contacts were made, and spinning at w.
  const BodyState& before = reference[reference.size() - 2];
  const double rx = before.position[0] - 0.3, ry = before.position[1] + 0.2;
  constexpr double kStickCreep = 5e-8;  // CFM compliance of sticking rows (belt_contact_test)
  EXPECT_NEAR(last.linear[0], 0.2 - 0.5 * ry, kStickCreep);
  EXPECT_NEAR(last.linear[1], 0.1 + 0.5 * rx, kStickCreep);
  EXPECT_NEAR(last.angular[2], 0.5, kStickCreep);
  for (AttachOrder order : {AttachOrder::G1First, AttachOrder::G2First}) {
    for (Carrier carrier : {Carrier::Static, Carrier::Kinematic}) {
      for (bool g1 : {true, false}) {
        SCOPED_TRACE(testing::Message() << name(carrier) << (g1 ? ", feeder g1" : ", feeder g2")
                                        << (order == AttachOrder::G1First ? ", attach g1 first"
                                                                          : ", attach g2 first"));
        const double diff = worstDifference(trajectory(carrier, g1, order), reference);
        std::printf("[ measured ] layout %s g%d attach %s: max state difference %.3g\n",
                    name(carrier), g1 ? 1 : 2, order == AttachOrder::G1First ? "g1" : "g2", diff);
        EXPECT_LT(diff, kLcpTolerance);
      }
    }
  }
}

TEST(Layouts, HeavyDynamicFeederOnGroundGivesTheSameTrajectory) {
  const std::vector<BodyState> reference = trajectory(Carrier::Static, true, AttachOrder::G1First);
  for (bool g1 : {true, false}) {
    SCOPED_TRACE(g1 ? "feeder g1" : "feeder g2");
    const double diff =
        worstDifference(trajectory(Carrier::Heavy, g1, AttachOrder::G1First), reference);
    std::printf("[ measured ] layout heavy g%d: max state difference %.3g\n", g1 ? 1 : 2, diff);
    EXPECT_LT(diff, kHeavyTolerance);
  }
}

// ---------------------------------------------------------------------------------------------
// A feeder that does not move is a plain geom

namespace {

/// Drops a cubic part from 1 cm onto a static box and lets it settle for 1 s with the
/// ContactCollider; if `law` is given the box is a feeder with that law. Returns the final
/// state of the part.
BodyState settle(const MotionLaw* law, bool force_approx1, int mode) {
  FeederSet::Options options;
  options.force_approx1 = force_approx1;
  OdeWorld w(options);
  w.setSurface(mode, kMu);
  dGeomID table = w.staticBox(2.0, 1.0, 0.1, 0, 0, -0.05);
  dBodyID part = w.box(kPart, kPart, kPart, 1.0, 0.1, -0.05, kPart / 2 + 0.01);
  if (law) w.feeders->add(table, *law);
  w.run(1.0, kStep);
  return stateOf(part);
}

bool bitwiseEqual(const BodyState& a, const BodyState& b) {
  return std::memcmp(a.position.data(), b.position.data(), sizeof a.position) == 0 &&
         std::memcmp(a.quaternion.data(), b.quaternion.data(), sizeof a.quaternion) == 0 &&
         std::memcmp(a.linear.data(), b.linear.data(), sizeof a.linear) == 0 &&
         std::memcmp(a.angular.data(), b.angular.data(), sizeof a.angular) == 0;
}

}  // namespace

TEST(ZeroMotionFeeder, RestsAtExactlyTheHeightOfAPlainGeom) {
  // A feeder whose surface does not move only gets mode &= ~(FDir1 | Motion1 | Motion2),
  // motion1 = motion2 = 0 (plus Approx1, which the plain run sets itself): ODE sees the same
  // contact rows, so the same floating-point operations give bitwise the same state.
  const MotionLaw laws[] = {
      MotionLaw::belt({1, 0, 0}, 0.0),
      MotionLaw(),
      MotionLaw::rotation({0, 0, 0}, {1, 2, 3}),
      MotionLaw::translation({0.3, 0, 0}).withProfile(TimeProfile::constant(0.0)),
      MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::onOff(100.0)),
  };
  const BodyState plain = settle(nullptr, true, dContactApprox1);
  // Settled on the table top, within the ERP recovery of the last penetration.
  ASSERT_NEAR(plain.position[2], kPart / 2, 1e-3);
  int index = 0;
  for (const MotionLaw& law : laws) {
    SCOPED_TRACE(testing::Message() << "law #" << index++);
    const BodyState fed = settle(&law, true, dContactApprox1);
    EXPECT_EQ(fed.position[2], plain.position[2]);
    EXPECT_TRUE(bitwiseEqual(fed, plain)) << "max difference " << maxDifference(fed, plain);
  }
  // The same without Approx1 on either side (Options::force_approx1 = false).
  const BodyState plain_box = settle(nullptr, false, 0);
  const BodyState fed_box = settle(&laws[0], false, 0);
  EXPECT_EQ(fed_box.position[2], plain_box.position[2]);
  EXPECT_TRUE(bitwiseEqual(fed_box, plain_box));
}

// ---------------------------------------------------------------------------------------------
// Feeder against feeder

namespace {

constexpr double kBeltSpeed = 0.3;        // m/s along x, feeder F1
const Vec3 kPartSurface{0.1, 0.05, 0.0};  // m/s, feeder F2's surface, in its body frame
// F2 accelerates at most mu g = 4.9 m/s^2 towards |c1 - c2| ~ 0.2 m/s: stuck after ~0.05 s.
constexpr int kFeederFeederSteps = 100;

}  // namespace

TEST(FeederAgainstFeeder, SurfacesMoveTogetherSoRelativeVelocityIsTheFieldDifference) {
  // Two feeders in contact: the material points move together, v1 + c1 = v2 + c2 (tangential),
  // so the bodies' relative velocity v1 - v2 equals c2 - c1. F1 is a belt on a static geom or on
  // a kinematic body moving at u; F2 is a box (a dynamic body) whose own surface moves at
  // kPartSurface relative to it.
  for (bool kinematic : {false, true}) {
    for (bool f1_is_g1 : {true, false}) {
      SCOPED_TRACE(testing::Message() << (kinematic ? "F1 kinematic, moving" : "F1 static")
                                      << (f1_is_g1 ? ", F1 = g1" : ", F1 = g2"));
      OdeWorld w;
      dWorldSetContactSurfaceLayer(w.world, kLayer);
      dGeomID f1 = dCreateBox(w.space, 4.0, 1.0, 0.1);
      Vec3 u{0, 0, 0};
      dBodyID carrier = nullptr;
      if (kinematic) {
        carrier = dBodyCreate(w.world);
        dBodySetKinematic(carrier);
        dGeomSetBody(f1, carrier);
        dBodySetPosition(carrier, 0, 0, -0.05);
        u = {0.0, 0.1, 0.0};
        dBodySetLinearVel(carrier, u.x, u.y, u.z);
      } else {
        dGeomSetPosition(f1, 0, 0, -0.05);
      }
      dBodyID part = w.box(kPart, kPart, kPart, 1.0, 0, 0, kPart / 2 - kLayer);
      dGeomID f2 = dBodyGetFirstGeom(part);
      w.feeders->add(f1, MotionLaw::belt({1, 0, 0}, kBeltSpeed));
      w.feeders->add(f2, MotionLaw::translation(kPartSurface, Frame::Body));
      for (int i = 0; i < kFeederFeederSteps; ++i) {
        if (f1_is_g1) {
          w.stepPairs({{f1, f2}}, kStep, kMu);
        } else {
          w.stepPairs({{f2, f1}}, kStep, kMu);
        }
      }
      EXPECT_EQ(w.feeders->stats(f1).contacts_driven, 4);
      EXPECT_EQ(w.feeders->stats(f2).contacts_driven, 4);
      // c1 = belt, c2 = kPartSurface (the part does not turn: its frame is the world's).
      const Vec3 c1{kBeltSpeed, 0, 0};
      const Vec3 v2 = linearVelocity(part);
      const Vec3 relative = u - v2;  // v1 - v2
      EXPECT_NEAR(relative.x, kPartSurface.x - c1.x, kLcpTolerance);
      EXPECT_NEAR(relative.y, kPartSurface.y - c1.y, kLcpTolerance);
      EXPECT_NEAR(v2.z, u.z, kLcpTolerance);
      EXPECT_LT(norm(angularVelocity(part)), kLcpTolerance);
    }
  }
}

}  // namespace rheofeed::test
