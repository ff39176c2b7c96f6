// SPDX-License-Identifier: MIT
// A body taken out of the world (a part that left the scene) stays where it was, collides with
// nothing, and the bodies still in play go on as if it were not there.
#include <gtest/gtest.h>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kStep = 0.01;  // s

TEST(ReferenceDisable, DisabledBodyStaysAndOthersStillRestOnTheGround) {
  initOdeOnce();
  for (bool matrix_free : {false, true}) {
    SCOPED_TRACE(matrix_free ? "matrix-free" : "dense");
    Settings settings;
    settings.dense_contact_limit = matrix_free ? 0 : 100;
    World world(settings);
    dGeomID ground = dCreateBox(world.space(), 10, 10, 0.2);
    dGeomSetPosition(ground, 0, 0, -0.1);
    BodyState a, b;
    a.position = {0, 0, 0.05};
    b.position = {1, 0, 0.5};  // falling: disabled in mid-air
    const BoxBody resting = addBox(world, 1.0, {0.1, 0.1, 0.1}, a);
    const BoxBody gone = addBox(world, 2.0, {0.1, 0.1, 0.1}, b);
    world.step(kStep);
    world.disableBody(gone.id);
    const Vec3 frozen = world.state(gone.id).position;
    for (int i = 0; i < 100; ++i) world.step(kStep);
    // It does not fall further; the resting box is unaffected (rests on the ground top, z = 0).
    EXPECT_EQ(world.state(gone.id).position.z, frozen.z);
    EXPECT_NEAR(world.state(resting.id).position.z, 0.05, 1e-3);
    EXPECT_NEAR(world.state(resting.id).linear_velocity.z, 0.0, 1e-6);
  }
}

TEST(ReferenceDisable, RefusesAStaticOrUnknownBody) {
  initOdeOnce();
  World world;
  EXPECT_THROW(world.disableBody(0), std::invalid_argument);
  EXPECT_THROW(world.disableBody(kStatic), std::invalid_argument);
}

}  // namespace
}  // namespace rheofeed::reference::test
