// SPDX-License-Identifier: MIT
// Full-vibration runs against the classical single-part theory (NOTES section 5).
//
// One flat part (a 20 x 20 x 5 mm box) rests on a straight track (a static box fixture whose
// law is a Vibration: x(t) = A sin(2 pi f t) along (cos beta, 0, sin beta)). The scene runs with
// Method::OdeFullVibration (dWorldStep) and Method::ReferenceFullVibration (cone
// complementarity), 400 steps per cycle; the mean conveying speed over whole cycles after a
// warm-up is compared with classicalDrift(), which integrates the theory in closed form and uses
// neither ODE nor the CCP solver. An inclined track (alpha) is represented by tilting gravity:
// g = (-g sin alpha, 0, -g cos alpha) makes +x climb by alpha relative to the track; it is the
// same physics and keeps the geometry axis-aligned.
//
// What is checked: no conveying below the forward onset Gamma_f, conveying above it; the mean
// speed in the sliding regimes; 1/f scaling at fixed throw number; independence of the part's
// mass; and the speed and time in flight when hopping. The reference solver runs its true
// Coulomb mode; its convex relaxation of the cone is measured separately (last test).
#include <gtest/gtest.h>
#include <ode/ode.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <ostream>
#include <string>
#include <tuple>
#include <utility>

#include "rheofeed/measure/classical_model.hpp"
#include "rheofeed/simulation/simulation.hpp"
#include "scene_builders.hpp"

