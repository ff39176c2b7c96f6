// SPDX-License-Identifier: MIT
// The reduced stability matrix (issue 7 item 5): the quick cases of demos/stability (a few parts,
// a few thousand steps each) through every method they apply to. Each run is measured from the
// part states by the matrix's own code (not the engine's counters) against bounds from mechanics
// (demos/stability/stability_cases.hpp):
//  - no NaN or infinity anywhere in a part's state (position, velocity, angular velocity,
//    rotation), and the run finishes (or is refused, for the case built to be refused);
//  - no blow-up: the fastest part stays within the physical speed bound (fastest surface,
//    push-out cap and free fall) and the energy within the budget (initial energy plus what the
//    surfaces and the push-out can give), and the penetration at most a fifth of the part's
//    thinnest dimension - unless the scene check warned before the run that the scene is
//    beyond a known limit (tunnelling, a mass ratio the iterations cannot hold, parts spawned
//    into each other, a weak collider pair); then the verdict is "warned", and speeds beyond
//    three times the bound still fail (a blow-up is never a documented limit);
//  - every part that our measurement counts as lost (through a fixture, out of bounds,
//    removed, non-finite) is reported by Simulation::health().
#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <vector>

#include "stability/stability_cases.hpp"

namespace {

using namespace rheofeed;
using namespace rheofeed::stability;

struct QuickRun {
  StabilityCase kase;
  scene::Method method;
};

std::vector<QuickRun> quickRuns() {
  std::vector<QuickRun> out;
  for (const StabilityCase& c : stabilityCases()) {
    if (!c.quick) continue;
    for (scene::Method m : methodsFor(c)) out.push_back({c, m});
  }
  return out;
}

void PrintTo(const QuickRun& run, std::ostream* os) {
  *os << run.kase.name << " / " << scene::toString(run.method);
}

class StabilityMatrix : public testing::TestWithParam<QuickRun> {};

TEST_P(StabilityMatrix, StaysFiniteBoundedAndReportsEveryLostPart) {
  const QuickRun& run = GetParam();
  const Limits limits;  // the matrix's own pass/fail limits, reasons in stability_run.cpp
  const RunRecord r = runCase(run.kase, run.method, limits);
  SCOPED_TRACE(run.kase.name + " / " + r.method + ": " + run.kase.covers + " | " + r.cause);
  if (run.kase.expect_refusal) {
    EXPECT_EQ(r.status, "refused");
    return;
  }
  ASSERT_EQ(r.status, "finished") << r.message;
  EXPECT_EQ(r.nonfinite_parts, 0) << r.nonfinite_where;
  EXPECT_LE(r.lost_measured, r.lost_reported) << r.lost_how;
  // Penetration and energy stay within their physical bounds, unless the run is beyond a limit
  // of ODE or of the discrete step (tunnelling, a mass ratio the iterations cannot hold) that
  // the scene check named before the run: then it is a documented limit, not a silent failure.
  if (r.check_warnings == 0) {
    EXPECT_LE(r.max_speed, limits.speed_slack * r.speed_bound);
    EXPECT_LE(r.energy_ratio, limits.energy_slack) << "budget " << r.energy_budget << " J";
    EXPECT_LE(r.penetration_ratio, limits.penetration_ratio)
        << r.max_penetration << " m, " << r.penetration_where;
  }
  EXPECT_NE(r.verdict, "FAIL") << r.cause;
}

std::string runName(const testing::TestParamInfo<QuickRun>& info) {
  std::string name = info.param.kase.name + "_" + scene::toString(info.param.method);
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Quick, StabilityMatrix, testing::ValuesIn(quickRuns()), runName);

}  // namespace
