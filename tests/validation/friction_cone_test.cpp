// SPDX-License-Identifier: MIT
// ODE full vibration with the friction cone of the patched ODE (patches/0002) against the
// reference engine, whose contact law is the true Coulomb cone, on the drift-model study's
// 5 degree cross slope (tiltedTrackScene: 0.2 mm at 20 degrees, 50 Hz, mu 0.4, one flat part,
// gravity turned 5 degrees towards -y). With ODE's pyramid the sideways row keeps its full
// capacity while the part slides forward, and the part does not creep downhill at all; with
// the cone it must creep as the reference engine's part does.
//
// Judge: the reference engine's full vibration at 1000 steps per cycle (NOTES section 4: ~0.1 %
// discretisation error for one part). ODE runs quickstep (100 sweeps) at 1000 steps per cycle
// with the scene's other solver settings; only solver.friction differs between its two runs.
#include <gtest/gtest.h>
#include <ode/ode.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>

#include "common/builtin_scenes.hpp"
#include "rheofeed/friction_model.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {
namespace {

constexpr int kStepsPerCycle = 1000;
// Quickstep sweeps of the ODE runs: one box on four corner contacts converges well within them.
constexpr int kSweeps = 100;
// Issue 15's goal: ODE full vibration with the cone within 5 % of the reference cone on the
// sideways creep of the 5 degree cross slope; the same bound along the track.
constexpr double kConeTolerance = 0.05;
// The pyramid's sideways creep measured 0 (drift_models_tracks: -3e-8 m/s against -5.5e-3):
// anything under a tenth of the reference's shows the defect.
constexpr double kPyramidCreepShare = 0.1;

double drift(Scene s, Method method, std::optional<FrictionModel> friction = std::nullopt) {
  static const bool initialised = (dInitODE2(0), true);  // the reference collides through ODE
  (void)initialised;
  s.solver.time_step = 1.0 / (50.0 * kStepsPerCycle);
  if (method == Method::OdeFullVibration) {
    // The track scene steps ODE with dWorldStep (Dantzig), which cannot solve the cone: both
    // ODE runs take quickstep with converged sweeps instead, and differ only in the friction.
    s.solver.ode_quickstep = true;
    s.solver.iterations = kSweeps;
    s.solver.friction = friction;
  }
  const RunMetrics m = measureRun(s, method);
  EXPECT_EQ(m.health.partsLost(), 0) << s.name;
  EXPECT_EQ(m.health.friction_model,
            method == Method::ReferenceFullVibration ? "cone" : toString(*friction));
  return m.mean_drift;
}

TEST(FrictionCone, CrossSlopeCreepOfOdeFullVibrationMatchesTheReferenceCone) {
  if (!odeHasFrictionCone()) {
    GTEST_SKIP() << "linked with a stock ODE (RHEOFEED_ODE=system): no friction cone";
  }
  const Scene sideways = tiltedTrackScene(0, 5, true, false);
  const double reference = drift(sideways, Method::ReferenceFullVibration);
  const double cone = drift(sideways, Method::OdeFullVibration, FrictionModel::Cone);
  const double pyramid = drift(sideways, Method::OdeFullVibration, FrictionModel::Pyramid);
  const Scene along = tiltedTrackScene(0, 5, false, false);
  const double reference_along = drift(along, Method::ReferenceFullVibration);
  const double cone_along = drift(along, Method::OdeFullVibration, FrictionModel::Cone);
  std::printf(
      "[ numbers  ] 5 deg cross slope, sideways (+y uphill): reference %+.4f mm/s, ODE cone "
      "%+.4f mm/s (%+.2f %%), ODE pyramid %+.4f mm/s; along: reference %+.4f mm/s, ODE cone "
      "%+.4f mm/s (%+.2f %%)\n",
      1e3 * reference, 1e3 * cone, 100 * (cone - reference) / std::abs(reference), 1e3 * pyramid,
      1e3 * reference_along, 1e3 * cone_along,
      100 * (cone_along - reference_along) / std::abs(reference_along));
  EXPECT_LT(reference, 0) << "the vibrated part creeps downhill (-y)";
  EXPECT_NEAR(cone, reference, kConeTolerance * std::abs(reference));
  EXPECT_NEAR(cone_along, reference_along, kConeTolerance * std::abs(reference_along));
  EXPECT_LT(std::abs(pyramid), kPyramidCreepShare * std::abs(reference));
}

TEST(FrictionCone, SceneDefaultIsTheConeWhereOdeHasItAndThePyramidWithDantzig) {
  SolverSettings s;
  EXPECT_EQ(odeFrictionModel(s),
            odeHasFrictionCone() ? FrictionModel::Cone : FrictionModel::Pyramid);
  s.ode_quickstep = false;
  EXPECT_EQ(odeFrictionModel(s), FrictionModel::Pyramid);
  s.friction = FrictionModel::Cone;
  EXPECT_THROW(odeFrictionModel(s), std::invalid_argument);
  s.ode_quickstep = true;
  if (odeHasFrictionCone()) {
    EXPECT_EQ(odeFrictionModel(s), FrictionModel::Cone);
  } else {
    try {
      odeFrictionModel(s);
      ADD_FAILURE() << "the cone was accepted on a stock ODE";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("solver.friction"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace rheofeed::scene