namespace rheofeed::scene {

// Readable test names in ctest (gtest_discover_tests prints the parameters).
void PrintTo(Method method, std::ostream* os) {
  *os << toString(method);
}

namespace {

constexpr double kDeg = kPi / 180;
constexpr double kG = 9.81;

// Time step: NOTES section 4 quotes a few percent of drift error at ~250 steps per cycle and
// 1-2 % at 1000 for piles; for one part, 400 steps per cycle measured <= 0.28 % (200: 0.8 %).
constexpr int kStepsPerCycle = 400;
// The sliding regimes reach their periodic state within a cycle or two (the model's period is
// found after 1-13 cycles); 10 cycles of warm-up, then 40 measured cycles.
constexpr int kWarmupCycles = 10;
constexpr int kMeasuredCycles = 40;

// Both engines: the remaining error is the time discretisation of the stick/slip and
// lift-off/landing events at 400 steps per cycle; measured <= 0.28 % in the sliding regimes and
// 0.6 % when hopping (Gamma 1.5). The reference solver runs in its true-Coulomb mode and then
// gives ODE's numbers to 4-5 digits (same contacts, same time discretisation).
constexpr double kSpeedTolerance = 0.005;          // relative, sliding
constexpr double kHopSpeedTolerance = 0.01;        // relative, hopping (Gamma <= 1.5)
constexpr double kFlightFractionTolerance = 0.01;  // of the cycle: 4 steps in 400
// A speed below this is "not conveying" (m/s): 0.02 mm/s, 2.5e-3 of the smallest peak
// tangential track speed used here (8 mm/s); below the onset both engines measured < 1e-7 m/s.
// It also floors the relative tolerances near the onset, where the model's speed tends to 0.
constexpr double kStillSpeed = 2e-5;
// The planar theory needs the part to stay flat and on its line. Tilt of its z axis (rad):
// both engines keep the symmetric box exactly flat (measured 0).
constexpr double kMaxTilt = 1e-6;
// Sideways drift (m): nothing drives y; measured below 1e-16 m in both.
constexpr double kMaxSideways = 1e-6;

struct TrackCase {
  std::string name;
  double gamma = 0.5;                  // throw number
  double track_angle = 0;              // alpha (rad), > 0: +x climbs
  double vibration_angle = 30 * kDeg;  // beta (rad)
  double mu = 0.5;
  double frequency = 50;  // (Hz)
  double density = 1000;  // (kg/m^3): a 2 g part
};

ClassicalParams modelParams(const TrackCase& c) {
  ClassicalParams p;
  p.track_angle = c.track_angle;
  p.vibration_angle = c.vibration_angle;
  p.mu = c.mu;
  p.frequency = c.frequency;
  p.gravity = kG;
  p.amplitude = amplitudeForThrowNumber(p, c.gamma);
  return p;
}

constexpr double kPartX = 0.02, kPartY = 0.02, kPartZ = 0.005;  // (m)

Scene trackScene(const TrackCase& c) {
  const ClassicalParams p = modelParams(c);
  const double w = 2 * kPi * c.frequency, beta = c.vibration_angle;
  Scene s;
  s.name = "vibrating_track_" + c.name;
  s.gravity = {-kG * std::sin(c.track_angle), 0, -kG * std::cos(c.track_angle)};

  s.fixtures.push_back(test::vibratingBox("track", {0.4, 0.1, 0.02}, {0, 0, 0},  // top at z = 0
                                          p.amplitude, c.frequency,
                                          {std::cos(beta), 0, std::sin(beta)}));

  PartSpec part;
  part.name = "flat_box";
  part.shape = Shape::Kind::Box;
  part.size[0].mean = kPartX;
  part.size[1].mean = kPartY;
  part.size[2].mean = kPartZ;
  part.density = c.density;
  part.spawn_min = part.spawn_max = {0, 0, 0.5 * kPartZ};  // resting on the track
  part.count = 1;
  // Moving with the track at t = 0 (phase 0: displacement 0, velocity A w along the direction).
  part.initial_velocity = {p.amplitude * w * std::cos(beta), 0, p.amplitude * w * std::sin(beta)};
  s.parts.push_back(part);

  s.material.mu = c.mu;
  s.material.restitution = 0;  // the theory's landing is plastic
  s.solver.time_step = 1.0 / (c.frequency * kStepsPerCycle);
  s.solver.ode_quickstep = false;  // dWorldStep (Dantzig)
  // ODE's default ERP and CFM: with CFM 0 or 1e-9 Dantzig reports "LCP internal error" on the
  // four coplanar corner contacts (rank-deficient rows); 1e-5 leaves a contact compliance
  // whose effect on the speed was below 1e-5 relative between a 2 g and a 20 g part.
  s.solver.erp = 0.2;
  s.solver.cfm = 1e-5;
  // CCP: converged solves. With 1e-6 and 50-100 iterations sticking is not exact and the part
  // creeps at ~0.01 mm/s below the onset (measured with the relaxed cone).
  s.solver.iterations = 1000;
  s.solver.tolerance = 1e-10;
  s.solver.apgd = true;
  // True Coulomb friction (outer fixed point), as the theory; 0 would solve the relaxed cone
  // (see ReferenceCone below).
  s.solver.coulomb_iterations = 20;
  s.duration = (kWarmupCycles + kMeasuredCycles) / c.frequency;
  s.outputs.conveying_direction = {1, 0, 0};
  return s;
}

struct Measured {
  double speed = 0;                // mean speed along +x over the measured cycles (m/s)
  double no_contact_fraction = 0;  // steps without a part-track contact (measured cycles)
  double tilt = 0;                 // largest angle of the part's z axis from the vertical (rad)
  double sideways = 0;             // largest |y| (m)
  double seconds = 0;              // wall time of the run
};

// ODE must be initialised before any collision call. OdeSimulation does it itself, but a
// ReferenceFullVibration run (collision through ODE too) does not: a reference test run on its
// own (ctest runs each test in its own process) aborts with "Please call ODE initialization".
void initOde() {
  static const bool initialised = (dInitODE2(0), true);
  (void)initialised;
}

Measured run(const Scene& scene, Method method) {
  initOde();
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<Simulation> sim = makeSimulation(scene, method);
  const int warm = kWarmupCycles * kStepsPerCycle;
  const int total = (kWarmupCycles + kMeasuredCycles) * kStepsPerCycle;
  Measured m;
  double x0 = 0;
  int free_steps = 0;
  for (int k = 1; k <= total; ++k) {
    sim->step();
    if (k == warm) x0 = sim->part(0).position.x;
    if (k <= warm) continue;
    if (sim->contactTotals().count == 0) ++free_steps;
    const PartState s = sim->part(0);
    m.tilt = std::max(m.tilt, std::acos(std::min(1.0, s.rotation[8])));
    m.sideways = std::max(m.sideways, std::abs(s.position.y));
  }
  const double frequency = scene.fixtures[0].law.vibration.frequency;
  m.speed = (sim->part(0).position.x - x0) * frequency / kMeasuredCycles;
  m.no_contact_fraction = static_cast<double>(free_steps) / (total - warm);
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return m;
}

double speedTolerance(double model_speed) {
  return std::max(kSpeedTolerance * std::abs(model_speed), kStillSpeed);
}

void report(const std::string& name, Method method, const ClassicalDrift& d, const Measured& m) {
  std::printf(
      "[ numbers  ] %-22s %-25s model %9.4f mm/s (%s)  sim %9.4f mm/s  diff %+7.2f %%  "
      "no-contact %.3f  tilt %.1e rad  %.2f s\n",
      name.c_str(), toString(method), d.mean_speed * 1e3, toString(d.regime), m.speed * 1e3,
      d.mean_speed != 0 ? 100 * (m.speed - d.mean_speed) / std::abs(d.mean_speed) : 0.0,
      m.no_contact_fraction, m.tilt, m.seconds);
}

void expectFlatAndStraight(const Measured& m) {
  EXPECT_LT(m.tilt, kMaxTilt);
  EXPECT_LT(m.sideways, kMaxSideways);
}

// ---------------------------------------------------------------------------------------------
// Mean speed in the sliding regimes (Gamma < 1), both methods.

struct SlidingCase {
  TrackCase track;
  ClassicalRegime regime;  // what the case is meant to exercise (checked against the model)
};

void PrintTo(const SlidingCase& c, std::ostream* os) {
  *os << c.track.name;
}

std::string caseName(const testing::TestParamInfo<std::tuple<SlidingCase, Method>>& info) {
  return std::get<0>(info.param).track.name + "_" + toString(std::get<1>(info.param));
}

class SlidingSpeed : public testing::TestWithParam<std::tuple<SlidingCase, Method>> {};

TEST_P(SlidingSpeed, MatchesClassicalModel) {
  const auto& [c, method] = GetParam();
  const ClassicalDrift d = classicalDrift(modelParams(c.track));
  ASSERT_EQ(d.regime, c.regime) << "the case does not exercise the regime it names";
  const Measured m = run(trackScene(c.track), method);
  report(c.track.name, method, d, m);
  EXPECT_NEAR(m.speed, d.mean_speed, speedTolerance(d.mean_speed));
  if (d.mean_speed != 0) {
    EXPECT_GT(m.speed * d.mean_speed, 0.0) << "conveys the wrong way";
  }
  expectFlatAndStraight(m);
  EXPECT_EQ(m.no_contact_fraction, 0.0);
}

TrackCase trackCase(std::string name, double gamma, double alpha = 0, double beta = 30 * kDeg,
                    double mu = 0.5) {
  TrackCase c;
  c.name = std::move(name);
  c.gamma = gamma;
  c.track_angle = alpha;
  c.vibration_angle = beta;
  c.mu = mu;
  return c;
}

// beta = 30 deg, mu = 0.5: Gamma_f = 0.224, Gamma_b = 0.406.
const SlidingCase kSlidingCases[] = {
    {trackCase("Forward_G030", 0.30), ClassicalRegime::ForwardSliding},
    {trackCase("ForwardBackward_G045", 0.45), ClassicalRegime::ForwardBackwardSliding},
    {trackCase("ForwardBackward_G060", 0.60), ClassicalRegime::ForwardBackwardSliding},
    {trackCase("ForwardBackward_G080", 0.80), ClassicalRegime::ForwardBackwardSliding},
    // Climbing 3 deg: Gamma_f = 0.248, Gamma_b = 0.363.
    {trackCase("Incline3deg_G060", 0.60, 3 * kDeg), ClassicalRegime::ForwardBackwardSliding},
    // Climbing 15 deg: Gamma_b = 0.188 < Gamma_f = 0.344: the part slides down the track.
    {trackCase("Incline15deg_G030", 0.30, 15 * kDeg), ClassicalRegime::BackwardSliding},
    // beta = 20 deg, mu = 0.3: Gamma_f = 0.098, Gamma_b = 0.123.
    {trackCase("Beta20Mu03_G050", 0.50, 0, 20 * kDeg, 0.3),
     ClassicalRegime::ForwardBackwardSliding},
};

INSTANTIATE_TEST_SUITE_P(FullVibration, SlidingSpeed,
                         testing::Combine(testing::ValuesIn(kSlidingCases),
                                          testing::Values(Method::OdeFullVibration,
                                                          Method::ReferenceFullVibration)),
                         caseName);

// ---------------------------------------------------------------------------------------------
// Onset of conveying at Gamma_f.

class Onset : public testing::TestWithParam<Method> {};

TEST_P(Onset, NoConveyingBelowForwardOnsetConveyingAbove) {
  const Method method = GetParam();
  for (double alpha : {0.0, 3 * kDeg}) {
    TrackCase c = trackCase("onset", 0.5, alpha);
    const double gamma_f = forwardOnsetThrowNumber(modelParams(c));
    SCOPED_TRACE("alpha " + std::to_string(alpha) + " Gamma_f " + std::to_string(gamma_f));

    c.gamma = 0.9 * gamma_f;
    c.name = alpha == 0 ? "Below_Gf" : "Below_Gf_incl3";
    const ClassicalDrift still = classicalDrift(modelParams(c));
    ASSERT_EQ(still.regime, ClassicalRegime::NoMotion);
    const Measured below = run(trackScene(c), method);
    report(c.name, method, still, below);
    EXPECT_LT(std::abs(below.speed), kStillSpeed);

    c.gamma = 1.25 * gamma_f;
    c.name = alpha == 0 ? "Above_Gf" : "Above_Gf_incl3";
    const ClassicalDrift moving = classicalDrift(modelParams(c));
    ASSERT_EQ(moving.regime, ClassicalRegime::ForwardSliding);
    ASSERT_GT(moving.mean_speed, 10 * kStillSpeed);
    const Measured above = run(trackScene(c), method);
    report(c.name, method, moving, above);
    EXPECT_GT(above.speed, 10 * kStillSpeed);
    EXPECT_NEAR(above.speed, moving.mean_speed, speedTolerance(moving.mean_speed));
  }
}

// ---------------------------------------------------------------------------------------------
// Scaling laws of the theory, checked on the simulations alone (the model only picks the
// amplitude for the throw number).

class Scaling : public testing::TestWithParam<Method> {};

TEST_P(Scaling, SpeedScalesAsOneOverFrequencyAtFixedThrowNumber) {
  const Method method = GetParam();
  for (double gamma : {0.3, 0.6}) {
    TrackCase c = trackCase("f50", gamma);
    const Measured slow = run(trackScene(c), method);
    c.frequency = 100;  // A / 4 at the same Gamma; same steps per cycle
    c.name = "f100";
    const Measured fast = run(trackScene(c), method);
    std::printf(
        "[ numbers  ] Gamma %.2f %-25s v(50 Hz) %.4f mm/s  v(100 Hz) %.4f mm/s  "
        "ratio %.4f\n",
        gamma, toString(method), slow.speed * 1e3, fast.speed * 1e3, fast.speed / slow.speed);
    // Two measurements, each within speedTolerance of the same (scaled) model value.
    EXPECT_NEAR(fast.speed / slow.speed, 0.5, 2 * kSpeedTolerance * 0.5) << "Gamma " << gamma;
  }
}

TEST_P(Scaling, SpeedDoesNotDependOnPartMass) {
  const Method method = GetParam();
  for (double gamma : {0.3, 0.6}) {
    TrackCase c = trackCase("light", gamma);
    const Measured light = run(trackScene(c), method);
    c.density *= 10;
    c.name = "heavy";
    const Measured heavy = run(trackScene(c), method);
    std::printf("[ numbers  ] Gamma %.2f %-25s v(2 g) %.4f mm/s  v(20 g) %.4f mm/s\n", gamma,
                toString(method), light.speed * 1e3, heavy.speed * 1e3);
    EXPECT_NEAR(heavy.speed, light.speed, 2 * speedTolerance(light.speed)) << "Gamma " << gamma;
  }
}

INSTANTIATE_TEST_SUITE_P(FullVibration, Onset,
                         testing::Values(Method::OdeFullVibration, Method::ReferenceFullVibration),
                         [](const testing::TestParamInfo<Method>& i) {
                           return std::string(toString(i.param));
                         });
INSTANTIATE_TEST_SUITE_P(FullVibration, Scaling,
                         testing::Values(Method::OdeFullVibration, Method::ReferenceFullVibration),
                         [](const testing::TestParamInfo<Method>& i) {
                           return std::string(toString(i.param));
                         });

// ---------------------------------------------------------------------------------------------
// Hopping (Gamma > 1): speed and time in flight.

class Hopping : public testing::TestWithParam<Method> {};

TEST_P(Hopping, MatchesClassicalSpeedAndFlightTime) {
  const Method method = GetParam();
  for (double gamma : {1.2, 1.5}) {
    const TrackCase c = trackCase(gamma < 1.3 ? "Hop_G120" : "Hop_G150", gamma);
    const ClassicalDrift d = classicalDrift(modelParams(c));
    ASSERT_EQ(d.regime, ClassicalRegime::Hopping);
    const Measured m = run(trackScene(c), method);
    report(c.name, method, d, m);
    EXPECT_NEAR(m.speed, d.mean_speed, kHopSpeedTolerance * d.mean_speed);
    EXPECT_NEAR(m.no_contact_fraction, d.flight_fraction, kFlightFractionTolerance);
    expectFlatAndStraight(m);
  }
}

INSTANTIATE_TEST_SUITE_P(FullVibration, Hopping,
                         testing::Values(Method::OdeFullVibration, Method::ReferenceFullVibration),
                         [](const testing::TestParamInfo<Method>& i) {
                           return std::string(toString(i.param));
                         });

// ---------------------------------------------------------------------------------------------
// The reference solver's relaxed cone (coulomb_iterations = 0). NOTES section 3: the relaxed
// problem separates a sliding contact at u_n = mu |u_t|. ODE's collider reports only
// penetrating contacts, so the sliding part is launched off the track and flies: out of contact
// in most steps in a regime where the theory keeps it on the track, with a speed error of a few
// percent that does not shrink with the time step (measured -4.3 % to +2.2 % at Gamma 0.9-0.95
// between 200 and 1600 steps per cycle; +7.6 % and +14.6 % when hopping at Gamma 1.2 and 1.5).
// The true-Coulomb mode removes it. Pinned here so that a change is noticed.
TEST(ReferenceCone, RelaxedConeLaunchesTheSlidingPartTrueCoulombKeepsItOnTheTrack) {
  const TrackCase c = trackCase("G090", 0.9);
  const ClassicalDrift d = classicalDrift(modelParams(c));
  ASSERT_EQ(d.flight_fraction, 0.0);
  Scene scene = trackScene(c);
  const Measured coulomb = run(scene, Method::ReferenceFullVibration);
  scene.solver.coulomb_iterations = 0;
  const Measured relaxed = run(scene, Method::ReferenceFullVibration);
  report("G090_true_coulomb", Method::ReferenceFullVibration, d, coulomb);
  report("G090_relaxed_cone", Method::ReferenceFullVibration, d, relaxed);
  EXPECT_NEAR(coulomb.speed, d.mean_speed, kSpeedTolerance * d.mean_speed);
  EXPECT_EQ(coulomb.no_contact_fraction, 0.0);
  EXPECT_GT(relaxed.no_contact_fraction, 0.5);
}

}  // namespace
}  // namespace rheofeed::scene
