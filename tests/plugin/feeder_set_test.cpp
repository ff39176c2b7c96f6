// SPDX-License-Identifier: MIT
// FeederSet::driveContacts on hand-made contacts: what it writes into a feeder contact, what it
// leaves alone, what it counts, records, and how often it evaluates a law.
#include "rheofeed/feeder_set.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {

// fdir1 is c_rel / |c_rel| in double precision: unit and orthogonal to n up to round-off.
constexpr double kRoundOff = 1e-14;

/// Geoms for hand-made contacts: a static feeder geom, one on a body, a dynamic part, and a
/// plain static geom. They are in no space; only their ids and bodies matter.
class HandMadeContacts : public testing::Test {
 protected:
  void SetUp() override {
    static const bool initialised = (dInitODE2(0), true);
    (void)initialised;
    world_ = dWorldCreate();
    static_feeder_ = dCreateBox(nullptr, 1, 1, 1);
    body_feeder_ = dCreateBox(nullptr, 1, 1, 1);
    dGeomSetBody(body_feeder_, dBodyCreate(world_));
    part_ = dCreateBox(nullptr, 1, 1, 1);
    dGeomSetBody(part_, dBodyCreate(world_));
    other_part_ = dCreateBox(nullptr, 1, 1, 1);
    dGeomSetBody(other_part_, dBodyCreate(world_));
    plain_ = dCreateBox(nullptr, 1, 1, 1);
  }
  void TearDown() override {
    for (dGeomID g : {static_feeder_, body_feeder_, part_, other_part_, plain_}) dGeomDestroy(g);
    dWorldDestroy(world_);
  }

  /// A contact between g1 and g2 at p with unit normal n (from g2 into g1), depth 1 mm,
  /// Approx1 friction mu = 0.5.
  static dContact contact(dGeomID g1, dGeomID g2, const Vec3& p, const Vec3& n) {
    dContact c;
    std::memset(&c, 0, sizeof c);
    c.geom.g1 = g1;
    c.geom.g2 = g2;
    c.geom.pos[0] = p.x;
    c.geom.pos[1] = p.y;
    c.geom.pos[2] = p.z;
    c.geom.normal[0] = n.x;
    c.geom.normal[1] = n.y;
    c.geom.normal[2] = n.z;
    c.geom.depth = 1e-3;
    c.surface.mode = dContactApprox1;
    c.surface.mu = 0.5;
    return c;
  }

  dWorldID world_;
  dGeomID static_feeder_, body_feeder_, part_, other_part_, plain_;
};

Vec3 fdir1(const dContact& c) {
  return {c.fdir1[0], c.fdir1[1], c.fdir1[2]};
}

/// The velocity ODE imposes on the part relative to the feeder, read back from the contact the
/// way ODE's friction row reads it: (v_node0 - v_node1) . fdir1 = motion1, where node0 is
/// body(g1) (body(g2) when `g2_first`) unless that is 0 and the other is not.
Vec3 imposedPartVelocity(const dContact& c, dGeomID part, bool g2_first) {
  dGeomID first = g2_first ? c.geom.g2 : c.geom.g1;
  if (!dGeomGetBody(first)) first = first == c.geom.g1 ? c.geom.g2 : c.geom.g1;
  const double sign = first == part ? 1.0 : -1.0;
  return (sign * c.surface.motion1) * fdir1(c);
}

