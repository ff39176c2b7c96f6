// SPDX-License-Identifier: MIT
// calibration.cpp on a case with a known answer: a flat track vibrating at 30 degrees with
// throw number 3.4, where the classical single-part model has a closed form (NOTES section 5;
// tests/validation/classical_model_test.cpp derives it): the part hops for exactly one cycle and
// leaves the track at the track's velocity at the phase cos(phi) = pi / Gamma, so it drifts at
// A w cos(beta) pi / Gamma = pi g cot(beta) / w.
#include "rheofeed/measure/calibration.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "rheofeed/number_format.hpp"
#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kG = 9.81;              // m/s^2
constexpr double kBeta = kPi / 6;        // vibration angle above the track, 30 degrees
constexpr double kThrowNumber = 3.4;     // Gamma = A w^2 sin(beta) / g
constexpr double kFrequency = 50;        // Hz
const double kW = 2 * kPi * kFrequency;  // rad/s
const double kAmplitude = kThrowNumber * kG / (kW * kW * std::sin(kBeta));  // m
// The model integrates the flight in closed form and finds the landing by root finding to
// rounding: the closed form holds to 1e-9 relative (as in classical_model_test.cpp).
constexpr double kClosedForm = 1e-9;

Scene hoppingTrack() {
  Scene s;
  s.name = "one-cycle hop";
  s.fixtures.push_back(test::vibratingBox("track", {0.4, 0.1, 0.02}, {0, 0, 0}, kAmplitude,
                                          kFrequency, {std::cos(kBeta), 0, std::sin(kBeta)}));
  PartSpec p;
  p.name = "flat_box";
  p.size[0].mean = 0.02;
  p.size[1].mean = 0.02;
  p.size[2].mean = 0.005;
  p.density = 2700;
  p.spawn_min = {-0.05, -0.02, 0.0025};
  p.spawn_max = {0.05, 0.02, 0.0025};
  p.count = 4;
  s.parts.push_back(p);
  s.material.mu = 0.5;
  s.gravity = {0, 0, -kG};
  s.solver.time_step = 0.01;
  s.duration = 0.5;
  s.outputs.conveying_direction = {1, 0, 0};
  return s;
}

TEST(CalibrateClassical, OneCycleHopDriftsAtPiGCotBetaOverOmega) {
  const Scene s = hoppingTrack();
  const Calibration c = calibrateClassical(s, 0);
  const double expected = kPi * kG / std::tan(kBeta) / kW;  // 0.1700 m/s
  EXPECT_EQ(c.fixture, 0);
  EXPECT_NEAR(c.value, expected, kClosedForm * expected);
  EXPECT_EQ(c.ci95, 0.0);  // a model, not a sample
  // A translation along the conveying direction, no rotation.
  EXPECT_NEAR(c.drift.linear.x, expected, kClosedForm * expected);
  EXPECT_EQ(c.drift.linear.y, 0.0);
  EXPECT_EQ(c.drift.linear.z, 0.0);
  EXPECT_TRUE(isZero(c.drift.angular));
  // Efficiency: drift over the peak track velocity along the track, A w cos(beta) = pi / Gamma.
  EXPECT_NEAR(c.efficiency, kPi / kThrowNumber, kClosedForm);
}

TEST(CalibrateClassical, TheConveyingDirectionSetsTheSignOfTheDrift) {
  Scene s = hoppingTrack();
  s.outputs.conveying_direction = {-1, 0, 0};  // measured against the motion
  const double expected = kPi * kG / std::tan(kBeta) / kW;
  const Calibration c = calibrateClassical(s, 0);
  EXPECT_NEAR(c.value, -expected, kClosedForm * expected);
  // The drift field itself does not depend on how it is measured.
  EXPECT_NEAR(c.drift.linear.x, expected, kClosedForm * expected);
}

