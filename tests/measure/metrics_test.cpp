// SPDX-License-Identifier: MIT
// metrics.cpp's rule of whether a run has an answer (runAnswer): no part measured, or more of
// the spawned parts lost than the run's bound. The runs are RunMetrics filled by hand with
// counts whose share against the bound is known by arithmetic (1 of 10 is exactly a tenth), so
// the expectations do not come from the code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "rheofeed/measure/metrics.hpp"

namespace rheofeed::scene {
namespace {

// A run of `parts` parts of which `fell` fell (RunHealth::parts_fell) and the others were
// measured.
RunMetrics lossyRun(int parts, int fell) {
  RunMetrics r;
  r.parts = parts;
  r.health.parts_fell = fell;
  r.drift_parts = parts - fell;
  return r;
}

TEST(RunAnswer, TheDefaultBoundIsATenth) {
  EXPECT_EQ(RunMetrics().max_lost_fraction, 0.1);
  EXPECT_EQ(kDefaultMaxLostFraction, 0.1);
}

TEST(RunAnswer, NothingLostIsAnAnswer) {
  const RunAnswer a = runAnswer(lossyRun(10, 0));
  EXPECT_TRUE(a.trusted);
  EXPECT_TRUE(a.why.empty());
}

// "More than" the bound: a tenth lost at a bound of a tenth is still an answer.
TEST(RunAnswer, LossAtTheBoundIsAnAnswer) {
  EXPECT_TRUE(runAnswer(lossyRun(10, 1)).trusted);
}

TEST(RunAnswer, LossBeyondTheBoundIsNoAnswerAndSaysHowMany) {
  const RunAnswer a = runAnswer(lossyRun(10, 2));
  EXPECT_FALSE(a.trusted);
  EXPECT_EQ(a.why,
            std::vector<std::string>{"lost 2 of 10 parts (20 %), more than max_lost_fraction 0.1"});
}

// The bound is compared with the share, not the share's count: 0.57 x 100 is
// 56.99999999999999 in doubles, and 57 parts of 100 are not more than 0.57 of them.
TEST(RunAnswer, TheBoundIsAShareOfTheSpawnedParts) {
  ASSERT_LT(0.57 * 100, 57.0);  // the rounding the rule must not fall into
  RunMetrics at = lossyRun(100, 57), beyond = lossyRun(100, 58);
  at.max_lost_fraction = beyond.max_lost_fraction = 0.57;
  EXPECT_TRUE(runAnswer(at).trusted);
  EXPECT_FALSE(runAnswer(beyond).trusted);
}

// Every kind of loss counts (RunHealth::partsLost): parts inside a fixture at the end too.
TEST(RunAnswer, PartsInsideAFixtureAtTheEndCountAsLost) {
  RunMetrics r = lossyRun(10, 0);
  r.health.parts_inside_fixture = 2;
  r.drift_parts = 8;
  EXPECT_FALSE(runAnswer(r).trusted);
}

TEST(RunAnswer, BoundOneAcceptsAnyLossThatLeavesAMeasurement) {
  RunMetrics r = lossyRun(4, 3);
  r.max_lost_fraction = 1;
  EXPECT_TRUE(runAnswer(r).trusted);
}

TEST(RunAnswer, BoundZeroAcceptsNoLoss) {
  RunMetrics r = lossyRun(100, 1);
  r.max_lost_fraction = 0;
  EXPECT_FALSE(runAnswer(r).trusted);
  r.health.parts_fell = 0;
  EXPECT_TRUE(runAnswer(r).trusted);
}

// Every part lost: one reason, whatever the bound (not the share again).
TEST(RunAnswer, EveryPartLostIsNoAnswerWhateverTheBound) {
  RunMetrics r = lossyRun(2, 2);
  r.max_lost_fraction = 1;
  const RunAnswer a = runAnswer(r);
  EXPECT_FALSE(a.trusted);
  EXPECT_EQ(a.why, std::vector<std::string>{"lost all 2 parts it spawned"});
}

TEST(RunAnswer, NoPartSpawnedIsNoAnswer) {
  const RunAnswer a = runAnswer(lossyRun(0, 0));
  EXPECT_FALSE(a.trusted);
  EXPECT_EQ(a.why, std::vector<std::string>{"spawned no part"});
}

TEST(RunAnswer, NoPartMeasuredNorExitedIsNoAnswer) {
  RunMetrics r = lossyRun(2, 0);
  r.drift_parts = 0;
  r.feeder.spawned_beyond_exit = 2;
  const RunAnswer a = runAnswer(r);
  EXPECT_FALSE(a.trusted);
  EXPECT_EQ(a.why, std::vector<std::string>{
                       "measured none of its 2 parts (0 lost, 2 spawned beyond the exit plane)"});
  // ... while parts that crossed the exit are an answer (its throughput) with none measured.
  r.feeder.exit_times = {0.5};
  EXPECT_TRUE(runAnswer(r).trusted);
}

// A caller names the bound as its user knows it (a command's option).
TEST(RunAnswer, TheReasonNamesTheBoundAsTheCallerSays) {
  const RunAnswer a = runAnswer(lossyRun(3, 1), "--max-lost-fraction");
  ASSERT_EQ(a.why.size(), 1u);
  EXPECT_EQ(a.why[0], "lost 1 of 3 parts (33.3 %), more than --max-lost-fraction 0.1");
}

// A bound that is not a share judges nothing: no answer rather than a silent pass.
TEST(RunAnswer, ABoundOutsideZeroToOneJudgesNothing) {
  for (const double bound : {std::nan(""), -0.1, 2.0}) {
    RunMetrics r = lossyRun(10, 0);
    r.max_lost_fraction = bound;
    const RunAnswer a = runAnswer(r);
    EXPECT_FALSE(a.trusted) << bound;
    ASSERT_EQ(a.why.size(), 1u) << bound;
    EXPECT_NE(a.why[0].find("is not in [0, 1]"), std::string::npos) << a.why[0];
  }
}

}  // namespace
}  // namespace rheofeed::scene
