// SPDX-License-Identifier: MIT
// A scene run in the reference world (rheofeed::reference::World, cone complementarity).
#include <algorithm>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "geom_factory.hpp"
#include "rheofeed/reference/world.hpp"
#include "rheofeed/simulation/reference_simulation.hpp"
#include "simulation_internal.hpp"
#include "stage_clock.hpp"

namespace rheofeed::scene {
namespace {

using reference::BodyId;

class ReferenceSimulation final : public PartSimulation {
 public:
  ReferenceSimulation(const Scene& scene, Method method, reference::StepObserver observer,
                      const ReferenceSettingsAdjust& adjust = {})
      : PartSimulation(scene, method) {
    reference::Settings s;
    s.gravity = scene.gravity;
    s.erp = scene.solver.erp;
    s.broad_phase = scene.solver.broad_phase;
    s.cfm = scene.solver.cfm;
    s.default_mu = scene.material.mu;
    s.restitution = scene.material.restitution;  // Newton's impact law, as ODE's dContactBounce
    s.bounce_velocity = 0;                       // as the ODE engine's surface.bounce_vel
    s.solver.method = scene.solver.apgd ? ccp::Method::Apgd : ccp::Method::Pgs;
    s.solver.max_iterations = scene.solver.iterations;
    s.solver.tolerance = scene.solver.tolerance;
    s.solver.coulomb_outer_iterations = scene.solver.coulomb_iterations;
    s.max_correcting_velocity = scene.solver.max_correcting_velocity;
    s.surface_layer = scene.solver.surface_layer;
    if (adjust) adjust(s);
    world_ = std::make_unique<reference::World>(s);
    recordApplied(world_->settings());
    world_->setStepObserver(std::move(observer));

    for (std::size_t fi = 0; fi < scene.fixtures.size(); ++fi) {
      const Fixture& f = scene.fixtures[fi];
      const bool vibrates = isFullVibration(method) && f.law.kind == FeederLaw::Kind::Vibration;
      BodyId body = reference::kStatic;
      if (vibrates) {
        const Vibration v = f.law.vibration;
        body = world_->addKinematicBody([v](double t) { return v.displacement(t); });
      }
      MotionLaw law;  // one law per fixture: its geoms share the local law's table
      if (body == reference::kStatic && f.law.kind != FeederLaw::Kind::None) {
        law = feederLaw(static_cast<int>(fi));
      }
      for (const Fixture::Geom& g : f.geoms) {
        dGeomID geom = createGeom(world_->space(), g.shape, meshes_);
        if (g.shape.kind != Shape::Kind::Plane) setGeomPose(geom, g.pose);
        if (body != reference::kStatic) {
          world_->attachGeom(geom, body, g.pose);  // the body's rest pose is the identity
        } else if (f.law.kind != FeederLaw::Kind::None) {
          world_->setFeeder(geom, law);
        }
        addFixtureGeom(geom, static_cast<int>(fi));
      }
    }
    listIgnoredSettings();
    spawnDue();
  }

  // What the world took (AppliedSolver), after any adjustment: the mode its solve stage picks
  // from the settings (world_contacts.cpp, solveStage) and what that mode reads.
  void recordApplied(const reference::Settings& s) {
    AppliedSolver& a = applied_;
    a.engine = "reference";
    const bool coulomb = s.solver.coulomb_outer_iterations > 0;
    const bool nsgs = coulomb && s.coulomb_solver == reference::CoulombSolver::Nsgs;
    a.mode = !coulomb ? "relaxed_ccp" : nsgs ? "coulomb_nsgs" : "coulomb_fixed_point";
    a.iterations = nsgs ? s.nsgs.max_iterations : s.solver.max_iterations;
    a.tolerance = s.solver.tolerance;
    if (!nsgs) a.relaxed_solver = s.solver.method == ccp::Method::Apgd ? "apgd" : "pgs";
    if (coulomb && !nsgs) a.coulomb_iterations = s.solver.coulomb_outer_iterations;
    if (nsgs) a.ipm_rounds = s.ipm_rounds;
    a.warm_start = s.warm_start;
    a.erp = s.erp;
    a.cfm = s.cfm;
    a.max_correcting_velocity = s.max_correcting_velocity;
    a.surface_layer = s.surface_layer;
    a.mu = s.default_mu;
    a.restitution = s.restitution;
    a.bounce_velocity = s.bounce_velocity;
  }