TEST(CalibrateClassical, RefusesAFixtureThatDoesNotVibrateNamingIt) {
  Scene s = hoppingTrack();
  s.fixtures.push_back(test::boxFixture("floor", {1, 1, 0.01}, {0, 0, -0.2}));
  for (int fixture : {1, 2, -1}) {
    try {
      calibrateClassical(s, fixture);
      ADD_FAILURE() << "fixture " << fixture << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("fixtures[" + std::to_string(fixture) + "]"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(WithCalibration, StoresTheDriftAndSwitchesTheFixtureToIt) {
  const Scene s = hoppingTrack();
  const Calibration c = calibrateClassical(s, 0);
  const Scene calibrated = withCalibration(s, c);
  const FeederLaw& law = calibrated.fixtures[0].law;
  EXPECT_TRUE(law.has_calibrated_drift);
  EXPECT_EQ(law.drift_model, DriftModel::CalibratedDrift);
  EXPECT_EQ(law.calibrated_drift.linear, c.drift.linear);
  EXPECT_NO_THROW(calibrated.validate());
  Calibration wrong = c;
  wrong.fixture = 3;
  EXPECT_THROW(withCalibration(s, wrong), std::invalid_argument);
}

// What a calibration was measured for (FeederLaw::calibrated_for): a scene whose vibration,
// gravity or friction changed since (an edited file, a sweep over the amplitude) must not keep
// answering with it.
TEST(StaleCalibration, AChangedVibrationGravityOrMuMakesTheCalibrationStaleNamingBothValues) {
  const Scene s = hoppingTrack();
  const Scene calibrated = withCalibration(s, calibrateClassical(s, 0));
  ASSERT_TRUE(calibrated.fixtures[0].law.calibrated_for.has_value());
  EXPECT_EQ(staleCalibration(calibrated, 0), "");
  EXPECT_FALSE(needsCalibration(calibrated));
  EXPECT_NO_THROW(rheonomicLaw(calibrated, 0));

  Scene louder = calibrated;
  louder.fixtures[0].law.vibration.amplitude = 2 * kAmplitude;
  const std::string why = staleCalibration(louder, 0);
  EXPECT_NE(why.find("calibrated drift was measured for another feeder"), std::string::npos) << why;
  EXPECT_NE(why.find("amplitude (m) " + formatNumber(kAmplitude) + " when calibrated, " +
                     formatNumber(2 * kAmplitude) + " now"),
            std::string::npos)
      << why;
  EXPECT_EQ(why.find("frequency"), std::string::npos) << why;  // only what changed
  EXPECT_TRUE(needsCalibration(louder));
  try {
    rheonomicLaw(louder, 0);
    ADD_FAILURE() << "a stale calibrated drift was used";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fixtures[0] ('track')"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("amplitude (m)"), std::string::npos) << e.what();
  }

  Scene moon = calibrated;
  moon.gravity = {0, 0, -1.62};
  EXPECT_NE(staleCalibration(moon, 0).find("gravity (m/s^2) [0, 0, -9.81] when calibrated, "
                                           "[0, 0, -1.62] now"),
            std::string::npos)
      << staleCalibration(moon, 0);
  Scene slippery = calibrated;
  slippery.material.mu = 0.2;
  EXPECT_NE(staleCalibration(slippery, 0).find("mu 0.5 when calibrated, 0.2 now"),
            std::string::npos)
      << staleCalibration(slippery, 0);

  Scene shifted = calibrated;  // a phase does not change a steady drift
  shifted.fixtures[0].law.vibration.phase = 1;
  EXPECT_EQ(staleCalibration(shifted, 0), "");
  Scene rounded = calibrated;  // the same values within rounding: no change
  rounded.fixtures[0].law.vibration.amplitude *= 1 + 1e-12;
  rounded.gravity.x = -0.0;
  EXPECT_EQ(staleCalibration(rounded, 0), "");
  Scene local = louder;  // the local law uses no calibration
  local.fixtures[0].law.drift_model = DriftModel::Local;
  EXPECT_EQ(staleCalibration(local, 0), "");
  Scene by_hand = louder;  // a drift given without its basis cannot be checked, and says so
  by_hand.fixtures[0].law.calibrated_for.reset();
  EXPECT_EQ(staleCalibration(by_hand, 0), "");
  EXPECT_TRUE(uncheckedCalibration(by_hand.fixtures[0].law));
  EXPECT_FALSE(uncheckedCalibration(louder.fixtures[0].law));
  EXPECT_FALSE(uncheckedCalibration(local.fixtures[0].law));
  Scene moved_axis = calibrated;  // an axis without a torsion moves nothing
  moved_axis.fixtures[0].law.vibration.axis_origin = {1, 2, 0};
  EXPECT_EQ(staleCalibration(moved_axis, 0), "");
}

TEST(StaleCalibration, LocalSampledEfficienciesKeepWhatTheyWereMeasuredFor) {
  Scene s = hoppingTrack();
  EfficiencyCalibration c;
  c.fixture = 0;
  c.family = 0;
  c.efficiency = 0.8;
  const Scene sampled = withEfficiency(s, c);
  EXPECT_EQ(staleCalibration(sampled, 0), "");
  // A calibrated drift kept beside the factors shares their record: one sampled for this
  // feeder and these parts stays; one of unknown origin (no calibrated_for), or a classical one
  // (whose own record the sampling record would replace), does not pass for it.
  Calibration sampled_drift = calibrateClassical(s, 0);
  sampled_drift.method = "sampling";
  Scene drift_too = withCalibration(s, sampled_drift);
  EXPECT_TRUE(withEfficiency(drift_too, c).fixtures[0].law.has_calibrated_drift);
  EXPECT_FALSE(withEfficiency(withCalibration(s, calibrateClassical(s, 0)), c)
                   .fixtures[0]
                   .law.has_calibrated_drift);
  drift_too.fixtures[0].law.calibrated_for.reset();
  EXPECT_FALSE(withEfficiency(drift_too, c).fixtures[0].law.has_calibrated_drift);
  Scene faster = sampled;
  faster.fixtures[0].law.vibration.frequency = 60;
  const std::string why = staleCalibration(faster, 0);
  EXPECT_NE(why.find("part efficiency factors were measured for another feeder: frequency (Hz) "
                     "50 when calibrated, 60 now"),
            std::string::npos)
      << why;
}

// A sample run measures the drift of the scene's parts on its fixtures: other parts (a sweep
// over their size), moved fixtures or another restitution make it stale too; more or fewer of
// the same parts, or a new family name, do not.
TEST(StaleCalibration, ASampledCalibrationKnowsItsPartsFixturesAndRestitution) {
  const Scene s = hoppingTrack();
  Calibration c = calibrateClassical(s, 0);
  c.method = "sampling";  // as calibrateBySampling returns it (the value itself is not used)
  const Scene calibrated = withCalibration(s, c);
  const CalibrationBasis& basis = *calibrated.fixtures[0].law.calibrated_for;
  ASSERT_EQ(basis.part_digests.size(), 1u);
  EXPECT_EQ(basis.part_digests[0], partDigest(s.parts[0]));
  ASSERT_EQ(basis.fixture_digests.size(), 1u);
  EXPECT_EQ(basis.fixture_digests[0], fixtureDigest(s.fixtures[0]));
  EXPECT_EQ(basis.restitution, s.material.restitution);
  ASSERT_TRUE(basis.conveying_direction.has_value());
  EXPECT_FALSE(basis.track_point.has_value());  // a straight track: no radius
  EXPECT_EQ(staleCalibration(calibrated, 0), "");

  Scene more = calibrated;  // more of the same parts, later, under another name
  more.parts[0].count *= 10;
  more.parts[0].rate = 5;
  more.parts[0].name = "renamed";
  EXPECT_EQ(staleCalibration(more, 0), "");
  Scene rounded = calibrated;
  rounded.parts[0].size[0].mean *= 1 + 1e-13;
  rounded.fixtures[0].geoms[0].pose.position.x += 1e-14;
  EXPECT_EQ(staleCalibration(rounded, 0), "");

  Scene bigger = calibrated;
  bigger.parts[0].size[0].mean *= 1.5;
  const std::string why = staleCalibration(bigger, 0);
  EXPECT_EQ(why.find("its calibrated drift was measured with other parts: parts[0] 'flat_box' "
                     "(the digest of its shape, sizes"),
            0u)
      << why;
  EXPECT_NE(
      why.find(basis.part_digests[0] + " when calibrated, " + partDigest(bigger.parts[0]) + " now"),
      std::string::npos)
      << why;
  EXPECT_TRUE(needsCalibration(bigger));
  EXPECT_THROW(rheonomicLaw(bigger, 0), std::invalid_argument);
  Scene denser = calibrated;
  denser.parts[0].density *= 2;
  EXPECT_NE(staleCalibration(denser, 0), "");
  Scene bouncier = calibrated;
  bouncier.material.restitution = 0.5;
  EXPECT_NE(staleCalibration(bouncier, 0).find("restitution 0 when calibrated, 0.5 now"),
            std::string::npos)
      << staleCalibration(bouncier, 0);

  Scene raised = calibrated;
  raised.fixtures[0].geoms[0].pose.position.z += 0.01;
  const std::string moved = staleCalibration(raised, 0);
  EXPECT_EQ(moved.find("its calibrated drift was measured for another feeder: fixture 'track' "
                       "(the digest of its geoms' shapes, sizes and poses) " +
                       basis.fixture_digests[0] + " when calibrated"),
            0u)
      << moved;
  raised.parts[0].density *= 2;
  EXPECT_EQ(staleCalibration(raised, 0).find("its calibrated drift was measured for another "
                                             "feeder and parts: fixture 'track'"),
            0u)
      << staleCalibration(raised, 0);
  Scene turned = calibrated;  // the drift is measured along the conveying direction
  turned.outputs.conveying_direction = {0, 1, 0};
  EXPECT_NE(staleCalibration(turned, 0).find("conveying direction [1, 0, 0] when calibrated, "
                                             "[0, 1, 0] now"),
            std::string::npos)
      << staleCalibration(turned, 0);
}

// A calibrated drift is sampled on the first part family only, efficiency factors each on
// their own: a change of another family does not make them stale, and the message names the
// family that changed. After a change of the feeder, a factor measured again for one family
// does not vouch for the others' old ones.
TEST(StaleCalibration, EachCalibrationIsComparedOnTheFamiliesItSampled) {
  Scene s = hoppingTrack();
  PartSpec pins = s.parts[0];
  pins.name = "pins";
  pins.size[2].mean = 0.01;
  s.parts.push_back(pins);
  Calibration c = calibrateClassical(s, 0);
  c.method = "sampling";
  const Scene drift = withCalibration(s, c);
  EXPECT_EQ(drift.fixtures[0].law.calibrated_for->part_digests.size(), 2u);
  Scene longer_pins = drift;
  longer_pins.parts[1].size[2].mean = 0.02;
  EXPECT_EQ(staleCalibration(longer_pins, 0), "");  // the drift sampled the first family only
  Scene wider_boxes = drift;
  wider_boxes.parts[0].size[1].mean = 0.03;
  EXPECT_EQ(staleCalibration(wider_boxes, 0)
                .find("its calibrated drift was measured with other "
                      "parts: parts[0] 'flat_box'"),
            0u)
      << staleCalibration(wider_boxes, 0);

  EfficiencyCalibration e;
  e.fixture = 0;
  e.efficiency = 0.8;
  e.family = 0;
  Scene sampled = withEfficiency(s, e);
  // The second family's factor (1 by default) was not measured: stale until it is.
  EXPECT_NE(staleCalibration(sampled, 0)
                .find("parts[1] 'pins' (its factor is not one this "
                      "record measured: calibrate every family)"),
            std::string::npos)
      << staleCalibration(sampled, 0);
  e.family = 1;
  e.efficiency = 0.9;
  sampled = withEfficiency(sampled, e);
  EXPECT_EQ(staleCalibration(sampled, 0), "");
  Scene pins_changed = sampled;
  pins_changed.parts[1].density = 7800;
  const std::string why = staleCalibration(pins_changed, 0);
  EXPECT_EQ(why.find("its part efficiency factors were measured with other parts: parts[1] "
                     "'pins'"),
            0u)
      << why;
  EXPECT_EQ(why.find("flat_box"), std::string::npos) << why;  // only the family that changed
  Scene another_family = sampled;
  another_family.parts.push_back(pins);
  EXPECT_NE(staleCalibration(another_family, 0)
                .find("the number of part families 2 when "
                      "calibrated, 3 now"),
            std::string::npos)
      << staleCalibration(another_family, 0);

  // The feeder changes; the first family is measured again, the second is not.
  Scene louder = sampled;
  louder.fixtures[0].law.vibration.amplitude *= 1.5;
  e.family = 0;
  const Scene half = withEfficiency(louder, e);
  const std::string half_why = staleCalibration(half, 0);
  EXPECT_NE(half_why.find("parts[1] 'pins' (its factor is not one this record measured"),
            std::string::npos)
      << half_why;
  EXPECT_EQ(half_why.find("flat_box"), std::string::npos) << half_why;
  e.family = 1;
  EXPECT_EQ(staleCalibration(withEfficiency(half, e), 0), "");  // both measured again
}

// A record written before the digests were kept checks the feeder only, and says so.
TEST(StaleCalibration, ARecordWithoutDigestsIsOnlyPartlyChecked) {
  const Scene s = hoppingTrack();
  Calibration c = calibrateClassical(s, 0);
  const Scene classical = withCalibration(s, c);
  EXPECT_EQ(missingDigests(classical.fixtures[0].law), "");  // nothing else to digest
  c.method = "sampling";
  Scene old_file = withCalibration(s, c);
  EXPECT_EQ(missingDigests(old_file.fixtures[0].law), "");
  old_file.fixtures[0].law.calibrated_for->fixture_digests.clear();
  EXPECT_EQ(missingDigests(old_file.fixtures[0].law), "fixture");
  old_file.fixtures[0].law.calibrated_for->part_digests.clear();
  EXPECT_EQ(missingDigests(old_file.fixtures[0].law), "part or fixture");
  old_file.parts[0].density *= 3;
  EXPECT_EQ(staleCalibration(old_file, 0), "");  // not noticed: hence the note
  old_file.fixtures[0].law.drift_model = DriftModel::Local;
  EXPECT_EQ(missingDigests(old_file.fixtures[0].law), "");  // not used
}

// The classical model takes the vibration, gravity, mu, a straight track's direction and a
// screw's radius (the spawn centre's), not the parts or the fixtures' shapes.
TEST(StaleCalibration, AClassicalCalibrationKnowsItsTrackDirectionAndAScrewsRadius) {
  const Scene s = hoppingTrack();
  const Scene calibrated = withCalibration(s, calibrateClassical(s, 0));
  const CalibrationBasis& basis = *calibrated.fixtures[0].law.calibrated_for;
  EXPECT_TRUE(basis.part_digests.empty());
  EXPECT_FALSE(basis.restitution.has_value());
  Scene other_parts = calibrated;
  other_parts.parts[0].size[0].mean *= 2;
  other_parts.parts[0].spawn_min.x += 0.1;
  other_parts.parts[0].spawn_max.x += 0.1;
  other_parts.fixtures[0].geoms[0].pose.position.z += 0.01;
  EXPECT_EQ(staleCalibration(other_parts, 0), "");
  Scene turned = calibrated;
  turned.outputs.conveying_direction = {0, -1, 0};
  EXPECT_NE(staleCalibration(turned, 0).find("conveying direction"), std::string::npos);

  Scene screw = s;
  Vibration& v = screw.fixtures[0].law.vibration;
  v.torsion_amplitude = 0.003;
  v.axis_origin = {0, -0.5, 0};
  v.axis_direction = {0, 0, 1};
  v.direction = {0, 0, 1};  // a bowl's screw: translation and gravity along the axis
  Calibration twist;
  twist.fixture = 0;
  twist.method = "classical";
  twist.drift.angular = {0, 0, 0.3};
  twist.drift.origin = v.axis_origin;
  const Scene bowl = withCalibration(screw, twist);
  const CalibrationBasis& screw_basis = *bowl.fixtures[0].law.calibrated_for;
  ASSERT_TRUE(screw_basis.track_point.has_value());
  EXPECT_FALSE(screw_basis.conveying_direction.has_value());  // a screw's drift turns
  EXPECT_EQ(staleCalibration(bowl, 0), "");
  Scene spun = bowl;
  spun.outputs.conveying_direction = {0, 1, 0};
  EXPECT_EQ(staleCalibration(spun, 0), "");
  Scene nearer = bowl;  // the spawn region nearer the axis: another radius
  nearer.parts[0].spawn_min.y -= 0.2;
  nearer.parts[0].spawn_max.y -= 0.2;
  EXPECT_NE(staleCalibration(nearer, 0).find("track radius (m, the first part family's spawn "
                                             "centre from the axis) 0.5 when calibrated, 0.3 now"),
            std::string::npos)
      << staleCalibration(nearer, 0);
  Scene round = bowl;  // the spawn region turned half way round the axis: the same radius
  for (Vec3* p : {&round.parts[0].spawn_min, &round.parts[0].spawn_max}) {
    p->y = -1.0 - p->y;  // mirrored through the axis at y = -0.5
    p->z += 0.01;        // and raised: the screw's vibration does not change along its axis
  }
  std::swap(round.parts[0].spawn_min.y, round.parts[0].spawn_max.y);
  EXPECT_EQ(staleCalibration(round, 0), "");
  // With the translation tilted off the axis, the place round the axis matters too.
  Scene tilted = screw;
  tilted.fixtures[0].law.vibration.direction = {std::cos(kBeta), 0, std::sin(kBeta)};
  Scene tilted_round = withCalibration(tilted, twist);
  tilted_round.parts[0] = round.parts[0];
  EXPECT_NE(staleCalibration(tilted_round, 0)
                .find("track point (m, the first part family's "
                      "spawn centre) [0, 0, 0.0025] when "
                      "calibrated"),
            std::string::npos)
      << staleCalibration(tilted_round, 0);
}

TEST(CalibrateScene, CalibratesAStaleCalibrationAgainAndSaysWhy) {
  Scene s = hoppingTrack();
  s.fixtures[0].law.drift_model = DriftModel::CalibratedDrift;
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  CalibrateOptions options;
  options.classical = true;
  calibrateScene(s, options, "test", log);
  const double first = s.fixtures[0].law.calibrated_drift.linear.x;
  EXPECT_EQ(s.fixtures[0].law.calibrated_for->method, "classical");
  // At 60 Hz (throw number 3.4 * 1.44 = 4.9) the drift is the classical model's there: a stale
  // classical drift is redone by the model even without options.classical (as it was made).
  s.fixtures[0].law.vibration.frequency = 60;
  options.classical = false;
  const CalibrateReport again = calibrateScene(s, options, "test", log);
  EXPECT_EQ(s.fixtures[0].law.calibrated_for->method, "classical");
  EXPECT_EQ(again.calibrated, 1);
  EXPECT_EQ(again.given, 0);
  ASSERT_EQ(again.stale.size(), 1u);
  EXPECT_NE(again.stale[0].find("fixture 'track': its calibrated drift was measured for another "
                                "feeder: frequency (Hz) 50 when calibrated, 60 now"),
            std::string::npos)
      << again.stale[0];
  EXPECT_EQ(staleCalibration(s, 0), "");
  Scene edited = hoppingTrack();
  edited.fixtures[0].law.vibration.frequency = 60;
  const double expected = calibrateClassical(edited, 0).value;
  EXPECT_EQ(s.fixtures[0].law.calibrated_drift.linear.x, expected);
  EXPECT_NE(expected, first);
  std::fclose(log);
}

TEST(CalibrateScene, CalibratesOnlyTheFixturesWhoseDriftModelTakesACalibration) {
  Scene s = hoppingTrack();
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  CalibrateOptions options;
  options.classical = true;
  Scene local = s;  // the default drift model, the local law: nothing to calibrate
  const CalibrateReport none = calibrateScene(local, options, "test", log);
  EXPECT_EQ(none.calibrated, 0);
  EXPECT_EQ(none.local, 1);
  EXPECT_FALSE(local.fixtures[0].law.has_calibrated_drift);

  s.fixtures[0].law.drift_model = DriftModel::CalibratedDrift;
  const CalibrateReport report = calibrateScene(s, options, "test", log);
  EXPECT_EQ(report.calibrated, 1);
  EXPECT_EQ(report.given, 0);
  const double expected = kPi * kG / std::tan(kBeta) / kW;
  EXPECT_TRUE(s.fixtures[0].law.has_calibrated_drift);
  EXPECT_NEAR(s.fixtures[0].law.calibrated_drift.linear.x, expected, kClosedForm * expected);
  // Calibrated once, the scene gives it: a second pass leaves it.
  const CalibrateReport again = calibrateScene(s, options, "test", log);
  EXPECT_EQ(again.calibrated, 0);
  EXPECT_EQ(again.given, 1);
  std::fclose(log);
}

// The sampling run's cycles (CalibrateOptions::warmup_cycles, measure_cycles; `rheofeed
// calibrate --warmup-cycles --measure-cycles`) reach the sample: the summary names them, and a
// negative warm-up is refused naming the setting.
TEST(CalibrateScene, SamplingRunTakesTheWarmupAndMeasuredCyclesOfTheOptions) {
  Scene s = hoppingTrack();
  s.fixtures[0].law.drift_model = DriftModel::CalibratedDrift;
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  CalibrateOptions options;
  options.warmup_cycles = 2;
  options.measure_cycles = 4;
  Scene sampled = s;
  const CalibrateReport report = calibrateScene(sampled, options, "test", log);
  EXPECT_EQ(report.calibrated, 1);
  EXPECT_NE(report.summary.find("2 cycles of warm-up, 4 measured"), std::string::npos)
      << report.summary;
  // A one-cycle hop moves the parts on at the closed form's speed from the first cycle on.
  const double expected = kPi * kG / std::tan(kBeta) / kW;
  EXPECT_NEAR(sampled.fixtures[0].law.calibrated_drift.linear.x, expected, 0.2 * expected);
  options.warmup_cycles = -1;
  try {
    calibrateScene(s, options, "test", log);
    ADD_FAILURE() << "a negative warm-up was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("warmup_cycles >= 0"), std::string::npos) << e.what();
  }
  std::fclose(log);
}

}  // namespace
}  // namespace rheofeed::scene
