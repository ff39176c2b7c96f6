// SPDX-License-Identifier: MIT
// The same step solved three ways must give the same motion: APGD on the dense Delassus matrix,
// APGD matrix-free (used above Settings::dense_contact_limit contacts) and projected Gauss-Seidel.
//
// Oracle: the contact velocities u = N gamma + r of a CCP are unique even where the impulses
// are not (N rank deficient: a box on four corners), and so are the body velocities
// v+ = v_free + M^-1 D gamma (N gamma1 = N gamma2 implies D gamma1 = D gamma2 for N = D^T M^-1 D).
// One step from the same state therefore gives the same velocities to the solvers' tolerance.
// (Over many steps contact sets can switch differently, so only one step is compared.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "reference_fixture.hpp"

namespace rheofeed::reference::test {
namespace {

constexpr double kStep = 1e-3;  // s
// Converged solves (1e-8 relative residual) of problems with |r| ~ 1 m/s.
constexpr double kAgreementTolerance = 1e-6;  // m/s

enum class Scene { Stack, SlidingBlock, BeltBox };

const char* name(Scene scene) {
  switch (scene) {
    case Scene::Stack:
      return "stack";
    case Scene::SlidingBlock:
      return "sliding block";
    case Scene::BeltBox:
      return "box on belt";
  }
  return "?";
}

/// Builds `scene`, takes one step, returns every body's linear and angular velocity (the latter
/// times 0.1 m, a typical lever arm) as one list of numbers (m/s).
std::vector<double> oneStep(Scene scene, const Settings& settings, StepReport* report) {
  World world(settings);
  const dGeomID ground = addGround(world);
  std::vector<BodyId> ids;
  switch (scene) {
    case Scene::Stack: {
      double z = -1e-9;  // slightly interpenetrating, see stack_test.cpp
      const double widths[] = {0.4, 0.3, 0.2, 0.1}, masses[] = {1.0, 3.0, 0.5, 2.0};
      for (int k = 0; k < 4; ++k) {
        const double centre = z + 0.05;
        ids.push_back(
            addBox(world, masses[k], {widths[k], widths[k], 0.1}, restingAt({0, 0, centre})).id);
        z = centre + 0.05 - 1e-9;
      }
      break;
    }
    case Scene::SlidingBlock: {
      BodyState s = restingAt({0, 0, 0.05 - 1e-6});
      s.linear_velocity = {1.0, 0.3, 0};
      s.angular_velocity = {0, 0, 2.0};
      ids.push_back(addBox(world, 1.0, {0.1, 0.1, 0.1}, s).id);
      break;
    }
    case Scene::BeltBox:
      world.setFeeder(ground, MotionLaw::belt({1, 1, 0}, 0.5));
      ids.push_back(addBox(world, 1.0, {0.1, 0.2, 0.1}, restingAt({0, 0, 0.05 - 1e-6})).id);
      break;
  }
  *report = world.step(kStep);
  std::vector<double> v;
  for (BodyId id : ids) {
    const BodyState& s = world.state(id);
    for (const Vec3& a : {s.linear_velocity, 0.1 * s.angular_velocity}) {
      v.insert(v.end(), {a.x, a.y, a.z});
    }
  }
  return v;
}

struct Variant {
  const char* label;
  ccp::Method method;
  bool matrix_free;
};

void expectAgreement(double cfm, int coulomb_outer_iterations) {
  const Variant variants[] = {{"APGD dense", ccp::Method::Apgd, false},
                              {"APGD matrix-free", ccp::Method::Apgd, true},
                              {"PGS dense", ccp::Method::Pgs, false},
                              {"PGS matrix-free", ccp::Method::Pgs, true}};
  for (Scene scene : {Scene::Stack, Scene::SlidingBlock, Scene::BeltBox}) {
    SCOPED_TRACE(name(scene));
    std::vector<double> reference;
    for (const Variant& variant : variants) {
      SCOPED_TRACE(variant.label);
      Settings settings = coulomb_outer_iterations > 0 ? coulombSettings(coulomb_outer_iterations)
                                                       : defaultSettings();
      settings.cfm = cfm;
      settings.default_mu = 0.4;
      settings.solver.method = variant.method;
      settings.dense_contact_limit = variant.matrix_free ? 0 : 100;
      StepReport report;
      const std::vector<double> v = oneStep(scene, settings, &report);
      EXPECT_EQ(report.solve.status, ccp::Status::Converged)
          << ccp::toString(report.solve.status) << " after " << report.solve.iterations;
      if (reference.empty()) {
        reference = v;
        continue;
      }
      ASSERT_EQ(v.size(), reference.size());
      double worst = 0;
      for (std::size_t k = 0; k < v.size(); ++k)
        worst = std::max(worst, std::abs(v[k] - reference[k]));
      std::printf(
          "%s, cfm %g, %s: %s vs APGD dense: max velocity difference %.2e m/s (%d contacts, "
          "%d iterations)\n",
          coulomb_outer_iterations > 0 ? "Coulomb" : "relaxed", cfm, name(scene), variant.label,
          worst, report.contacts, report.solve.iterations);
      EXPECT_LE(worst, kAgreementTolerance);
    }
  }
}

TEST(ReferenceSolverAgreement, DenseMatrixFreeAndPgsGiveTheSameStepWithoutCfm) {
  initOdeOnce();
  expectAgreement(0.0, 0);
}

TEST(ReferenceSolverAgreement, DenseMatrixFreeAndPgsGiveTheSameCoulombStepWithoutCfm) {
  initOdeOnce();
  expectAgreement(0.0, 50);
}

// ODE's CFM (impulse-space compliance cfm / h on the diagonal of N) must apply on the
// matrix-free path too, or scenes above Settings::dense_contact_limit contacts change physics:
// without it a resting stack chatters at up to ~1e-3 m/s, as with cfm = 0.
TEST(ReferenceSolverAgreement, MatrixFreePathAppliesCfmLikeTheDensePath) {
  initOdeOnce();
  expectAgreement(Settings{}.cfm, 0);
}

}  // namespace
}  // namespace rheofeed::reference::test
