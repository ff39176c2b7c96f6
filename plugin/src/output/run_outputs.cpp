// SPDX-License-Identifier: MIT
// A run's own files: the drift series CSV, the one-line JSON summary, and its plots.
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>

#include "output_json.hpp"
#include "rheofeed/measure/statistics.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/output/plot.hpp"
#include "rheofeed/version.hpp"

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
    // No part measured has no mean, and the spread of one part (or none) no confidence
    // interval: those fields stay empty (gnuplot skips them; a reader sees no value, not 0).
    char drift[32] = "", ci[32] = "", height[32] = "";
    if (d.parts > 0) {
      std::snprintf(drift, sizeof drift, "%.8g", d.mean_velocity);
      std::snprintf(height, sizeof height, "%.8g", d.mean_height);
    }
    if (ci95Defined(d.parts)) std::snprintf(ci, sizeof ci, "%.8g", d.ci95);
    std::snprintf(line, sizeof line, "%.6f,%d,%s,%s,%s,%d,%d,%d,%d,%d,%d,%d\n", d.time, d.parts,
                  drift, ci, height, d.exited, d.fell, d.through_fixture, d.out_of_bounds,
                  d.nonfinite, d.too_fast, d.left_feeder);
    s << line;
  }
  return s.str();
}

namespace {

OrderedJson vec3Json(const Vec3& v) {
  return {v.x, v.y, v.z};
}

// A vibrating fixture's drift field as the run used it (DriftField): null where its model
// has no such value.
OrderedJson driftFieldJson(const DriftField& f) {
  OrderedJson j;
  j["fixture"] = f.fixture;
  j["drift_model"] = f.drift_model;
  j["efficiency"] = nullptr;
  if (!f.efficiency.empty()) {
    j["efficiency"] = OrderedJson::array();
    for (const auto& [family, value] : f.efficiency) {
      j["efficiency"].push_back({{"family", family}, {"efficiency", value}});
    }
  }
  j["calibrated_drift"] = nullptr;
  if (f.calibrated_drift) {
    j["calibrated_drift"] = {{"linear_mps", vec3Json(f.calibrated_drift->linear)},
                             {"angular_radps", vec3Json(f.calibrated_drift->angular)},
                             {"origin_m", vec3Json(f.calibrated_drift->origin)}};
  }
  return j;
}

OrderedJson partEventJson(const PartEvent& e) {
  return {{"part", e.part},
          {"family", e.family},
          {"kind", e.kind},
          {"t_s", e.time},
          {"position_m", vec3Json(e.position)},
          {"velocity_mps", vec3Json(e.velocity)},
          {"fixture", e.fixture},
          {"what", e.what}};
}

OrderedJson healthJson(const RunHealth& h) {
  OrderedJson j;
  j["steps"] = h.steps;
  j["parts_removed_after_exit"] = h.parts_exited;
  j["parts_lost"] = h.partsLost();
  j["parts_fell"] = h.parts_fell;
  j["parts_through_fixture"] = h.parts_through_fixture;
  j["parts_out_of_bounds"] = h.parts_out_of_bounds;
  j["parts_nonfinite"] = h.parts_nonfinite;
  j["parts_too_fast"] = h.parts_too_fast;
  j["parts_inside_fixture"] = h.parts_inside_fixture;
  j["parts_left_feeder"] = h.parts_left_feeder;
  j["parts_sunk"] = h.parts_sunk;
  j["coulomb_fallback_steps"] = h.coulomb_fallback_steps;
  j["coulomb_fallback_share"] = h.steps > 0 ? double(h.coulomb_fallback_steps) / h.steps : 0.0;
  j["solver_unconverged_steps"] = h.solver_unconverged_steps;
  j["ipm_second_solve_steps"] = h.ipm_second_solve_steps;
  j["ipm_converged_steps"] = h.ipm_converged_steps;
  j["ipm_not_run_steps"] = h.ipm_not_run_steps;
  j["friction_dropped_contacts"] = h.friction_dropped_contacts;
  j["gyroscopic_fallback_steps"] = h.gyroscopic_fallback_steps;
  j["max_part_speed_mps"] = h.max_part_speed;
  j["speed_bound_mps"] = h.speed_bound;
  j["max_physical_speed_ratio"] = h.max_speed_ratio;
  j["speculative_contacts"] = h.speculative_contacts;
  j["warm_started_contacts"] = h.warm_started_contacts;
  j["passes_stopped"] = h.passes_stopped;
  j["ignored_settings"] = h.ignored_settings;
  j["part_events_dropped"] = h.part_events_dropped;
  OrderedJson events = OrderedJson::array();  // the counted parts, then those inside now
  for (const PartEvent& e : h.part_events) events.push_back(partEventJson(e));
  for (const PartEvent& e : h.inside_fixture_now) events.push_back(partEventJson(e));
  j["part_events"] = std::move(events);
  return j;
}

// An optional setting: null where it does not apply (AppliedSolver).
template <typename T>
OrderedJson orNull(const std::optional<T>& value) {
  return value ? OrderedJson(*value) : OrderedJson();
}

OrderedJson orNull(const std::string& text) {
  return text.empty() ? OrderedJson() : OrderedJson(text);
}

OrderedJson solverJson(const AppliedSolver& a) {
  OrderedJson j;
  j["engine"] = orNull(a.engine);
  j["mode"] = orNull(a.mode);
  j["iterations"] = orNull(a.iterations);
  j["tolerance"] = orNull(a.tolerance);
  j["relaxed_solver"] = orNull(a.relaxed_solver);
  j["coulomb_iterations"] = orNull(a.coulomb_iterations);
  j["ipm_rounds"] = orNull(a.ipm_rounds);
  j["warm_start"] = a.warm_start;
  j["speculative_contacts"] = orNull(a.speculative_contacts);
  j["erp"] = a.erp;
  j["cfm"] = a.cfm;
  j["max_correcting_velocity_mps"] = a.max_correcting_velocity;
  j["surface_layer_m"] = a.surface_layer;
  j["surface"] = {
      {"mu", a.mu}, {"restitution", a.restitution}, {"bounce_velocity_mps", a.bounce_velocity}};
  return j;
}

// RunHealth::local_law and the table's corners at the start.
OrderedJson localLawJson(const RunHealth& h) {
  const LocalDriftStats& l = h.local_law;
  return {{"feeders", h.local_law_feeders},
          {"contacts", l.contacts},
          {"wall_contacts", l.wall_contacts},
          {"cells_computed", l.cells_computed},
          {"model_runs", l.model_runs},
          {"model_cpu_s", l.model_cpu_seconds},
          {"corners_at_start", h.local_law_corners_at_start}};
}

}  // namespace

