// SPDX-License-Identifier: MIT
//
// Why the reference world's crowded contact solves stall (issue 16): on fc3d problems (e.g. the
// unconverged steps of the main demo written by `ccp_solver_comparison --failures`), compares
//   NSGS         the world's true-Coulomb solver with its settings (ccp/nsgs.hpp, cold start);
//   IPM relaxed  the convex relaxation (shift 0) solved by a primal-dual interior-point method:
//                whether the problem's conditioning (rigid Delassus operator plus the compliance,
//                a condition number of ~1e7 on the trough) is what stops the solvers;
//   IPM + FP     De Saxce's fixed point on the normal shift s_i = mu_i ||u_t,i|| with that
//                exact convex solver inside (warm started): whether the true Coulomb problem
//                itself, not Gauss-Seidel, is slow.
// Where the fixed point ends unconverged it names the contact holding most of the residual, with
// its state, normal velocity and impulse: a sliding contact whose normal velocity is held away
// from 0 by the others moves its shift by that velocity in every outer iteration, so the fixed
// point creeps instead of converging.
//
// The interior-point method is ccp/ipm.hpp's (dense or matrix-free, as the problem comes).
//
// Usage: coulomb_stall_probe FILE... [--tolerance T] [--max-outer K] [--mu-scale A] [--out MD]

#include <CLI/CLI.hpp>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench/coulomb_residual.hpp"
#include "rheofeed/ccp/cone.hpp"
#include "rheofeed/ccp/fc3d_reader.hpp"
#include "rheofeed/ccp/ipm.hpp"
#include "rheofeed/ccp/nsgs.hpp"

