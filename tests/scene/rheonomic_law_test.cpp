// SPDX-License-Identifier: MIT
// The drift model of a vibrating feeder in the scene layer (issue 8): rheonomicLaw builds the
// local vibration law from the scene's vibration, gravity and mu (its drift checked against the
// classical straight-track model, classical_model.hpp, an independent event-driven
// integration), the calibrated drift stays available, local_sampled needs its factors, the
// per-family factor reaches the parts in both engines, and the runs report the local law's
// counts.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "rheofeed/measure/classical_model.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/simulation/simulation.hpp"
#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kG = 9.81;        // m/s^2
constexpr double kBeta = kPi / 6;  // vibration angle, 30 degrees
constexpr double kMu = 0.5;
// Throw number 0.3 (forward sliding only for mu = 0.5, beta = 30 degrees).
const double kW = 2 * kPi * 50;
const double kAmplitude = 0.3 * kG / (kW * kW * std::sin(kBeta));

// The law's tabulated point-mass drift against the classical model: the point-mass model is
// within 0.6 % of max(|drift|, 2 % of the peak tangential speed) at its default resolution
// (vibration_drift.hpp), plus the table's linear interpolation over a cell.
constexpr double kLocalVsClassical = 0.02;  // relative
// A flat box sticking to a stationary surface that drives it at c moves at c up to the
// solver's slack (ODE quickstep iterations, CFM; the reference solver's tolerance) and its
// landing; the ratio of two such runs cancels most of it.
constexpr double kEfficiencyRatio = 0.02;  // relative

// A flat vibrating track (a box, top face at z = 0) and `count` flat boxes on it.
Scene track(int count = 1) {
  Scene s;
  s.name = "local law track";
  s.fixtures.push_back(test::vibratingBox("track", {2, 0.4, 0.02}, {0, 0, 0}, kAmplitude, 50,
                                          {std::cos(kBeta), 0, std::sin(kBeta)}));
  PartSpec p;
  p.name = "plates";
  p.size[0].mean = 0.03;
  p.size[1].mean = 0.03;
  p.size[2].mean = 0.005;
  p.density = 2700;
  p.spawn_min = {-0.3, -0.1, 0.0026};
  p.spawn_max = {0.3, 0.1, 0.0026};
  p.count = count;
  s.parts.push_back(p);
  s.material.mu = kMu;
  s.solver.time_step = 0.005;
  s.duration = 0.5;
  s.outputs.sample_interval = 0.05;
  s.outputs.warmup = 0.1;
  return s;
}

TEST(RheonomicLaw, VibratingFeederGetsTheLocalLawByDefault) {
  const Scene s = track();
  ASSERT_EQ(s.fixtures[0].law.drift_model, DriftModel::Local);
  const MotionLaw law = rheonomicLaw(s, 0);
  ASSERT_EQ(law.kind(), MotionLaw::Kind::LocalVibration);
  const LocalVibration* v = law.localVibration();
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->frequency, 50);
  EXPECT_EQ(v->amplitude.x, kAmplitude * std::cos(kBeta));
  EXPECT_EQ(v->amplitude.z, kAmplitude * std::sin(kBeta));
  EXPECT_EQ(v->gravity.z, -kG);
  EXPECT_EQ(v->mu, kMu);
  EXPECT_EQ(v->efficiency, 1);

  ClassicalParams c;
  c.vibration_angle = kBeta;
  c.amplitude = kAmplitude;
  c.frequency = 50;
  c.mu = kMu;
  c.gravity = kG;
  const double expected = classicalDrift(c).mean_speed;
  ASSERT_GT(expected, 0);
  const StepLaw frozen = law.evaluate(0, nullptr, 0.005);
  const Vec3 drift = frozen.contactVelocity({0.1, 0, 0}, {0, 0, 1}, kMu);
  EXPECT_NEAR(drift.x, expected, kLocalVsClassical * expected);
  EXPECT_NEAR(drift.y, 0, kLocalVsClassical * expected);
}

TEST(RheonomicLaw, CalibratedDriftAndLocalSampledNeedTheirValues) {
  Scene s = track();
  s.fixtures[0].law.drift_model = DriftModel::CalibratedDrift;
  try {
    (void)rheonomicLaw(s, 0);
    ADD_FAILURE() << "a calibrated_drift model without a value was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fixtures[0] ('track')"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("calibrated_drift"), std::string::npos) << e.what();
  }
  s.fixtures[0].law.has_calibrated_drift = true;
  s.fixtures[0].law.calibrated_drift.linear = {0.02, 0, 0};
  const MotionLaw twist = rheonomicLaw(s, 0);
  EXPECT_EQ(twist.kind(), MotionLaw::Kind::Twist);
  EXPECT_EQ(twist.constantTwist().linear.x, 0.02);

  s.fixtures[0].law.drift_model = DriftModel::LocalSampled;
  try {
    (void)rheonomicLaw(s, 0);
    ADD_FAILURE() << "a local_sampled model without factors was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("local_sampled needs"), std::string::npos) << e.what();
  }
  s.fixtures[0].law.efficiency = {0.8};
  EXPECT_EQ(rheonomicLaw(s, 0).kind(), MotionLaw::Kind::LocalVibration);
  EXPECT_EQ(partEfficiencies(s), std::vector<double>{0.8});
  EXPECT_THROW((void)rheonomicLaw(s, 1), std::invalid_argument);
}