std::string summaryJson(const RunMetrics& r) {
  OrderedJson j;
  j["scene"] = r.scene;
  j["scene_source"] = r.scene_file.empty() ? std::string("built-in") : r.scene_file;
  j["rheofeed_version"] = kVersion;
  j["method"] = toString(r.method);
  j["time_step_s"] = r.time_step;
  j["parts"] = r.parts;
  j["drift_unit"] = r.angular ? "rad/s" : "m/s";
  // The verdict before the numbers it judges (runAnswer), so that a reader of this file alone
  // sees whether they are the run's answer.
  const RunAnswer answer = runAnswer(r);
  const int lost = r.health.partsLost();
  j["answer"] = {
      {"trusted", answer.trusted},
      {"why", answer.why},
      {"parts_lost", lost},
      {"lost_fraction", r.parts > 0 ? OrderedJson(double(lost) / r.parts) : OrderedJson()},
      {"max_lost_fraction", r.max_lost_fraction}};
  // null, not 0: no part measured, and no confidence interval over fewer than two parts
  j["mean_drift"] = r.drift_parts > 0 ? OrderedJson(r.mean_drift) : OrderedJson();
  j["drift_parts"] = r.drift_parts;  // the parts behind the mean (parts: all spawned)
  j["mean_drift_ci95"] =
      ci95Defined(r.drift_parts) ? OrderedJson(r.mean_drift_ci95) : OrderedJson();
  j["vertical_displacement_m"] =
      r.displacement_parts > 0 ? OrderedJson(r.vertical_displacement) : OrderedJson();
  // no exit plane: no exit to count through (null, not 0 parts/s)
  j["throughput_parts_per_s"] = r.feeder.exit_plane ? OrderedJson(r.throughput) : OrderedJson();
  j["cpu_seconds"] = r.cpu_seconds;
  j["simulated_seconds"] = r.simulated_seconds;
  j["real_time_factor"] = r.real_time_factor;
  // the run's own settings: the mean drift's window, seed and drift models
  j["warmup_s"] = r.warmup;
  j["seed"] = r.seed;
  j["drift_models"] = r.drift_models;
  j["drift_fields"] = OrderedJson::array();
  for (const DriftField& f : r.drift_fields) j["drift_fields"].push_back(driftFieldJson(f));
  j["calibration_warnings"] = r.calibration_warnings;
  j["friction"] = r.health.friction_model;
  j["broad_phase"] = r.health.broad_phase;
  j["solver"] = solverJson(r.solver);
  j["health"] = healthJson(r.health);
  j["scene_check"] = r.scene_check;
  j["feeder"] = feederJsonValue(r.feeder);
  j["local_law"] = localLawJson(r.health);
  return oneLineJson(j);
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
  // A run with no answer says so on its plot too (in red): the curve is not the scene's drift.
  std::string no_answer;
  for (const std::string& why : runAnswer(run).why) {
    no_answer += (no_answer.empty() ? "no answer: " : "; ") + why;
  }
  gp << "set datafile separator ','\n"
     << "set key bottom right\nset grid\n"
     << "set xlabel 'time (s)'\nset ylabel '"
     << (run.angular ? "mean angular drift about the axis (rad/s)" : "mean drift velocity (m/s)")
     << "'\n"
     << "set title '" << run.scene << ": " << toString(run.method) << ", h = " << run.time_step
     << " s, " << run.parts << " parts'\n";
  if (!no_answer.empty()) {
    gp << "set label 1 '" << no_answer << "' at graph 0.02, graph 0.95 tc rgb '#c00000'\n";
  }
  gp << "plot ";
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