  // What one step's contact solve may run in the applied mode, and what its iteration count
  // counts (ccp/solver.cpp: the fixed point sums its rounds and normal re-solves;
  // world_contacts.cpp: after the interior-point rounds the best single solve is kept).
  std::string solveBudget() const {
    const std::string n = std::to_string(applied_.iterations.value_or(0));
    if (applied_.mode == "coulomb_fixed_point") {
      return std::to_string(applied_.coulomb_iterations.value_or(0)) + " rounds of at most " + n +
             " iterations each, then normal re-solves (the count sums them all)";
    }
    if (applied_.mode == "coulomb_nsgs") {  // the count is the kept solve's own
      return "at most " + n + " sweeps, then, while unconverged and where they can run, up to " +
             std::to_string(applied_.ipm_rounds.value_or(0)) +
             " interior-point and NSGS rounds (the count is the best of them)";
    }
    return "at most " + n + " iterations";
  }

  // Counts the steps whose contact solve cannot be trusted fully (RunHealth).
  void advance(double h) override {
    reference::StepReport report;
    {
      const StageClock solve(stageTiming() ? &stage_times_.solve : nullptr);  // StageTimes
      report = world_->step(h);
    }
    if (stageTiming()) {
      stage_times_.contact_count += report.contacts;
      stage_times_.constraint_rows += 3L * report.contacts;  // the cone: normal + 2 tangential
    }
    // Bodies the world found non-finite are disabled there at their last finite pose: counted
    // here as non-finite parts (their parked state alone would look fine).
    for (const BodyId body : report.nonfinite_bodies) {
      const auto it = std::find(parts_.begin(), parts_.end(), body);
      if (it != parts_.end()) markNonFinite(static_cast<int>(it - parts_.begin()));
    }
    if (report.solve.friction_dropped_contacts > 0) {
      health_.friction_dropped_contacts += report.solve.friction_dropped_contacts;
      std::ostringstream line;
      line << "step from t = " << time() << " s: the Coulomb fallback dropped the friction of "
           << report.solve.friction_dropped_contacts << " contacts to settle its normal impulses";
      reportFirst("friction dropped", line.str());
    }
    if (report.gyroscopic_fallbacks > 0) {
      ++health_.gyroscopic_fallback_steps;
      std::ostringstream line;
      line << "step from t = " << time() << " s: the implicit gyroscopic solve of "
           << report.gyroscopic_fallbacks
           << " bodies did not converge (h |w| far beyond 1); they took a dissipative step";
      reportFirst("gyroscopic fallback", line.str());
    }
    if (report.coulomb_fallback) {
      ++health_.coulomb_fallback_steps;
      std::ostringstream line;
      line << "step from t = " << time() << " s: the true-Coulomb fixed point did not settle in "
           << scene_.solver.coulomb_iterations << " iterations (" << report.contacts
           << " contacts); the step used the iterate with the lowest Coulomb residual ("
           << report.coulomb_residual << "), normal impulses re-solved so that friction launches "
           << "nothing";
      reportFirst("Coulomb fallback step", line.str());
    }
    if (report.ipm_rounds > 0) {
      ++health_.ipm_second_solve_steps;
      if (report.solve.status == ccp::Status::Converged) ++health_.ipm_converged_steps;
    }
    if (!report.ipm_not_run.empty()) {
      ++health_.ipm_not_run_steps;
      std::ostringstream line;
      line << "step from t = " << time() << " s: NSGS ended unconverged and the interior-point "
           << "rounds did not run: " << report.ipm_not_run;
      reportFirst("step without interior-point rounds", line.str());
    }
    if (report.contacts > 0 && report.solve.status != ccp::Status::Converged) {
      ++health_.solver_unconverged_steps;
      std::ostringstream line;
      line << "step from t = " << time() << " s: contact solve "
           << ccp::toString(report.solve.status) << " after " << report.solve.iterations
           << " iterations (" << report.contacts << " contacts; " << applied_.mode << " runs "
           << solveBudget() << " to solver.tolerance = " << scene_.solver.tolerance << ")";
      reportFirst("unconverged step", line.str());
    }
  }

  // The world keeps the body's own state (it cannot be set); PartSimulation reports `last`.
  void removePart(int i, const PartState&) override {
    world_->disableBody(parts_.at(static_cast<std::size_t>(i)));
  }

  PartState partState(int i) const override {
    const reference::BodyState& b = world_->state(parts_.at(static_cast<std::size_t>(i)));
    PartState s;
    s.position = b.position;
    s.velocity = b.linear_velocity;
    s.angular_velocity = b.angular_velocity;
    const Pose pose = reference::toPose(b.orientation);
    std::copy(pose.rotation, pose.rotation + 9, s.rotation);
    return s;
  }

 private:
  void addPart(const PartInstance& p) override {
    reference::BodyState state;
    state.position = p.pose.position;
    state.linear_velocity = p.velocity;
    state.orientation = reference::toQuat(p.pose);
    const BodyId body = world_->addBody(p.mass, p.inertia, state);
    dGeomID geom = createGeom(world_->space(), p.shape, meshes_);
    world_->attachGeom(geom, body);
    addPartGeom(geom, static_cast<int>(parts_.size()));
    const double efficiency = partEfficiency(p.spec);
    if (efficiency != 1.0) world_->setBodyEfficiency(body, efficiency);
    parts_.push_back(body);
  }