/// Unit vector from spherical angles.
Vec3 unit(double polar, double azimuth) {
  return {std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
          std::cos(polar)};
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// What a feeder contact gets

TEST_F(HandMadeContacts, FDir1IsUnitTangentAndMotion1MovesThePartWithTheSurface) {
  // Rotation law w about O: the part must be driven at c_t = w x (p - O) minus its normal part,
  // computed here by hand, for any normal, either geom order, static or body feeder and either
  // attach order.
  const Vec3 w{0.3, -1.2, 2.0}, o{0.1, 0.2, -0.3};
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(0.0, 2 * kPi), coordinate(-1.0, 1.0);
  for (AttachOrder order : {AttachOrder::G1First, AttachOrder::G2First}) {
    FeederSet::Options options;
    options.attach_order = order;
    FeederSet set(options);
    set.add(static_feeder_, MotionLaw::rotation(w, o));
    set.add(body_feeder_, MotionLaw::rotation(w, o));
    for (int trial = 0; trial < 200; ++trial) {
      const Vec3 n = unit(angle(random) / 2, angle(random));
      const Vec3 p{coordinate(random), coordinate(random), coordinate(random)};
      const Vec3 r = p - o;
      const Vec3 v{w.y * r.z - w.z * r.y, w.z * r.x - w.x * r.z, w.x * r.y - w.y * r.x};
      const double vn = v.x * n.x + v.y * n.y + v.z * n.z;
      const Vec3 expected{v.x - vn * n.x, v.y - vn * n.y, v.z - vn * n.z};
      for (dGeomID feeder : {static_feeder_, body_feeder_}) {
        for (bool feeder_g1 : {true, false}) {
          dContact c = feeder_g1 ? contact(feeder, part_, p, n) : contact(part_, feeder, p, n);
          set.beginStep(0.0);
          ASSERT_EQ(set.driveContacts(&c, 1), 1);
          ASSERT_TRUE(c.surface.mode & dContactFDir1);
          ASSERT_TRUE(c.surface.mode & dContactMotion1);
          EXPECT_TRUE(c.surface.mode & dContactApprox1);
          EXPECT_FALSE(c.surface.mode & dContactMotion2);
          EXPECT_EQ(c.surface.motion2, 0.0);
          EXPECT_NEAR(norm(fdir1(c)), 1.0, kRoundOff);
          EXPECT_NEAR(dot(fdir1(c), n), 0.0, kRoundOff);
          EXPECT_GE(c.surface.motion1, 0.0);
          const Vec3 imposed = imposedPartVelocity(c, part_, order == AttachOrder::G2First);
          EXPECT_NEAR(imposed.x, expected.x, kRoundOff);
          EXPECT_NEAR(imposed.y, expected.y, kRoundOff);
          EXPECT_NEAR(imposed.z, expected.z, kRoundOff);
        }
      }
    }
  }
}

TEST_F(HandMadeContacts, WithTheStepARotatingFeederCarriesThePartsCentreOfMassOnItsChord) {
  // Turntable w = 2 rad/s about +z through O, step h = 0.05 s (a turn of 0.1 rad). The part's
  // body is at x_c: a sticking part must move rigidly, its centre of mass along the chord to
  // x_c turned by w h about O, spinning at w. So the contact at p asks for
  // (Rot(w h)(x_c - O) + O - x_c) / h + w x (p - x_c) (tangential part), written out here with
  // cos and sin, for either geom order and a static or body feeder.
  const double w = 2.0, h = 0.05;
  const Vec3 o{0.1, -0.2, 0.0}, xc{0.4, 0.3, 0.02}, n{0, 0, 1};
  FeederSet set;
  set.add(static_feeder_, MotionLaw::rotation({0, 0, w}, o));
  set.add(body_feeder_, MotionLaw::rotation({0, 0, w}, o));
  dBodySetPosition(dGeomGetBody(part_), xc.x, xc.y, xc.z);
  const double c = std::cos(w * h), s = std::sin(w * h);
  const Vec3 r = xc - o;
  const Vec3 chord{(c * r.x - s * r.y - r.x) / h, (s * r.x + c * r.y - r.y) / h, 0.0};
  for (const Vec3& p : {Vec3{0.38, 0.28, 0}, Vec3{0.42, 0.32, 0}, Vec3{0.1, -0.2, 0}}) {
    const Vec3 expected = chord + Vec3{-w * (p.y - xc.y), w * (p.x - xc.x), 0.0};
    for (dGeomID feeder : {static_feeder_, body_feeder_}) {
      for (bool feeder_g1 : {true, false}) {
        dContact contact_ = feeder_g1 ? contact(feeder, part_, p, n) : contact(part_, feeder, p, n);
        set.beginStep(0.0, h);
        ASSERT_EQ(set.driveContacts(&contact_, 1), 1);
        const Vec3 imposed = imposedPartVelocity(contact_, part_, false);
        EXPECT_NEAR(imposed.x, expected.x, kRoundOff);
        EXPECT_NEAR(imposed.y, expected.y, kRoundOff);
        EXPECT_NEAR(imposed.z, expected.z, kRoundOff);
      }
    }
  }
  // Against the static environment (no body to carry) the contact point's own chord is used.
  const Vec3 p{0.4, 0.3, 0};
  dContact alone = contact(body_feeder_, nullptr, p, n);
  set.beginStep(0.0, h);
  ASSERT_EQ(set.driveContacts(&alone, 1), 1);
  const Vec3 rp = p - o;
  const Vec3 own{(c * rp.x - s * rp.y - rp.x) / h, (s * rp.x + c * rp.y - rp.y) / h, 0.0};
  // The feeder's body is node0: motion1 fdir1 = c_rel = 0 - c_feeder.
  const Vec3 imposed = alone.surface.motion1 * fdir1(alone);
  EXPECT_NEAR(imposed.x, -own.x, kRoundOff);
  EXPECT_NEAR(imposed.y, -own.y, kRoundOff);
}

TEST_F(HandMadeContacts, Approx1IsForcedOnFeederContactsOnly) {
  FeederSet set;
  set.add(static_feeder_, MotionLaw::belt({1, 0, 0}, 0.3));
  dContact c[2] = {contact(static_feeder_, part_, {0, 0, 0}, {0, 0, 1}),
                   contact(part_, plain_, {0, 0, 0}, {0, 0, 1})};
  c[0].surface.mode = 0;
  c[1].surface.mode = 0;
  set.beginStep(0.0);
  ASSERT_EQ(set.driveContacts(c, 2), 2);
  EXPECT_EQ(c[0].surface.mode & dContactApprox1, dContactApprox1);
  EXPECT_EQ(c[1].surface.mode, 0);
}

TEST_F(HandMadeContacts, NormalRowIsLeftAsTheApplicationSetIt) {
  FeederSet set;
  set.add(static_feeder_, MotionLaw::belt({1, 0, 0}, 0.3));
  dContact c = contact(static_feeder_, part_, {0, 0, 0}, {0, 0, 1});
  c.surface.mode |= dContactBounce | dContactSoftERP | dContactSoftCFM | dContactMotionN;
  c.surface.bounce = 0.25;
  c.surface.bounce_vel = 0.1;
  c.surface.soft_erp = 0.4;
  c.surface.soft_cfm = 1e-5;
  c.surface.motionN = 0.01;
  const dContact before = c;
  set.beginStep(0.0);
  ASSERT_EQ(set.driveContacts(&c, 1), 1);
  EXPECT_EQ(std::memcmp(&c.geom, &before.geom, sizeof c.geom), 0);
  EXPECT_EQ(c.surface.bounce, before.surface.bounce);
  EXPECT_EQ(c.surface.bounce_vel, before.surface.bounce_vel);
  EXPECT_EQ(c.surface.soft_erp, before.surface.soft_erp);
  EXPECT_EQ(c.surface.soft_cfm, before.surface.soft_cfm);
  EXPECT_EQ(c.surface.motionN, before.surface.motionN);
  EXPECT_EQ(c.surface.mu, before.surface.mu);
  const int normal_flags = dContactBounce | dContactSoftERP | dContactSoftCFM | dContactMotionN;
  EXPECT_EQ(c.surface.mode & normal_flags, normal_flags);
}

TEST_F(HandMadeContacts, ZeroOrTinySurfaceSpeedSetsNoDirectionAndNoMotion) {
  // Each law gives |c_t| = 0 or below Options::min_surface_speed (1e-9 m/s) at this contact.
  const Vec3 p{0.5, 0.0, 0.0}, n{0, 0, 1};
  const MotionLaw laws[] = {
      MotionLaw::rotation({0, 0, 3}, p),  // p is the rotation centre
      MotionLaw::translation({0, 0, 2}),  // purely normal: discarded
      MotionLaw::belt({0, 0, 1}, 0.3),    // belt end face: direction along n
      MotionLaw::belt({1, 0, 0}, 1e-12),  // tiny
      MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::constant(1e-13)),
      MotionLaw(),
  };
  int index = 0;
  for (const MotionLaw& law : laws) {
    SCOPED_TRACE(testing::Message() << "law #" << index++);
    FeederSet set;
    set.add(static_feeder_, law);
    dContact c = contact(static_feeder_, part_, p, n);
    // The application may have set motion and a direction of its own: a feeder contact with
    // no surface motion must not carry them to ODE.
    c.surface.mode |= dContactFDir1 | dContactMotion1 | dContactMotion2;
    c.surface.motion1 = 5.0;
    c.surface.motion2 = 6.0;
    set.beginStep(0.0);
    ASSERT_EQ(set.driveContacts(&c, 1), 1);
    EXPECT_FALSE(c.surface.mode & dContactFDir1);
    EXPECT_FALSE(c.surface.mode & dContactMotion1);
    EXPECT_FALSE(c.surface.mode & dContactMotion2);
    EXPECT_EQ(c.surface.motion1, 0.0);
    EXPECT_EQ(c.surface.motion2, 0.0);
    for (int k = 0; k < 4; ++k) EXPECT_FALSE(std::isnan(c.fdir1[k]));
    EXPECT_EQ(set.stats(static_feeder_).contacts_driven, 0);
    EXPECT_EQ(set.stats(static_feeder_).contacts_undriven, 1);
  }
}