TEST(RheonomicLaw, EfficiencyFactorsAreValidatedWithPathValueAndRange) {
  auto refused = [](const Scene& s, const std::string& what) {
    try {
      s.validate();
      ADD_FAILURE() << "accepted; expected " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  Scene s = track();
  s.fixtures[0].law.drift_model = DriftModel::LocalSampled;
  s.fixtures[0].law.efficiency = {150};
  refused(s, "fixtures[0].law.efficiency[0] = 150: must be a finite number in [0, 100]");
  s.fixtures[0].law.efficiency = {1, 1};
  refused(s, "fixtures[0].law.efficiency size = 2: must equal the number of part families (1)");
  s.fixtures[0].law.efficiency = {0.9};
  s.fixtures[0].law.drift_model = DriftModel::Local;
  refused(s, "efficiency factors apply to drift_model local_sampled only");
  // Two local feeders that disagree on a family's factor (FeederSet's factor is per body).
  s.fixtures[0].law.drift_model = DriftModel::LocalSampled;
  Fixture second = s.fixtures[0];
  second.name = "second track";
  second.geoms[0].pose.position.x = 3;
  second.law.drift_model = DriftModel::Local;
  second.law.efficiency.clear();
  s.fixtures.push_back(second);
  refused(s,
          "fixtures[1].law.efficiency[0] = 1: part family 'plates' has factor 0.9 on "
          "fixtures[0]");
  s.fixtures[1].law.drift_model = DriftModel::CalibratedDrift;  // not a local law: no conflict
  EXPECT_NO_THROW(s.validate());
}

// The family's factor reaches its parts in both engines: a plate sticking to the local law's
// drift moves at factor times that drift.
TEST(RheonomicLaw, PartEfficiencyScalesTheDriftInBothEngines) {
  for (Method m : {Method::OdeRheonomic, Method::ReferenceRheonomic}) {
    SCOPED_TRACE(toString(m));
    const Scene local = track(2);
    Scene sampled = local;
    sampled.fixtures[0].law.drift_model = DriftModel::LocalSampled;
    sampled.fixtures[0].law.efficiency = {0.5};
    const RunMetrics a = measureRun(local, m), b = measureRun(sampled, m);
    ASSERT_GT(a.mean_drift, 0);
    EXPECT_NEAR(b.mean_drift / a.mean_drift, 0.5, kEfficiencyRatio * 0.5);
    // The counts of the local law are in the health and the JSON summary.
    EXPECT_EQ(a.health.local_law_feeders, 1);
    EXPECT_GT(a.health.local_law.contacts, 0);
    EXPECT_EQ(a.health.local_law.wall_contacts, 0);  // a flat track only
    // The scene layer's laws share the process's table (LocalDriftTable::shared): the run of the
    // first engine fills it, the second engine's run of the same vibration finds every corner.
    EXPECT_GT(a.health.local_law.model_runs + a.health.local_law_corners_at_start, 0);
    if (m == Method::ReferenceRheonomic) {
      EXPECT_EQ(a.health.local_law.model_runs, 0);
      EXPECT_GT(a.health.local_law_corners_at_start, 0);
    }
    const nlohmann::json j = nlohmann::json::parse(summaryJson(a)).at("local_law");
    EXPECT_EQ(j.at("model_runs").get<long long>(), a.health.local_law.model_runs);
    EXPECT_EQ(j.at("corners_at_start").get<long long>(), a.health.local_law_corners_at_start);
    EXPECT_EQ(j.at("feeders").get<int>(), 1);
    EXPECT_EQ(j.at("contacts").get<long long>(), a.health.local_law.contacts);
    EXPECT_EQ(j.at("cells_computed").get<long long>(), a.health.local_law.cells_computed);
    // The run's JSON names what reproduces it: the seed and each vibrating fixture's model.
    const nlohmann::json run = nlohmann::json::parse(summaryJson(b));
    EXPECT_EQ(run.at("seed").get<std::uint64_t>(), sampled.seed);
    ASSERT_EQ(run.at("drift_models").size(), 1u);
    EXPECT_EQ(run.at("drift_models")[0].get<std::string>(),
              sampled.fixtures[0].name + ": local_sampled");
    // ...and the efficiency it ran with (the scene's 0.5), per family.
    const nlohmann::json& field = run.at("drift_fields").at(0);
    EXPECT_EQ(field.at("drift_model"), "local_sampled");
    ASSERT_EQ(field.at("efficiency").size(), 1u);
    EXPECT_EQ(field.at("efficiency")[0].at("family"), sampled.parts[0].name);
    EXPECT_EQ(field.at("efficiency")[0].at("efficiency").get<double>(), 0.5);
    EXPECT_TRUE(field.at("calibrated_drift").is_null());
  }
}

TEST(RheonomicLaw, FullVibrationRunsIgnoreTheDriftModel) {
  Scene s = track();
  s.duration = 0.05;
  s.solver.time_step = 1e-4;
  s.outputs.sample_interval = 0.01;
  s.outputs.warmup = 0;
  s.fixtures[0].law.drift_model = DriftModel::LocalSampled;  // no factors: fine here
  const RunMetrics r = measureRun(s, Method::OdeFullVibration);
  EXPECT_EQ(r.health.local_law_feeders, 0);
  EXPECT_EQ(r.health.local_law.contacts, 0);
}

}  // namespace
}  // namespace rheofeed::scene
