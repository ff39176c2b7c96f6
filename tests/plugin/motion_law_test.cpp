// SPDX-License-Identifier: MIT
#include "rheofeed/motion_law.hpp"

#include <gtest/gtest.h>

namespace rheofeed {
TEST(MotionLaw, TurntableFollowsRightHandRule) {
  const StepLaw law = MotionLaw::rotation({0, 0, 2.0}, {0, 0, 0}).evaluate(0, nullptr);
  const Vec3 c = law.tangentialVelocity({0.5, 0, 0}, {0, 0, 1});
  EXPECT_NEAR(c.x, 0.0, 1e-15);
  EXPECT_NEAR(c.y, 1.0, 1e-15);  // w x r = (0,0,2) x (0.5,0,0) = (0,1,0)
}
}  // namespace rheofeed
