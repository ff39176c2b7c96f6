// SPDX-License-Identifier: MIT
// The ODE boundary: no exception crosses dSpaceCollide (ContactCollider keeps the first one and
// rethrows it after the pass), and ODE's own error, debug and warning messages become test
// failures (ode_message_guard.hpp, active around every test of this binary).
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {

// A box resting on a static floor, and a second one beside it: two colliding pairs.
struct TwoBoxesOnAFloor {
  TwoBoxesOnAFloor() {
    w.setSurface(dContactApprox1, 0.5);
    floor = w.staticBox(4, 4, 0.1, 0, 0, -0.05);
    left = w.box(0.1, 0.1, 0.1, 1.0, -0.5, 0, 0.05);
    right = w.box(0.1, 0.1, 0.1, 1.0, 0.5, 0, 0.05);
  }
  OdeWorld w;
  dGeomID floor;
  dBodyID left, right;
};

// The height of a resting 0.1 m box's centre (m): half its size, give or take ODE's
// penetration under ERP/CFM (under 1 mm for 1 kg at these settings, far from a fall through).
constexpr double kRestHeight = 0.05;
constexpr double kRestTolerance = 1e-3;

}  // namespace

// ---------------------------------------------------------------------------------------------
// Exceptions inside the near callback

TEST(ContactColliderExceptions, ThrowingSurfaceCallbackIsRethrownByCollideAfterThePass) {
  TwoBoxesOnAFloor scene;
  OdeWorld& w = scene.w;
  w.step(0.01);  // a good step first: joints and records exist
  int calls = 0;
  w.collider->setSurfaceCallback([&calls](dGeomID, dGeomID, dContact*, int) -> bool {
    ++calls;
    throw std::runtime_error("surface callback failed on call " + std::to_string(calls));
  });
  try {
    w.collider->collide(w.space, w.time, 0.01);
    ADD_FAILURE() << "collide did not rethrow";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "surface callback failed on call 1");
  }
  // The pass stopped at the first exception: the second pair was skipped, and no joint of the
  // failed pass is left in the world.
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(w.collider->contactCount(), 0);
  EXPECT_FALSE(w.collider->hasPendingError());

  // The world is usable at the next step: both boxes rest on the floor again.
  w.setSurface(dContactApprox1, 0.5);
  for (int i = 0; i < 50; ++i) w.step(0.01);
  EXPECT_GT(w.collider->contactCount(), 0);
  EXPECT_NEAR(position(scene.left).z, kRestHeight, kRestTolerance);
  EXPECT_NEAR(position(scene.right).z, kRestHeight, kRestTolerance);
}

TEST(ContactColliderExceptions, NonStandardExceptionIsRethrownToo) {
  TwoBoxesOnAFloor scene;
  scene.w.collider->setSurfaceCallback([](dGeomID, dGeomID, dContact*, int) -> bool { throw 7; });
  try {
    scene.w.collider->collide(scene.w.space, 0.0, 0.01);
    ADD_FAILURE() << "collide did not rethrow";
  } catch (int value) {
    EXPECT_EQ(value, 7);
  }
}

TEST(ContactColliderExceptions, FeederRecordsOfAFailedPassAreDropped) {
  FeederSet::Options options;
  options.record_contacts = true;
  OdeWorld w(options);
  w.setSurface(dContactApprox1, 0.5);
  dGeomID belt = w.staticBox(4, 4, 0.1, 0, 0, -0.05);
  w.box(0.1, 0.1, 0.1, 1.0, -0.5, 0, 0.05);
  w.box(0.1, 0.1, 0.1, 1.0, 0.5, 0, 0.05);
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, 0.3));
  w.step(0.01);
  ASSERT_FALSE(w.feeders->records().empty());
  int calls = 0;
  w.collider->setSurfaceCallback([&calls](dGeomID, dGeomID, dContact* c, int n) -> bool {
    // The first pair is driven and recorded; the second throws.
    if (++calls == 2) throw std::runtime_error("second pair");
    for (int i = 0; i < n; ++i) c[i].surface.mu = 0.5;
    return true;
  });
  EXPECT_THROW(w.collider->collide(w.space, w.time, 0.01), std::runtime_error);
  EXPECT_EQ(calls, 2);
  // No record points at a joint of the emptied group.
  EXPECT_TRUE(w.feeders->records().empty());
  EXPECT_EQ(w.collider->contactCount(), 0);
}