TEST_F(HandMadeContacts, MinSurfaceSpeedIsTheDrivingThreshold) {
  FeederSet::Options options;
  options.min_surface_speed = 1e-3;  // m/s
  FeederSet set(options);
  set.add(static_feeder_, MotionLaw::belt({1, 0, 0}, 0.5e-3));
  dContact c = contact(static_feeder_, part_, {0, 0, 0}, {0, 0, 1});
  set.beginStep(0.0);
  set.driveContacts(&c, 1);
  EXPECT_FALSE(c.surface.mode & dContactMotion1);
  set.setLaw(static_feeder_, MotionLaw::belt({1, 0, 0}, 2e-3));
  c = contact(static_feeder_, part_, {0, 0, 0}, {0, 0, 1});
  set.beginStep(0.0);
  set.driveContacts(&c, 1);
  EXPECT_TRUE(c.surface.mode & dContactMotion1);
  EXPECT_DOUBLE_EQ(c.surface.motion1, 2e-3);
}

// ---------------------------------------------------------------------------------------------
// What is left alone

TEST_F(HandMadeContacts, ContactsTouchingNoFeederAreLeftBitwiseIdentical) {
  FeederSet set;
  set.setDiagnosticHandler([](const Diagnostic&) {});
  set.add(static_feeder_, MotionLaw::belt({1, 0, 0}, 0.3));
  set.add(body_feeder_, MotionLaw::rotation({0, 0, 1}, {0, 0, 0}));
  std::mt19937 random(11);
  std::vector<dContact> contacts;
  std::vector<dContact> plain;  // the non-feeder contacts, as made
  for (int i = 0; i < 24; ++i) {
    const int kind = i % 4;
    if (kind == 0 || kind == 2) {
      // Random bytes throughout (NaNs and all), between two non-feeder geoms.
      dContact c;
      auto* bytes = reinterpret_cast<unsigned char*>(&c);
      for (std::size_t b = 0; b < sizeof c; ++b) bytes[b] = static_cast<unsigned char>(random());
      c.geom.g1 = kind == 0 ? part_ : plain_;
      c.geom.g2 = kind == 0 ? plain_ : other_part_;
      contacts.push_back(c);
      plain.push_back(c);
    } else if (kind == 1) {
      contacts.push_back(contact(static_feeder_, part_, {0.1 * i, 0, 0}, {0, 0, 1}));
    } else {
      // An invalid feeder contact (negative mu): removed, so later contacts move forward.
      dContact c = contact(part_, body_feeder_, {0, 0.1 * i, 0}, {0, 0, 1});
      c.surface.mu = -1.0;
      contacts.push_back(c);
    }
  }
  set.beginStep(0.0);
  const int kept = set.driveContacts(contacts.data(), static_cast<int>(contacts.size()));
  ASSERT_EQ(kept, 18);  // 24 minus the 6 invalid ones
  std::size_t next_plain = 0;
  for (int i = 0; i < kept; ++i) {
    const dContact& c = contacts[i];
    if (c.geom.g1 == static_feeder_) continue;
    ASSERT_LT(next_plain, plain.size());
    EXPECT_EQ(std::memcmp(&c, &plain[next_plain], sizeof c), 0) << "contact " << i;
    ++next_plain;
  }
  EXPECT_EQ(next_plain, plain.size());
}

