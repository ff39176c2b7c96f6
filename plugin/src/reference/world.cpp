// SPDX-License-Identifier: MIT
// The reference world: ODE collision in, Eigen cone complementarity out (see world.hpp). This
// file holds the world's construction and accessors; a step's stages are in world_step.cpp and
// world_contacts.cpp (world_internal.hpp).
#include "rheofeed/reference/world.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "rheofeed/collision_space.hpp"
#include "rheofeed/reference/contact_problem.hpp"
#include "world_internal.hpp"

namespace rheofeed::reference {

using detail::refuse;
using detail::toEigen;
using detail::toQuat;
using Impl = WorldState;

const char* toString(CoulombSolver solver) {
  switch (solver) {
    case CoulombSolver::Nsgs:
      return "NSGS";
    case CoulombSolver::RelaxedFixedPoint:
      return "RelaxedFixedPoint";
  }
  return "Unknown";
}

namespace {

// Empty when `settings` are usable, else a message naming the first bad value. Checked by the
// constructor and again by every step, since World::settings() hands out a mutable reference.
std::string settingsProblem(const Settings& settings) {
  std::ostringstream bad;
  if (!(settings.erp >= 0 && settings.erp <= 1))
    bad << "Settings::erp = " << settings.erp << " must be in [0, 1]";
  else if (!(settings.cfm >= 0) || !std::isfinite(settings.cfm))
    bad << "Settings::cfm = " << settings.cfm << " must be finite and >= 0";
  else if (!(settings.max_correcting_velocity >= 0))
    bad << "Settings::max_correcting_velocity = " << settings.max_correcting_velocity
        << " must be >= 0";
  else if (!(settings.surface_layer >= 0) || !std::isfinite(settings.surface_layer))
    bad << "Settings::surface_layer = " << settings.surface_layer << " must be finite and >= 0";
  else if (settings.max_contacts_per_pair < 1)
    bad << "Settings::max_contacts_per_pair = " << settings.max_contacts_per_pair
        << " must be >= 1";
  else if (!(settings.default_mu >= 0) || !std::isfinite(settings.default_mu))
    bad << "Settings::default_mu = " << settings.default_mu << " must be finite and >= 0";
  else if (!(settings.restitution >= 0 && settings.restitution <= 1))
    bad << "Settings::restitution = " << settings.restitution << " must be in [0, 1]";
  else if (!(settings.bounce_velocity >= 0) || !std::isfinite(settings.bounce_velocity))
    bad << "Settings::bounce_velocity = " << settings.bounce_velocity
        << " must be finite and >= 0 (m/s)";
  else if (!isFinite(settings.gravity))
    bad << "Settings::gravity is not finite";
  else if (std::string m = settings.solver.validate(); !m.empty())
    bad << "Settings::solver: " << m;
  else if (!(settings.warm_start_distance >= 0) || !std::isfinite(settings.warm_start_distance))
    bad << "Settings::warm_start_distance = " << settings.warm_start_distance
        << " must be finite and >= 0 (m)";
  else if (settings.coulomb_solver != CoulombSolver::Nsgs &&
           settings.coulomb_solver != CoulombSolver::RelaxedFixedPoint)
    bad << "Settings::coulomb_solver is not Nsgs or RelaxedFixedPoint";
  else if (std::string nsgs = settings.nsgs.validate(); !nsgs.empty())
    bad << "Settings::nsgs: " << nsgs;
  else if (std::string ipm = settings.ipm.validate(); !ipm.empty())
    bad << "Settings::ipm: " << ipm;
  else if (settings.ipm_rounds < 0)
    bad << "Settings::ipm_rounds = " << settings.ipm_rounds << " must be >= 0";
  else if (settings.ipm_max_contacts < 0)
    bad << "Settings::ipm_max_contacts = " << settings.ipm_max_contacts << " must be >= 0";
  return bad.str();
}

}  // namespace

World::World(const Settings& settings) : impl_(std::make_unique<WorldState>()) {
  if (std::string bad = settingsProblem(settings); !bad.empty()) refuse(bad);
  impl_->settings = settings;
  impl_->solver.settings() = settings.solver;
  // ODE's collision module must be initialised once per process before any geom is used.
  static const bool ode_initialised = (dInitODE2(0), true);
  (void)ode_initialised;
  impl_->space = rheofeed::createCollisionSpace(nullptr, settings.broad_phase);
}

World::~World() {
  if (impl_ && impl_->space) dSpaceDestroy(impl_->space);
}

dSpaceID World::space() const {
  return impl_->space;
}

BodyId World::addBody(double mass, const double inertia[9], const BodyState& state) {
  if (!(mass > 0) || !std::isfinite(mass)) {
    std::ostringstream out;
    out << "addBody: mass = " << mass << " must be finite and > 0 (kg)";
    refuse(out.str());
  }
  Matrix3d i;
  for (int k = 0; k < 9; ++k) {
    if (!std::isfinite(inertia[k]))
      refuse("addBody: inertia[" + std::to_string(k) + "] is not finite");
    i(k / 3, k % 3) = inertia[k];
  }
  if ((i - i.transpose()).norm() > 1e-12 * i.norm()) refuse("addBody: inertia is not symmetric");
  Eigen::SelfAdjointEigenSolver<Matrix3d> eig(i);
  if (eig.eigenvalues().minCoeff() <= 0) {
    std::ostringstream out;
    out << "addBody: inertia has eigenvalue " << eig.eigenvalues().minCoeff()
        << " <= 0 (must be positive definite, kg m^2)";
    refuse(out.str());
  }
  if (!isFinite(state.position) || !isFinite(state.linear_velocity) ||
      !isFinite(state.angular_velocity)) {
    refuse("addBody: initial state is not finite");
  }
  Impl::Body b;
  b.mass = mass;
  b.inertia_body = i;
  b.inv_inertia_body = i.inverse();
  b.state = state;
  b.state.orientation = toQuat(toEigen(state.orientation).normalized());
  int dof = 0;
  for (const auto& other : impl_->bodies) dof += other.kinematic ? 0 : 6;
  b.dof = dof;
  impl_->bodies.push_back(b);
  return static_cast<BodyId>(impl_->bodies.size() - 1);
}

BodyId World::addKinematicBody(MotionOfTime motion) {
  if (!motion) refuse("addKinematicBody: motion function is empty");
  Impl::Body b;
  b.kinematic = true;
  b.mass = std::numeric_limits<double>::infinity();
  b.motion = std::move(motion);
  const Pose p = b.motion(impl_->time);
  if (!isFinite(p.position)) refuse("addKinematicBody: motion(t) position is not finite");
  b.state.position = p.position;
  b.state.orientation = toQuat(p);
  impl_->bodies.push_back(std::move(b));
  return static_cast<BodyId>(impl_->bodies.size() - 1);
}

void World::attachGeom(dGeomID geom, BodyId body, const Pose& offset) {
  if (!geom) refuse("attachGeom: geom is null");
  if (body < 0 || body >= numBodies())
    refuse("attachGeom: body " + std::to_string(body) + " does not exist");
  if (dGeomGetBody(geom))
    refuse("attachGeom: geom has an ODE body; reference geoms must have none");
  if (dGeomGetSpace(geom) != impl_->space) refuse("attachGeom: geom is not in World::space()");
  if (impl_->attached_index.count(geom)) refuse("attachGeom: geom is already attached");
  if (!isFinite(offset.position)) refuse("attachGeom: offset position is not finite");
  impl_->attached_index.emplace(geom, impl_->attached.size());
  impl_->attached.push_back(Impl::Attached{geom, body, offset});
}

void World::setFeeder(dGeomID geom, MotionLaw law) {
  if (!geom) refuse("setFeeder: geom is null");
  std::ostringstream where;
  where << "rheofeed::reference::World::setFeeder: geom " << static_cast<const void*>(geom);
  law.validate(where.str());
  auto it = impl_->feeder_index.find(geom);
  if (it != impl_->feeder_index.end()) {
    impl_->feeders[it->second].law = std::move(law);
    return;
  }
  impl_->feeder_index.emplace(geom, impl_->feeders.size());
  impl_->feeders.push_back(Impl::Feeder{geom, std::move(law), StepLaw{}});
}

void World::setBodyEfficiency(BodyId body, double factor) {
  if (body < 0 || body >= static_cast<BodyId>(impl_->bodies.size()) ||
      impl_->bodies[static_cast<std::size_t>(body)].kinematic) {
    refuse("setBodyEfficiency: body " + std::to_string(body) + " is not a dynamic body");
  }
  if (!(factor >= 0 && factor <= kMaxEfficiency)) {
    std::ostringstream out;
    out << "setBodyEfficiency: factor = " << factor << " must be in [0, " << kMaxEfficiency << "]";
    refuse(out.str());
  }
  impl_->bodies[static_cast<std::size_t>(body)].efficiency = factor;
}

void World::setFrictionCallback(FrictionCallback callback) {
  impl_->friction = std::move(callback);
}

void World::setStepObserver(StepObserver observer) {
  impl_->observer = std::move(observer);
}

void World::addForce(BodyId body, const Vec3& force, const Vec3& torque) {
  if (body < 0 || body >= numBodies())
    refuse("addForce: body " + std::to_string(body) + " does not exist");
  if (!isFinite(force) || !isFinite(torque)) refuse("addForce: force or torque is not finite");
  impl_->bodies[body].force += toEigen(force);
  impl_->bodies[body].torque += toEigen(torque);
}

Quat toQuat(const Pose& pose) {
  return toQuat(Eigen::Quaterniond(detail::rotationOf(pose)).normalized());
}

Pose toPose(const Quat& q, const Vec3& position) {
  return detail::poseOf(toEigen(position), toEigen(q).normalized().toRotationMatrix());
}

StepReport World::step(double h) {
  Impl& s = *impl_;
  if (!(h > 0) || !std::isfinite(h)) {
    std::ostringstream out;
    out << "step: h = " << h << " must be finite and > 0 (s)";
    refuse(out.str());
  }
  if (std::string bad = settingsProblem(s.settings); !bad.empty()) refuse("step: " + bad);
  StepContext c(s, h, s.settings);
  kinematicsStage(c);
  freeVelocityStage(c);
  collisionStage(c);
  c.nc = static_cast<int>(s.raw.size());
  c.report.contacts = c.nc;
  c.v_next = c.v_free;
  c.out.resize(static_cast<std::size_t>(c.nc));
  if (c.nc > 0) {
    contactRowsStage(c);
    problemStage(c);
    warmStartStage(c);
    solveStage(c);
    recordStage(c);
  } else {
    s.warm.clear();
  }
  s.contacts = std::move(c.out);
  integrationStage(c);
  s.time += h;
  if (s.observer) s.observer(*this, c.report);
  return std::move(c.report);
}

void World::disableBody(BodyId body) {
  if (body < 0 || body >= numBodies() || impl_->bodies[body].kinematic) {
    refuse("disableBody: " + std::to_string(body) + " is not a dynamic body");
  }
  impl_->disable(body);
}

double World::time() const {
  return impl_->time;
}
int World::numBodies() const {
  return static_cast<int>(impl_->bodies.size());
}
const BodyState& World::state(BodyId body) const {
  if (body < 0 || body >= numBodies())
    refuse("state: body " + std::to_string(body) + " does not exist");
  return impl_->bodies[body].state;
}
double World::mass(BodyId body) const {
  if (body < 0 || body >= numBodies())
    refuse("mass: body " + std::to_string(body) + " does not exist");
  return impl_->bodies[body].mass;
}
const std::vector<ContactImpulse>& World::contacts() const {
  return impl_->contacts;
}
Settings& World::settings() {
  return impl_->settings;
}

const ccp::Problem& lastContactProblem(const World& world) {
  return world.impl_->problem;
}

}  // namespace rheofeed::reference
