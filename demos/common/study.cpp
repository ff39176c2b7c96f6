// SPDX-License-Identifier: MIT
#include "common/study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/builtin_scenes.hpp"
#include "rheofeed/measure/calibration.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/measure/statistics.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/output/plot.hpp"

namespace rheofeed::demo {

using namespace rheofeed::scene;

namespace {

constexpr double kTargetError = 0.05;  // "equal drift error": 5 % of the reference drift

struct Row {
  Method method;
  double time_step;
  double steps_per_cycle;  // 0 for rheonomic
  RunMetrics metrics;
  double error = 0;  // |drift - reference| / |reference|
};

int vibratingFixture(const Scene& s) {
  for (std::size_t i = 0; i < s.fixtures.size(); ++i) {
    if (s.fixtures[i].law.kind == FeederLaw::Kind::Vibration) return static_cast<int>(i);
  }
  throw std::invalid_argument("scene '" + s.name + "' has no vibrating feeder to study");
}

}  // namespace

std::string runStudy(const Scene& scene, const StudyOptions& options) {
  if (options.seeds < 1) {
    throw std::invalid_argument("seeds = " + std::to_string(options.seeds) + ": must be >= 1");
  }
  scene.validate();
  const int fixture = vibratingFixture(scene);
  const Vibration& vib = scene.fixtures[static_cast<std::size_t>(fixture)].law.vibration;
  const double f = vib.frequency;
  std::fprintf(stderr, "study: scene '%s', %.1f Hz, amplitude %.3g m\n", scene.name.c_str(), f,
               vib.amplitude);

  // 1. Converged reference: ODE full vibration at the finest step, several seeds.
  const int ref_steps_per_cycle = options.quick ? 400 : 1000;
  std::vector<double> ref_drifts;
  double ref_cpu = 0;
  for (int k = 0; k < options.seeds; ++k) {
    Scene s = scene;
    s.seed = scene.seed + k;
    s.solver.time_step = 1.0 / (f * ref_steps_per_cycle);
    const RunMetrics m = measureRun(s, Method::OdeFullVibration,
                                    stderrProgress("reference seed " + std::to_string(k + 1) + "/" +
                                                   std::to_string(options.seeds)));
    ref_drifts.push_back(m.mean_drift);
    ref_cpu += m.cpu_seconds;
  }
  const double ref = mean(ref_drifts);
  const double ref_ci = ci95(ref_drifts);
  if (std::abs(ref) < 1e-9)
    throw std::runtime_error("the reference drift is zero: nothing to study");
  std::fprintf(stderr, "reference drift %.6g +- %.2g m/s (%d seeds, %d steps/cycle)\n", ref, ref_ci,
               options.seeds, ref_steps_per_cycle);

  // 2. Calibration of the vibration into a drift field.
  CalibrationSettings cs;
  if (options.quick) cs.measure_cycles = 40;
  const Calibration cal = calibrateBySampling(scene, fixture, cs);
  std::fprintf(stderr, "calibrated drift %.6g +- %.2g m/s (efficiency %.3f, %.2f s CPU)\n",
               cal.value, cal.ci95, cal.efficiency, cal.cpu_seconds);
  const Scene calibrated = withCalibration(scene, cal);
  std::string classical_line;
  try {
    const Calibration estimate = calibrateClassical(scene, fixture);
    std::ostringstream q;
    q << "Classical single-part estimate: " << estimate.value << " m/s ("
      << 100 * std::abs(estimate.value - ref) / std::abs(ref) << " % from the reference).\n";
    classical_line = q.str();
  } catch (const std::exception& e) {
    classical_line =
        std::string("Classical single-part estimate: not applicable (") + e.what() + ").\n";
  }

  // 3. Sweeps.
  std::vector<Row> rows;
  const std::vector<double> spc =
      options.quick ? std::vector<double>{25, 100} : std::vector<double>{20, 50, 100, 200, 400};
  const std::vector<double> steps = options.quick
                                        ? std::vector<double>{0.02, 0.005}
                                        : std::vector<double>{0.04, 0.02, 0.01, 0.005, 0.0025};
  for (Method m : {Method::OdeFullVibration, Method::ReferenceFullVibration}) {
    for (double n : spc) {
      Scene s = scene;
      s.solver.time_step = 1.0 / (f * n);
      char label[96];
      std::snprintf(label, sizeof label, "%s %g steps/cycle", toString(m), n);
      rows.push_back({m, s.solver.time_step, n, measureRun(s, m, stderrProgress(label))});
    }
  }
  for (Method m : {Method::OdeRheonomic, Method::ReferenceRheonomic}) {
    for (double h : steps) {
      Scene s = calibrated;
      s.solver.time_step = h;
      s.outputs.sample_interval = std::max(h, scene.outputs.sample_interval);
      char label[96];
      std::snprintf(label, sizeof label, "%s h = %g s", toString(m), h);
      rows.push_back({m, h, 0, measureRun(s, m, stderrProgress(label))});
    }
  }
  for (Row& r : rows) r.error = std::abs(r.metrics.mean_drift - ref) / std::abs(ref);

  // 4. Outputs.
  std::ostringstream csv, md;
  csv << "method,time_step_s,steps_per_cycle,mean_drift_mps,ci95_mps,error,cpu_s,"
         "real_time_factor,parts\n";
  md << "Scene `" << scene.name << "`: reference drift " << ref << " m/s (+- " << ref_ci
     << ", ODE full vibration, " << ref_steps_per_cycle << " steps/cycle, " << options.seeds
     << " seeds); calibrated drift " << cal.value << " +- " << cal.ci95 << " m/s (" << cal.how
     << ", " << cal.cpu_seconds << " s CPU once).\n\n"
     << classical_line << "\n"
     << "| method | h (s) | steps/cycle | drift (m/s) | error | CPU (s) | real-time factor |\n"
     << "|---|---|---|---|---|---|---|\n";
  char line[256];
  for (const Row& r : rows) {
    std::snprintf(line, sizeof line, "%s,%.6g,%.6g,%.8g,%.6g,%.6g,%.6g,%.6g,%d\n",
                  toString(r.method), r.time_step, r.steps_per_cycle, r.metrics.mean_drift,
                  r.metrics.mean_drift_ci95, r.error, r.metrics.cpu_seconds,
                  r.metrics.real_time_factor, r.metrics.parts);
    csv << line;
    std::snprintf(line, sizeof line, "| %s | %.3g | %s | %.5f | %.1f %% | %.3f | %.4f |\n",
                  toString(r.method), r.time_step,
                  r.steps_per_cycle > 0 ? std::to_string(int(r.steps_per_cycle)).c_str() : "-",
                  r.metrics.mean_drift, 100 * r.error, r.metrics.cpu_seconds,
                  r.metrics.real_time_factor);
    md << line;
  }
  // Speed-up at equal error: cheapest run within the target error, per method.
  std::map<Method, double> cheapest;
  for (const Row& r : rows) {
    if (r.error > kTargetError) continue;
    auto it = cheapest.find(r.method);
    if (it == cheapest.end() || r.metrics.cpu_seconds < it->second) {
      cheapest[r.method] = r.metrics.cpu_seconds;
    }
  }
  md << "\nCheapest run within " << 100 * kTargetError << " % drift error:\n\n"
     << "| method | CPU (s) |\n|---|---|\n";
  for (const auto& [m, cpu] : cheapest) md << "| " << toString(m) << " | " << cpu << " |\n";
  auto speedup = [&](Method full, Method rheo) {
    if (!cheapest.count(full) || !cheapest.count(rheo))
      return std::string("n/a (a method never reached the target error)");
    std::ostringstream s;
    s << cheapest[full] / cheapest[rheo] << "x ("
      << cheapest[full] / (cheapest[rheo] + cal.cpu_seconds) << "x counting the calibration once)";
    return s.str();
  };
  md << "\nSpeed-up at equal error (<= " << 100 * kTargetError << " %): ODE "
     << speedup(Method::OdeFullVibration, Method::OdeRheonomic) << "; reference solver "
     << speedup(Method::ReferenceFullVibration, Method::ReferenceRheonomic) << ".\n";

  if (options.rtf_parts > 0) {
    Scene big = withCalibration(linearTroughScene(options.rtf_parts, 100), cal);
    big.solver.time_step = 0.01;
    big.duration = std::max(6.0, options.rtf_parts / 100.0 + 2.0);
    const RunMetrics m = measureRun(big, Method::OdeRheonomic, stderrProgress("rtf run"));
    md << "\nReal-time factor, ODE + plugin, linear trough with " << m.parts
       << " parts, h = 0.01 s: " << m.real_time_factor << " (CPU " << m.cpu_seconds << " s for "
       << m.simulated_seconds << " s).\n";
  }

  const std::filesystem::path out(options.out_dir);
  writeFileAtomically(out / "study.csv", csv.str());
  writeFileAtomically(out / "study.md", md.str());
  std::ostringstream gp;
  gp << "set datafile separator ','\nset logscale xy\nset grid\nset key outside right\n"
     << "set xlabel 'CPU time (s)'\nset ylabel 'relative drift error'\n"
     << "set title '" << scene.name << ": drift error vs CPU time'\n"
     << "plot ";
  const char* methods[] = {"ode_full_vibration", "reference_full_vibration", "ode_rheonomic",
                           "reference_rheonomic"};
  for (int k = 0; k < 4; ++k) {
    gp << (k ? ", " : "") << "$data using (strcol(1) eq '" << methods[k]
       << "' ? $7 : 1/0):(($6 > 1e-4) ? $6 : 1e-4) with linespoints lw 2 pt 7 title '" << methods[k]
       << "'";
  }
  gp << ", " << kTargetError << " with lines dt 2 lc rgb 'gray' title '5 % error'\n";
  plotPng(gp.str(), {{"data", csv.str()}}, (out / "study.png").string());
  return md.str();
}

}  // namespace rheofeed::demo