TEST_F(HandMadeContacts, NoFeedersMeansNoChangeAtAll) {
  FeederSet set;
  dContact c = contact(part_, plain_, {1, 2, 3}, {0, 0, 1});
  const dContact before = c;
  set.beginStep(0.0);
  EXPECT_EQ(set.driveContacts(&c, 1), 1);
  EXPECT_EQ(std::memcmp(&c, &before, sizeof c), 0);
  EXPECT_EQ(set.driveContacts(&c, 0), 0);
  // Caller bugs drive nothing and create no joint, with or without feeders (bad_input_test).
  std::vector<Diagnostic> seen;
  set.setDiagnosticHandler([&seen](const Diagnostic& d) { seen.push_back(d); });
  EXPECT_EQ(set.driveContacts(nullptr, 3), 0);
  EXPECT_EQ(set.driveContacts(&c, -2), 0);
  EXPECT_EQ(set.invalidCalls(), 2u);
  EXPECT_EQ(seen.size(), 2u);
}

// ---------------------------------------------------------------------------------------------
// Counters and records

TEST_F(HandMadeContacts, StatsCountThisStepsFeederContactsOnBothFeeders) {
  FeederSet set;
  set.add(static_feeder_, MotionLaw::belt({1, 0, 0}, 0.3));
  set.add(body_feeder_, MotionLaw::belt({0, 1, 0}, 0.2, Frame::Body));
  std::vector<dContact> c = {
      contact(static_feeder_, part_, {0, 0, 0}, {0, 0, 1}),
      contact(part_, static_feeder_, {0.1, 0, 0}, {0, 0, -1}),
      contact(static_feeder_, body_feeder_, {0.2, 0, 0}, {0, 0, 1}),  // feeder on feeder
      contact(body_feeder_, part_, {0.3, 0, 0}, {0, 0, 1}),
      contact(part_, plain_, {0.4, 0, 0}, {0, 0, 1}),
  };
  set.beginStep(0.0);
  ASSERT_EQ(set.driveContacts(c.data(), static_cast<int>(c.size())), 5);
  EXPECT_EQ(set.stats(static_feeder_).contacts_driven, 3);
  EXPECT_EQ(set.stats(body_feeder_).contacts_driven, 2);
  // A new step starts the count again.
  set.beginStep(0.01);
  EXPECT_EQ(set.stats(static_feeder_).contacts_driven, 0);
  EXPECT_EQ(set.stats(body_feeder_).contacts_driven, 0);
}