TEST(ContactColliderExceptions, ManualDSpaceCollideLeavesTheErrorPendingForTheApplication) {
  TwoBoxesOnAFloor scene;
  OdeWorld& w = scene.w;
  int calls = 0;
  w.collider->setSurfaceCallback([&calls](dGeomID, dGeomID, dContact*, int) -> bool {
    ++calls;
    throw std::logic_error("manual pass");
  });
  w.collider->clearJoints();
  w.feeders->beginStep(0.0, 0.01);
  dSpaceCollide(w.space, w.collider.get(), &ContactCollider::nearCallback);  // no throw here
  EXPECT_EQ(calls, 1);
  ASSERT_TRUE(w.collider->hasPendingError());
  EXPECT_THROW(w.collider->rethrowPendingError(), std::logic_error);
  EXPECT_FALSE(w.collider->hasPendingError());
  w.collider->rethrowPendingError();  // nothing pending: no-op

  // Left pending, the error is thrown by the next collide before it does anything.
  dSpaceCollide(w.space, w.collider.get(), &ContactCollider::nearCallback);
  ASSERT_TRUE(w.collider->hasPendingError());
  const int calls_before = calls;
  EXPECT_THROW(w.collider->collide(w.space, 0.01, 0.01), std::logic_error);
  EXPECT_EQ(calls, calls_before);
  EXPECT_EQ(w.feeders->time(), 0.0);  // beginStep was not called
}

TEST(ContactColliderExceptions, ThrowingFieldInsideThePassLeavesContactsUndrivenButJointed) {
  // The field is called by FeederSet::driveContacts (noexcept): its exception is caught there,
  // the contact keeps its normal row, and the box rests instead of being driven.
  OdeWorld w;
  w.setSurface(dContactApprox1, 0.5);
  dGeomID table = w.staticBox(4, 4, 0.1, 0, 0, -0.05);
  dBodyID part = w.box(0.1, 0.1, 0.1, 1.0, 0, 0, 0.05);
  std::vector<Diagnostic> seen;
  w.feeders->setDiagnosticHandler([&seen](const Diagnostic& d) { seen.push_back(d); });
  w.feeders->add(table, MotionLaw::field([](const Vec3&, const Vec3&, double) -> Vec3 {
                   throw std::runtime_error("field failed");
                 }));
  std::uint64_t contacts = 0;
  for (int i = 0; i < 50; ++i) {
    ASSERT_NO_THROW(w.step(0.01));
    contacts += static_cast<std::uint64_t>(w.collider->contactCount());
  }
  EXPECT_GT(contacts, 0u);
  EXPECT_EQ(w.feeders->stats(table).law_threw, contacts);
  EXPECT_EQ(seen.size(), contacts);
  EXPECT_NEAR(position(part).z, kRestHeight, kRestTolerance);
  EXPECT_LT(norm(linearVelocity(part)), 1e-3);  // not driven: it rests
}

// ---------------------------------------------------------------------------------------------
// ODE's own messages

TEST(OdeMessages, WarningIsATestFailureUnderTheDefaultGuard) {
  // dMessage is ODE's warning; the guard that every test of this binary runs under turns it
  // into a non-fatal failure naming the text.
  EXPECT_NONFATAL_FAILURE(dMessage(3, "LCP internal error, s <= 0 (s=%.4e)", -1.5),
                          "ODE message 3: LCP internal error, s <= 0 (s=-1.5000e+00)");
}

TEST(OdeMessages, RecordingGuardCollectsARealOdeWarningAndRestoresTheHandlers) {
  dMessageFunction* outer_message = dGetMessageHandler();
  dMessageFunction* outer_debug = dGetDebugHandler();
  dMessageFunction* outer_error = dGetErrorHandler();
  {
    OdeMessageGuard guard(OdeMessageGuard::Policy::Record);
    dMass mass;
    dMassSetZero(&mass);  // mass 0: ODE's dMassCheck warns "mass must be > 0"
    EXPECT_EQ(dMassCheck(&mass), 0);
    ASSERT_EQ(guard.messages().size(), 1u);
    EXPECT_EQ(guard.messages()[0].kind, OdeMessageGuard::Kind::Message);
    EXPECT_NE(guard.messages()[0].text.find("mass must be > 0"), std::string::npos)
        << guard.messages()[0].text;
  }
  EXPECT_EQ(dGetMessageHandler(), outer_message);
  EXPECT_EQ(dGetDebugHandler(), outer_debug);
  EXPECT_EQ(dGetErrorHandler(), outer_error);
}

TEST(OdeMessagesDeathTest, ArgumentAssertionIsNamedWithTheTestBeforeOdeAborts) {
  // ODE's dDebug aborts after the handler returns (ode/src/error.cpp); the guard prints the
  // message and the test's name first. A null body is one of ODE's argument assertions.
  EXPECT_DEATH(dBodySetPosition(nullptr, 0, 0, 0),
               "ODE internal error \\(debug\\) 2 in "
               "OdeMessagesDeathTest.ArgumentAssertionIsNamedWithTheTestBeforeOdeAborts: Bad "
               "argument\\(s\\) in dBodySetPosition");
}

TEST(OdeMessagesDeathTest, ErrorIsNamedBeforeOdeExitsWithCodeOne) {
  EXPECT_EXIT(dError(9, "out of %s", "memory"), testing::ExitedWithCode(1),
              "ODE error 9 in OdeMessagesDeathTest.ErrorIsNamedBeforeOdeExitsWithCodeOne: out of "
              "memory");
}

}  // namespace rheofeed::test