namespace {

namespace ccp = rheofeed::ccp;
using Eigen::Vector3d;
using Eigen::VectorXd;
using rheofeed::bench::coulombResidual;

// The contact that holds most of the Coulomb residual at `gamma`: its share and state.
std::string worstContact(const ccp::Problem& p, const VectorXd& gamma) {
  const VectorXd errors = rheofeed::bench::coulombErrors(p, gamma);
  Eigen::Index worst = 0;
  errors.maxCoeff(&worst);
  const VectorXd u = p.contactVelocity(gamma);
  const Vector3d g = gamma.segment<3>(3 * worst);
  std::ostringstream s;
  s.precision(3);
  s << "contact " << worst << " (" << 100 * errors[worst] / errors.sum()
    << " % of the squared residual): "
    << (g[0] <= 0                                                  ? "open"
        : std::hypot(g[1], g[2]) < (1 - 1e-6) * p.mu[worst] * g[0] ? "stick"
                                                                   : "slide")
    << ", u_n " << u[3 * worst] << " m/s, |u_t| " << std::hypot(u[3 * worst + 1], u[3 * worst + 2])
    << " m/s, gamma_n " << g[0] << " N s";
  return s.str();
}

struct Probe {
  std::string file;
  int contacts = 0;
  double nsgs_residual = NAN, nsgs_s = NAN;
  int nsgs_sweeps = 0;
  double relaxed_residual = NAN, relaxed_s = NAN;
  int relaxed_iterations = 0;
  double fp_residual = NAN, fp_s = NAN;
  int fp_outer = 0, fp_ipm_iterations = 0;
  std::string creeping;  // the contact holding most of the residual, when unconverged
  std::string error;
};

Probe probe(const std::string& file, double tol, int max_outer, double mu_scale, int max_contacts) {
  Probe out;
  out.file = file;
  ccp::Problem p = ccp::readFc3dFile(file);
  p.mu *= mu_scale;
  const int nc = int(p.numContacts());
  out.contacts = nc;
  if (nc > max_contacts) {
    out.error = std::to_string(nc) + " contacts > --max-contacts " + std::to_string(max_contacts);
    return out;
  }
  {  // NSGS as the reference world runs it (its settings, the step's tolerance), cold start
    ccp::NsgsSettings settings;
    settings.tolerance = tol;
    ccp::NsgsSolver nsgs(settings);
    VectorXd gamma = VectorXd::Zero(p.size());
    const ccp::Result result = nsgs.solve(p, gamma);
    out.nsgs_s = result.solve_time_s;
    out.nsgs_sweeps = result.iterations;
    out.nsgs_residual = coulombResidual(p, gamma);
  }
  ccp::IpmSettings settings;
  settings.tolerance = 1e-2 * tol;
  settings.max_outer_iterations = max_outer;
  ccp::IpmSolver ipm(settings);
  {  // the relaxed CCP (shift 0)
    VectorXd gamma;
    const ccp::Result result = ipm.solveConvex(p, VectorXd::Zero(nc), gamma);
    if (result.status == ccp::Status::InvalidInput) {
      out.error = result.message;
      return out;
    }
    out.relaxed_iterations = result.iterations;
    out.relaxed_s = result.solve_time_s;
    const VectorXd zero = VectorXd::Zero(nc);
    out.relaxed_residual = coulombResidual(p, gamma, &zero);
  }
  {  // De Saxce's fixed point with the IPM inside, cold start
    ipm.settings().tolerance = tol;
    VectorXd gamma;
    const ccp::Result result = ipm.solve(p, gamma);
    out.fp_s = result.solve_time_s;
    out.fp_outer = result.outer_iterations;
    out.fp_ipm_iterations = result.iterations;
    out.fp_residual = coulombResidual(p, gamma);
    if (out.fp_residual > tol) out.creeping = worstContact(p, gamma);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "Why crowded Coulomb problems stall: NSGS, an interior-point method on the "
      "relaxation, and De Saxce's fixed point around it, on fc3d files");
  std::vector<std::string> files;
  double tol = 1e-6, mu_scale = 1.0;
  int max_outer = 40, max_contacts = 800;
  std::string out_file;
  app.add_option("files", files, "fc3d problems (.dat)")->required()->check(CLI::ExistingFile);
  app.add_option("--tolerance", tol, "Coulomb tolerance (the reference world's: 1e-6)")
      ->check(CLI::Range(1e-14, 1e-1));
  app.add_option("--max-outer", max_outer, "fixed-point iterations")->check(CLI::Range(1, 10000));
  app.add_option("--mu-scale", mu_scale, "multiply every friction coefficient by this")
      ->check(CLI::Range(1e-3, 10.0));
  app.add_option("--max-contacts", max_contacts, "skip larger problems (dense IPM)")
      ->check(CLI::Range(1, 5000));
  app.add_option("--out", out_file, "also write the table (markdown) to this file");
  CLI11_PARSE(app, argc, argv);

  std::ostringstream md;
  md << "Coulomb tolerance " << tol << ", friction coefficients x " << mu_scale
     << ", fixed point up to " << max_outer << " outer iterations (`coulomb_stall_probe`).\n\n"
     << "| problem | contacts | NSGS residual (sweeps, s) | IPM relaxed residual (iterations, s) "
        "| IPM + fixed point residual (outer, IPM iterations, s) | worst contact when unconverged "
        "|\n"
     << "|---|---:|---|---|---|---|\n";
  int failures = 0;
  for (size_t k = 0; k < files.size(); ++k) {
    std::fprintf(stderr, "[%zu/%zu] %s\n", k + 1, files.size(), files[k].c_str());
    Probe r;
    try {
      r = probe(files[k], tol, max_outer, mu_scale, max_contacts);
    } catch (const std::exception& e) {
      r.file = files[k];
      r.error = e.what();
    }
    char line[1024];
    if (!r.error.empty()) {
      ++failures;
      std::snprintf(line, sizeof line, "| %s | %d | not probed: %s | | | |\n",
                    std::filesystem::path(r.file).filename().c_str(), r.contacts, r.error.c_str());
    } else {
      std::snprintf(line, sizeof line,
                    "| %s | %d | %.2e (%d, %.2f) | %.2e (%d, %.2f) | %.2e (%d, %d, %.1f) "
                    "| %s |\n",
                    std::filesystem::path(r.file).filename().c_str(), r.contacts, r.nsgs_residual,
                    r.nsgs_sweeps, r.nsgs_s, r.relaxed_residual, r.relaxed_iterations, r.relaxed_s,
                    r.fp_residual, r.fp_outer, r.fp_ipm_iterations, r.fp_s, r.creeping.c_str());
    }
    md << line;
    std::fputs(line, stderr);
  }
  std::fputs(md.str().c_str(), stdout);
  if (!out_file.empty()) {
    const std::string tmp = out_file + ".tmp";
    std::ofstream f(tmp);
    f << md.str();
    f.close();
    if (!f || std::rename(tmp.c_str(), out_file.c_str()) != 0) {
      std::fprintf(stderr, "error: could not write %s\n", out_file.c_str());
      return 1;
    }
  }
  if (failures)
    std::fprintf(stderr, "%d of %zu problems not probed (table)\n", failures, files.size());
  return failures == int(files.size()) ? 1 : 0;
}