TEST_F(HandMadeContacts, UndrivenFeederFeederContactCountsOnBothFeeders) {
  // Two feeders with equal surface velocities: c_rel = 0, the contact is undriven. It is a
  // contact of both feeders, so each feeder's driven + undriven counts must include it, as a
  // driven feeder-feeder contact is counted as driven on both.
  FeederSet set;
  set.add(static_feeder_, MotionLaw::belt({1, 0, 0}, 0.3));
  set.add(body_feeder_, MotionLaw::belt({1, 0, 0}, 0.3));
  dContact c = contact(static_feeder_, body_feeder_, {0, 0, 0}, {0, 0, 1});
  set.beginStep(0.0);
  ASSERT_EQ(set.driveContacts(&c, 1), 1);
  EXPECT_FALSE(c.surface.mode & dContactMotion1);
  for (dGeomID g : {static_feeder_, body_feeder_}) {
    const FeederStats s = set.stats(g);
    EXPECT_EQ(s.contacts_driven + s.contacts_undriven, 1) << (g == static_feeder_ ? "g1" : "g2");
  }
}

TEST_F(HandMadeContacts, RecordsDescribeEachFeederContactOfTheStep) {
  FeederSet::Options options;
  options.record_contacts = true;
  FeederSet set(options);
  set.add(static_feeder_, MotionLaw::belt({1, 0, 0}, 0.3));
  std::vector<dContact> c = {
      contact(part_, static_feeder_, {0.1, 0.2, 0.3}, {0, 0, -1}),
      contact(part_, plain_, {0.4, 0, 0}, {0, 0, 1}),
  };
  set.beginStep(0.0);
  set.driveContacts(c.data(), 2);
  ASSERT_EQ(set.records().size(), 1u);
  const ContactRecord& r = set.records()[0];
  EXPECT_EQ(r.feeder, static_feeder_);
  EXPECT_EQ(r.part, part_);
  EXPECT_EQ(r.position, (Vec3{0.1, 0.2, 0.3}));
  EXPECT_EQ(r.normal, (Vec3{0, 0, -1}));
  EXPECT_NEAR(r.surface_velocity.x, 0.3, kRoundOff);
  EXPECT_NEAR(r.surface_velocity.y, 0.0, kRoundOff);
  EXPECT_NEAR(r.surface_velocity.z, 0.0, kRoundOff);
  set.beginStep(0.01);
  EXPECT_TRUE(set.records().empty());
}

