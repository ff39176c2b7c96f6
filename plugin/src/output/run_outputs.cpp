// SPDX-License-Identifier: MIT
// A run's own files: the drift series CSV, the one-line JSON summary, and its plots.
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "rheofeed/measure/statistics.hpp"
#include "rheofeed/number_format.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/output/plot.hpp"

namespace rheofeed::scene {

std::string seriesCsv(const RunMetrics& run) {
  std::ostringstream s;
  // The drift's unit in its column names: m/s along the conveying direction, or rad/s about
  // the angular drift's axis.
  s << (run.angular ? "time_s,parts,mean_drift_radps,ci95_radps,"
                    : "time_s,parts,mean_velocity_mps,ci95_mps,")
    << "mean_height_m,exited,lost_fell,lost_through_fixture,lost_out_of_bounds,lost_nonfinite,"
       "lost_too_fast,lost_left_feeder\n";
  char line[256];
  for (const DriftSample& d : run.series) {
    // the spread of one part (or none) has no confidence interval: the field stays empty
    char ci[32] = "";
    if (ci95Defined(d.parts)) std::snprintf(ci, sizeof ci, "%.8g", d.ci95);
    std::snprintf(line, sizeof line, "%.6f,%d,%.8g,%s,%.8g,%d,%d,%d,%d,%d,%d,%d\n", d.time, d.parts,
                  d.mean_velocity, ci, d.mean_height, d.exited, d.fell, d.through_fixture,
                  d.out_of_bounds, d.nonfinite, d.too_fast, d.left_feeder);
    s << line;
  }
  return s.str();
}

std::string summaryJson(const RunMetrics& r) {
  char ci[32] = "null";  // no confidence interval over fewer than two parts
  if (ci95Defined(r.drift_parts)) std::snprintf(ci, sizeof ci, "%.8g", r.mean_drift_ci95);
  char drift[32] = "null";  // no part measured
  if (r.drift_parts > 0) std::snprintf(drift, sizeof drift, "%.8g", r.mean_drift);
  char b[768];
  std::snprintf(b, sizeof b,
                ", \"method\": \"%s\", \"time_step_s\": %.8g, \"parts\": %d, "
                "\"drift_unit\": \"%s\", \"mean_drift\": %s, \"mean_drift_ci95\": %s, "
                "\"vertical_displacement_m\": %.8g, \"throughput_parts_per_s\": %.8g, "
                "\"cpu_seconds\": %.6g, \"simulated_seconds\": %.6g, \"real_time_factor\": %.6g",
                toString(r.method), r.time_step, r.parts, r.angular ? "rad/s" : "m/s", drift, ci,
                r.vertical_displacement, r.throughput, r.cpu_seconds, r.simulated_seconds,
                r.real_time_factor);
  std::string run = b;  // the run's own settings: seed and drift models
  run += ", \"warmup_s\": " + formatNumber(r.warmup);  // the mean drift's window starts there
  run += ", \"seed\": " + std::to_string(r.seed) + ", \"drift_models\": [";
  for (std::size_t k = 0; k < r.drift_models.size(); ++k) {
    run += (k ? ", " : "") + jsonQuoted(r.drift_models[k]);
  }
  run += "], \"friction\": " + jsonQuoted(r.health.friction_model) +
         ", \"broad_phase\": " + jsonQuoted(r.health.broad_phase);
  const RunHealth& h = r.health;
  char c[1792];
  std::snprintf(
      c, sizeof c,
      ", \"health\": {\"steps\": %ld, \"parts_removed_after_exit\": %d, \"parts_lost\": %d, "
      "\"parts_fell\": %d, \"parts_through_fixture\": %d, \"parts_out_of_bounds\": %d, "
      "\"parts_nonfinite\": %d, \"parts_too_fast\": %d, \"parts_inside_fixture\": %d, "
      "\"parts_left_feeder\": %d, \"parts_sunk\": %d, "
      "\"coulomb_fallback_steps\": %ld, "
      "\"coulomb_fallback_share\": %.6g, \"solver_unconverged_steps\": %ld, "
      "\"ipm_second_solve_steps\": %ld, \"ipm_converged_steps\": %ld, "
      "\"ipm_not_run_steps\": %ld, "
      "\"friction_dropped_contacts\": %ld, \"gyroscopic_fallback_steps\": %ld, "
      "\"max_part_speed_mps\": %.6g, \"speed_bound_mps\": %.6g, "
      "\"max_physical_speed_ratio\": %.6g, \"speculative_contacts\": %ld, "
      "\"warm_started_contacts\": %ld, \"passes_stopped\": %ld, \"ignored_settings\": [",
      h.steps, h.parts_exited, h.partsLost(), h.parts_fell, h.parts_through_fixture,
      h.parts_out_of_bounds, h.parts_nonfinite, h.parts_too_fast, h.parts_inside_fixture,
      h.parts_left_feeder, h.parts_sunk, h.coulomb_fallback_steps,
      h.steps > 0 ? double(h.coulomb_fallback_steps) / h.steps : 0.0, h.solver_unconverged_steps,
      h.ipm_second_solve_steps, h.ipm_converged_steps, h.ipm_not_run_steps,
      h.friction_dropped_contacts, h.gyroscopic_fallback_steps, h.max_part_speed, h.speed_bound,
      h.max_speed_ratio, h.speculative_contacts, h.warm_started_contacts, h.passes_stopped);
  std::string json = "{\"scene\": " + jsonQuoted(r.scene) + run + c;
  for (std::size_t k = 0; k < h.ignored_settings.size(); ++k) {
    json += (k ? ", " : "") + jsonQuoted(h.ignored_settings[k]);
  }
  json += "], \"part_events_dropped\": " + std::to_string(h.part_events_dropped) +
          ", \"part_events\": [";
  std::vector<const PartEvent*> events;
  for (const PartEvent& e : h.part_events) events.push_back(&e);
  for (const PartEvent& e : h.inside_fixture_now) events.push_back(&e);
  for (std::size_t k = 0; k < events.size(); ++k) {
    const PartEvent& e = *events[k];
    const auto vec = [](const Vec3& v) {
      return "[" + jsonNumber(v.x) + ", " + jsonNumber(v.y) + ", " + jsonNumber(v.z) + "]";
    };
    json += std::string(k ? ", " : "") + "{\"part\": " + std::to_string(e.part) +
            ", \"kind\": " + jsonQuoted(e.kind) + ", \"t_s\": " + jsonNumber(e.time) +
            ", \"position_m\": " + vec(e.position) + ", \"velocity_mps\": " + vec(e.velocity) +
            ", \"fixture\": " + jsonQuoted(e.fixture) + ", \"what\": " + jsonQuoted(e.what) + "}";
  }
  json += "]}, \"scene_check\": [";
  for (std::size_t k = 0; k < r.scene_check.size(); ++k) {
    json += (k ? ", " : "") + jsonQuoted(r.scene_check[k]);
  }
  const LocalDriftStats& l = h.local_law;  // RunHealth::local_law (simulation.hpp)
  char d[384];
  std::snprintf(d, sizeof d,
                "{\"feeders\": %d, \"contacts\": %lld, \"wall_contacts\": %lld, "
                "\"cells_computed\": %lld, \"model_runs\": %lld, \"model_cpu_s\": %.6g, "
                "\"corners_at_start\": %lld}",
                h.local_law_feeders, static_cast<long long>(l.contacts),
                static_cast<long long>(l.wall_contacts), static_cast<long long>(l.cells_computed),
                static_cast<long long>(l.model_runs), l.model_cpu_seconds,
                static_cast<long long>(h.local_law_corners_at_start));
  return json + "], \"feeder\": " + feederJson(r.feeder) + ", \"local_law\": " + d + "}";
}

std::vector<std::string> writeRunOutputs(const RunMetrics& run, const std::string& folder,
                                         const std::string& stem) {
  const std::filesystem::path base = std::filesystem::path(folder) / stem;
  std::vector<std::string> written;
  const std::string csv = seriesCsv(run);
  writeFileAtomically(base.string() + ".csv", csv);
  written.push_back(base.string() + ".csv");
  writeFileAtomically(base.string() + ".json", summaryJson(run) + "\n");
  written.push_back(base.string() + ".json");

  std::ostringstream gp;
  gp << "set datafile separator ','\n"
     << "set key bottom right\nset grid\n"
     << "set xlabel 'time (s)'\nset ylabel '"
     << (run.angular ? "mean angular drift about the axis (rad/s)" : "mean drift velocity (m/s)")
     << "'\n"
     << "set title '" << run.scene << ": " << toString(run.method) << ", h = " << run.time_step
     << " s, " << run.parts << " parts'\n"
     << "plot ";
  // the band only where there is one (two parts or more; the CSV's field is empty otherwise)
  if (ci95Defined(run.parts)) {
    gp << "$data using 1:($3-$4):($3+$4) with filledcurves fc rgb '#c0d0f0' title '95 % CI', ";
  }
  gp << "$data using 1:3 with lines lw 2 lc rgb '#1040a0' title 'mean over parts'\n";
  const std::string png = base.string() + ".png";
  if (plotPng(gp.str(), {{"data", csv}}, png)) written.push_back(png);
  const std::string title = run.scene + ": " + toString(run.method);
  for (const std::string& path : writeFeederOutputs(run.feeder, folder, stem, title)) {
    written.push_back(path);
  }
  return written;
}

}  // namespace rheofeed::scene
