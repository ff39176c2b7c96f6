// SPDX-License-Identifier: MIT
// ODE + rheofeed plugin against the reference cone-complementarity solver on small rheonomic
// scenes: belt, inclined belt (carried and slipping), turntable, helical ramp up and down, and a
// 50-box pile on a belt. For each scene it prints and writes (Markdown + CSV) the end states of
// both runs, their differences, the analytic expectation where one exists, and what explains a
// difference.
//
//   ode_vs_reference [--out out/ode_vs_reference] [--pile 50] [--friction cone|pyramid]
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "common/builtin_scenes.hpp"
#include "rheofeed/measure/compare.hpp"
#include "rheofeed/output/output.hpp"

namespace {

using namespace rheofeed;
using namespace rheofeed::scene;

struct Case {
  Scene scene;
  std::string expectation;  // analytic expectation, in words and numbers
  std::string causes;       // what explains the differences
};

std::vector<Case> cases(int pile) {
  const double g = 9.81;
  std::vector<Case> out;
  {
    Scene s = beltScene(0.3);
    out.push_back({s, "sticks at V = 0.3 m/s after V/(mu g) = 0.061 s",
                   "none expected: sticking contact, both enforce v = V exactly"});
  }
  {
    const double angle = 0.25;  // tan = 0.255 <= mu = 0.5
    Scene s = inclineBeltScene(angle, 0.2);
    out.push_back({s, "tan(theta) = 0.255 <= mu: carried up the slope at 0.2 m/s",
                   "none expected: sticking"});
  }
  {
    const double angle = 0.55;  // tan = 0.613 > mu = 0.5
    Scene s = inclineBeltScene(angle, 0.2);
    s.name = "incline_belt_slipping";
    s.duration = 0.6;  // before the part reaches the belt's lower end
    const double a = g * (std::sin(angle) - 0.5 * std::cos(angle));
    std::ostringstream e;
    e << "tan(theta) = 0.613 > mu: slides down at a = g (sin - mu cos) = " << a
      << " m/s^2, |v| = " << a * s.duration << " m/s at t = " << s.duration << " s";
    out.push_back({s, e.str(),
                   "sliding along fdir1 = belt direction, where even ODE's friction pyramid is "
                   "exact, so both models match the cone; the reference solves true Coulomb (the "
                   "relaxed CCP, "
                   "coulomb_iterations = 0, would launch the part at u_n = mu |u_t|)"});
  }
  {
    Scene s = turntableScene(1.0);
    out.push_back({s, "parts stick: |v| = w r = 0.15 and 0.30 m/s along w x r",
                   "none expected: sticking (centripetal w^2 r << mu g)"});
  }
  {
    Scene s = helicalRampScene(1.0);
    out.push_back({s, "climbs: w agrees with the helix's handedness",
                   "partial sliding on tilted segments and across the seams between them "
                   "(quickstep's iterations; with --friction pyramid also the pyramid's extra "
                   "grip off the drive direction)"});
  }
  {
    Scene s = helicalRampScene(-1.0);
    out.push_back({s, "descends: w reversed", "as above"});
  }
  {
    Scene s = pileOnBeltScene(pile, 0.3);
    out.push_back({s, "all parts end at V = 0.3 m/s; fixtures carry the weight m g per step",
                   "pile contacts are redundant (impulses not unique), ERP depth recovery, "
                   "solver tolerance"});
  }
  return out;
}

std::string fmt(const Vec3& v) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.4f, %.4f, %.4f)", v.x, v.y, v.z);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_dir = "out/ode_vs_reference";
  int pile = 50;
  CLI::App app{"ODE + rheofeed plugin vs the reference CCP solver on small rheonomic scenes"};
  app.add_option("--out", out_dir, "output folder");
  app.add_option("--pile", pile, "boxes in the pile scene")->check(CLI::Range(1, 2000));
  std::string friction;
  app.add_option("--friction", friction,
                 "ODE's friction model, cone or pyramid (solver.friction; default: the scenes' "
                 "own, the cone where the linked ODE has it)")
      ->check(CLI::IsMember({"cone", "pyramid"}));
  CLI11_PARSE(app, argc, argv);

  try {
    std::ostringstream md, csv;
    md << "| scene | ODE mean v (m/s) | reference mean v (m/s) | max |dv| (m/s) | max |dx| (m) "
          "| J_n per step ODE / ref (N s) | rel. dJ_n | expectation | causes of differences |\n"
       << "|---|---|---|---|---|---|---|---|---|\n";
    csv << "scene,parts,ode_vx,ode_vy,ode_vz,ref_vx,ref_vy,ref_vz,max_dv,max_dx,ode_jn,ref_jn,"
           "rel_djn,ode_mean_z,ref_mean_z,ode_cpu_s,ref_cpu_s\n";
    const std::vector<Case> all = cases(pile);
    for (std::size_t i = 0; i < all.size(); ++i) {
      Case c = all[i];
      if (!friction.empty()) {
        FrictionModel model = FrictionModel::Cone;
        parseFrictionModel(friction.c_str(), model);  // checked by CLI::IsMember
        c.scene.solver.friction = model;
      }
      std::fprintf(stderr, "[%zu/%zu] %s ...\n", i + 1, all.size(), c.scene.name.c_str());
      const Comparison r = compare(c.scene, Method::OdeRheonomic, Method::ReferenceRheonomic);
      char row[512];
      std::snprintf(
          row, sizeof row, "| %s | %s | %s | %.2e | %.2e | %.5f / %.5f | %.2e | %s | %s |\n",
          c.scene.name.c_str(), fmt(r.a.mean_velocity).c_str(), fmt(r.b.mean_velocity).c_str(),
          r.max_velocity_difference, r.max_position_difference, r.a.normal_impulse,
          r.b.normal_impulse, r.normal_impulse_difference, c.expectation.c_str(), c.causes.c_str());
      md << row;
      std::snprintf(
          row, sizeof row,
          "%s,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.4f,%.4f\n",
          c.scene.name.c_str(), r.a.parts, r.a.mean_velocity.x, r.a.mean_velocity.y,
          r.a.mean_velocity.z, r.b.mean_velocity.x, r.b.mean_velocity.y, r.b.mean_velocity.z,
          r.max_velocity_difference, r.max_position_difference, r.a.normal_impulse,
          r.b.normal_impulse, r.normal_impulse_difference, r.a.mean_position.z, r.b.mean_position.z,
          r.a.cpu_seconds, r.b.cpu_seconds);
      csv << row;
    }
    std::printf("%s", md.str().c_str());
    writeFileAtomically(std::filesystem::path(out_dir) / "ode_vs_reference.md", md.str());
    writeFileAtomically(std::filesystem::path(out_dir) / "ode_vs_reference.csv", csv.str());
    std::printf("\nwrote %s/ode_vs_reference.{md,csv}\n", out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ode_vs_reference: %s\n", e.what());
    return 2;
  }
  return 0;
}