// ---------------------------------------------------------------------------------------------
// Evaluate only what a law needs

TEST_F(HandMadeContacts, FieldIsCalledOncePerFeederContact) {
  int calls = 0;
  FeederSet set;
  set.add(static_feeder_, MotionLaw::field([&calls](const Vec3&, const Vec3&, double) {
            ++calls;
            return Vec3{0.1, 0, 0};
          }));
  std::vector<dContact> c;
  for (int i = 0; i < 5; ++i)
    c.push_back(contact(static_feeder_, part_, {0.1 * i, 0, 0}, {0, 0, 1}));
  for (int i = 0; i < 3; ++i) c.push_back(contact(part_, plain_, {0, 0, 0}, {0, 0, 1}));
  for (int step = 0; step < 4; ++step) {
    std::vector<dContact> copy = c;
    set.beginStep(0.01 * step);
    set.driveContacts(copy.data(), static_cast<int>(copy.size()));
  }
  EXPECT_EQ(calls, 4 * 5);
}

TEST_F(HandMadeContacts, ProfileAndTwistFunctionAreCalledOncePerStepPerFeeder) {
  int profile_calls = 0, twist_calls = 0;
  FeederSet set;
  set.add(
      static_feeder_,
      MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::function([&profile_calls](double t) {
        ++profile_calls;
        return 1.0 + t;
      })));
  set.add(body_feeder_, MotionLaw::twistFunction([&twist_calls](double t) {
            ++twist_calls;
            return Twist{{t, 0, 0}, {0, 0, 1}, {0, 0, 0}};
          }));
  constexpr int kSteps = 6;
  for (int step = 0; step < kSteps; ++step) {
    // Several contacts on each feeder, in two separate driveContacts calls.
    std::vector<dContact> a, b;
    for (int i = 0; i < 4; ++i) {
      a.push_back(contact(static_feeder_, part_, {0.1 * i, 0, 0}, {0, 0, 1}));
      b.push_back(contact(part_, body_feeder_, {0, 0.1 * i, 0}, {0, 0, -1}));
    }
    set.beginStep(0.01 * step);
    set.driveContacts(a.data(), 4);
    set.driveContacts(b.data(), 4);
  }
  EXPECT_EQ(profile_calls, kSteps);
  EXPECT_EQ(twist_calls, kSteps);
  // A step without contacts on a feeder evaluates nothing of its law.
  set.beginStep(1.0);
  EXPECT_EQ(profile_calls, kSteps);
  EXPECT_EQ(twist_calls, kSteps);
}