  ContactTotals fixtureImpulses(double) const override {
    ContactTotals totals;
    for (const reference::ContactImpulse& c : world_->contacts()) {
      const bool f1 = isFixture(c.g1), f2 = isFixture(c.g2);
      if (f1 == f2) continue;
      // Impulse on body1 (g1) is gamma_n n + gamma_t; on g2 its opposite.
      const Vec3 on_g1 = c.normal_impulse * c.normal + c.tangential_impulse;
      const Vec3 impulse = f1 ? -on_g1 : on_g1;
      ++totals.count;
      totals.normal_impulse += c.normal_impulse;
      totals.impulse = totals.impulse + impulse;
    }
    return totals;
  }

  std::vector<FixtureContact> fixtureContacts() const override {
    std::vector<FixtureContact> out;
    for (const reference::ContactImpulse& c : world_->contacts()) {
      const bool f1 = isFixture(c.g1), f2 = isFixture(c.g2);
      if (f1 == f2) continue;
      out.push_back(f1 ? FixtureContact{c.g2, c.g1, -c.normal}
                       : FixtureContact{c.g1, c.g2, c.normal});
    }
    return out;
  }

  // Settings of the scene the reference world does not read, when they differ from their
  // defaults.
  void listIgnoredSettings() {
    health_.friction_model = "cone";
    health_.broad_phase = toString(broadPhaseOf(world_->space()));
    if (scene_.solver.friction == FrictionModel::Pyramid) {
      ignoreSetting(
          "solver.friction = pyramid: ignored by the reference solver (it solves the cone)");
    }
    if (scene_.solver.speculative_contacts.value_or(false)) {
      ignoreSetting(
          "solver.speculative_contacts = true: ignored by the reference solver (it makes "
          "contacts only where geoms overlap)");
    }
    if (scene_.solver.warm_start.value_or(false)) {
      ignoreSetting(
          "solver.warm_start = true: ignored by the reference solver (its own solvers warm "
          "start as their settings say)");
    }
    if (!scene_.solver.ode_quickstep) {
      ignoreSetting(
          "solver.ode_quickstep = false: ignored by the reference solver (ODE's stepper choice)");
    }
    // The true-Coulomb NSGS mode (the default) runs its own sweeps: the relaxed solver's budget
    // and choice are not read, and coulomb_iterations only switches the mode on.
    if (applied_.mode == "coulomb_nsgs") {
      const SolverSettings defaults;
      const SolverSettings& s = scene_.solver;
      const std::string nsgs =
          "ignored by the reference solver's true-Coulomb NSGS (it runs up "
          "to " +
          std::to_string(applied_.iterations.value_or(0)) + " sweeps to solver.tolerance)";
      if (s.iterations != defaults.iterations) {
        ignoreSetting("solver.iterations = " + std::to_string(s.iterations) + ": " + nsgs);
      }
      if (s.apgd != defaults.apgd) {
        ignoreSetting(std::string("solver.apgd = ") + (s.apgd ? "true" : "false") + ": " + nsgs);
      }
      if (s.coulomb_iterations != defaults.coulomb_iterations) {
        ignoreSetting("solver.coulomb_iterations = " + std::to_string(s.coulomb_iterations) +
                      ": only switches the true-Coulomb mode on (any value > 0); " + nsgs);
      }
    }
  }

  TriMeshStore meshes_;  // declared before world_: destroyed after the world's space and geoms
  std::unique_ptr<reference::World> world_;
  std::vector<BodyId> parts_;
};

}  // namespace

std::unique_ptr<Simulation> makeReferenceSimulation(const Scene& scene, Method method) {
  return std::make_unique<ReferenceSimulation>(scene, method, reference::StepObserver{});
}

std::unique_ptr<Simulation> makeObservedReferenceSimulation(const Scene& scene, Method method,
                                                            reference::StepObserver observer) {
  return makeObservedReferenceSimulation(scene, method, std::move(observer), {});
}

std::unique_ptr<Simulation> makeObservedReferenceSimulation(const Scene& scene, Method method,
                                                            reference::StepObserver observer,
                                                            const ReferenceSettingsAdjust& adjust) {
  if (method != Method::ReferenceRheonomic && method != Method::ReferenceFullVibration) {
    throw std::invalid_argument(
        "makeObservedReferenceSimulation: method " + std::string(toString(method)) +
        " is not a reference method (reference_rheonomic, reference_full_vibration)");
  }
  scene.validate();
  return std::make_unique<ReferenceSimulation>(scene, method, std::move(observer), adjust);
}

}  // namespace rheofeed::scene
