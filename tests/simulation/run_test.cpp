// SPDX-License-Identifier: MIT
// run.cpp: the run loop calls its observers in the order run.hpp documents - onStart once at
// t = 0, onStep after every step with the sample flag every sample_every steps, onEnd once -
// and runSchedule rounds duration / h and sample_interval / h as documented.
#include "rheofeed/simulation/run.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

// Times are sums of k steps of h: a few ulps of rounding.
constexpr double kTimeRounding = 1e-12;  // s

// Records every call it gets, in one log shared by all observers.
class Recorder : public RunObserver {
 public:
  Recorder(std::string name, std::vector<std::string>& log) : name_(std::move(name)), log_(log) {}
  void onStart(const Simulation& sim) override {
    ++starts;
    start_time = sim.time();
    log_.push_back(name_ + " start");
  }
  void onStep(const Simulation& sim, long step, bool sample) override {
    steps.push_back(step);
    times.push_back(sim.time());
    if (sample) samples.push_back(step);
    log_.push_back(name_ + " step " + std::to_string(step));
  }
  void onEnd(const Simulation& sim) override {
    ++ends;
    end_time = sim.time();
    log_.push_back(name_ + " end");
  }
  int starts = 0, ends = 0;
  double start_time = -1, end_time = -1;
  std::vector<long> steps, samples;
  std::vector<double> times;

 private:
  std::string name_;
  std::vector<std::string>& log_;
};

Scene cubeOnFloor(double h, double duration, double sample_interval) {
  Scene s = test::cubeOnFloor("run loop", h, duration);
  s.outputs.sample_interval = sample_interval;
  return s;
}

TEST(RunSchedule, StepsAndSampleEveryAreRoundedQuotients) {
  // Binary fractions, so that the quotients are exact: 2.5 rounds to 3, 1.5 to 2.
  EXPECT_EQ(runSchedule(cubeOnFloor(0.25, 0.625, 0.375)).steps, 3);
  EXPECT_EQ(runSchedule(cubeOnFloor(0.25, 0.625, 0.375)).sample_every, 2);
  // 10 steps of 1/64 s; a sample every 4 steps (1/16 s).
  const RunSchedule s = runSchedule(cubeOnFloor(1.0 / 64, 10.0 / 64, 1.0 / 16));
  EXPECT_EQ(s.steps, 10);
  EXPECT_EQ(s.sample_every, 4);
  // A sample interval shorter than half a step still samples every step.
  EXPECT_EQ(runSchedule(cubeOnFloor(0.25, 1.0, 0.0625)).sample_every, 1);
}

TEST(RunSimulation, CallsEveryObserverInOrderOnceAtStartEveryStepAndOnceAtTheEnd) {
  const double h = 1.0 / 64;
  const Scene scene = cubeOnFloor(h, 10 * h, 4 * h);
  const RunSchedule schedule = runSchedule(scene);
  ASSERT_EQ(schedule.steps, 10);
  ASSERT_EQ(schedule.sample_every, 4);
  for (Method m : {Method::OdeRheonomic, Method::ReferenceRheonomic}) {
    SCOPED_TRACE(toString(m));
    std::vector<std::string> log;
    Recorder first("a", log), second("b", log);
    std::vector<double> progress;
    std::unique_ptr<Simulation> sim = makeSimulation(scene, m);
    runSimulation(*sim, schedule, {&first, nullptr, &second},
                  [&](double f) { progress.push_back(f); });
    for (const Recorder* r : {&first, &second}) {
      EXPECT_EQ(r->starts, 1);
      EXPECT_EQ(r->ends, 1);
      EXPECT_EQ(r->start_time, 0.0);
      EXPECT_NEAR(r->end_time, 10 * h, kTimeRounding);
      ASSERT_EQ(r->steps.size(), 10u);
      for (long k = 1; k <= 10; ++k) {
        EXPECT_EQ(r->steps[static_cast<std::size_t>(k - 1)], k);
        EXPECT_NEAR(r->times[static_cast<std::size_t>(k - 1)], k * h, kTimeRounding);
      }
      EXPECT_EQ(r->samples, (std::vector<long>{4, 8}));
    }
    // Order: both starts, then for each step a before b, then both ends.
    std::vector<std::string> expected = {"a start", "b start"};
    for (int k = 1; k <= 10; ++k) {
      expected.push_back("a step " + std::to_string(k));
      expected.push_back("b step " + std::to_string(k));
    }
    expected.push_back("a end");
    expected.push_back("b end");
    EXPECT_EQ(log, expected);
    // Progress rises to 1.0, which comes last.
    ASSERT_FALSE(progress.empty());
    EXPECT_EQ(progress.back(), 1.0);
    for (std::size_t k = 1; k < progress.size(); ++k) EXPECT_GE(progress[k], progress[k - 1]);
  }
}

TEST(RunSimulation, ZeroStepsStillStartsAndEndsEveryObserver) {
  const Scene scene = cubeOnFloor(0.01, 0.1, 0.01);
  std::vector<std::string> log;
  Recorder r("a", log);
  std::unique_ptr<Simulation> sim = makeSimulation(scene, Method::OdeRheonomic);
  runSimulation(*sim, RunSchedule{0, 1}, {&r});
  EXPECT_EQ(log, (std::vector<std::string>{"a start", "a end"}));
}

TEST(HealthSummary, NamesEveryLossByKindAndSaysNothingLostOtherwise) {
  RunHealth h;
  EXPECT_EQ(healthSummary(h, 10), "nothing lost");
  h.steps = 200;
  h.parts_fell = 2;
  h.parts_through_fixture = 1;
  h.coulomb_fallback_steps = 50;
  EXPECT_EQ(healthSummary(h, 60),
            "3 of 60 parts lost (fell 2, through a fixture 1); 50 of 200 steps used the Coulomb "
            "fallback (25 %)");
}

}  // namespace
}  // namespace rheofeed::scene