TEST_F(HandMadeContacts, FieldIsNotCalledWhileItsProfileIsZero) {
  int calls = 0;
  FeederSet set;
  set.add(static_feeder_, MotionLaw::field([&calls](const Vec3&, const Vec3&, double) {
                            ++calls;
                            return Vec3{0.1, 0, 0};
                          }).withProfile(TimeProfile::onOff(1.0)));
  dContact c = contact(static_feeder_, part_, {0, 0, 0}, {0, 0, 1});
  set.beginStep(0.5);
  set.driveContacts(&c, 1);
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(c.surface.mode & dContactMotion1);
  c = contact(static_feeder_, part_, {0, 0, 0}, {0, 0, 1});
  set.beginStep(1.5);
  set.driveContacts(&c, 1);
  EXPECT_EQ(calls, 1);
  EXPECT_TRUE(c.surface.mode & dContactMotion1);
}

// ---------------------------------------------------------------------------------------------
// Unusual but valid contacts

TEST_F(HandMadeContacts, ContactAgainstANullGeomIsDrivenAsAgainstStaticGround) {
  // ODE's contact joint never reads geom.g1/g2, so an application may hand-make a contact
  // whose other geom is 0 (the static environment). It must be driven, not crash ODE's
  // dGeomGetBody, and a body feeder then gets node0 = its own body.
  FeederSet::Options options;
  options.record_contacts = true;
  FeederSet set(options);
  set.add(body_feeder_, MotionLaw::belt({1, 0, 0}, 0.3));
  dContact c = contact(body_feeder_, nullptr, {0, 0, 0}, {0, 0, 1});
  set.beginStep(0.0);
  ASSERT_EQ(set.driveContacts(&c, 1), 1);
  ASSERT_TRUE(c.surface.mode & dContactMotion1);
  // Feeder body first: (v_F - 0) . fdir1 = motion1 must move the feeder's body against its
  // surface motion, i.e. at -0.3 along x.
  const Vec3 imposed = c.surface.motion1 * fdir1(c);
  EXPECT_NEAR(imposed.x, -0.3, kRoundOff);
  ASSERT_EQ(set.records().size(), 1u);
  const Vec3 slip = set.slip(set.records()[0]);  // bodies at rest: slip = -surface velocity
  EXPECT_NEAR(slip.x, -0.3, kRoundOff);
}

TEST_F(HandMadeContacts, RecordOfAContactLeftUndrivenByABadLawImposesNothing) {
  FeederSet::Options options;
  options.record_contacts = true;
  FeederSet set(options);
  set.setDiagnosticHandler([](const Diagnostic&) {});
  set.add(static_feeder_, MotionLaw::field([](const Vec3&, const Vec3&, double) {
            return Vec3{std::nan(""), 0, 0};
          }));
  dContact c = contact(static_feeder_, part_, {0, 0, 0}, {0, 0, 1});
  set.beginStep(0.0);
  set.driveContacts(&c, 1);
  ASSERT_EQ(set.records().size(), 1u);
  EXPECT_EQ(set.records()[0].surface_velocity, (Vec3{0, 0, 0}));
  EXPECT_TRUE(isFinite(set.slip(set.records()[0])));
}

}  // namespace rheofeed::test
