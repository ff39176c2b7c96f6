// SPDX-License-Identifier: MIT
// One run of a stability case, measured from the part states after every step (the quantities
// and their physical bounds are defined in stability_cases.hpp), and the CSV / Markdown rows.
//
// Pass/fail limits (Limits):
//  - speed_slack 1.2: v_bound is a sum of physical speeds; a step may overshoot a contact's
//    target velocity by the ERP correction and the discrete gravity impulse g h, a few % at the
//    largest h here; 20 % leaves room for that and still catches a blow-up.
//  - energy_slack 1.1: E_budget already doubles the kinetic energy a surface can give; 10 % for
//    the penetration recovered by ERP (potential energy of a part pushed out) and discretisation.
//  - penetration_ratio 0.2: beyond a fifth of a part's thinnest dimension the contact normal of
//    a thin part is no longer reliable and it is a step or two from passing through.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

#include "rheofeed/number_format.hpp"
#include "rheofeed/simulation/check.hpp"
#include "stability/stability_cases.hpp"

namespace rheofeed::stability {
namespace {

using namespace rheofeed::scene;

bool finite(const PartState& s) {
  if (!isFinite(s.position) || !isFinite(s.velocity) || !isFinite(s.angular_velocity)) {
    return false;
  }
  for (double r : s.rotation) {
    if (!std::isfinite(r)) return false;
  }
  return true;
}

std::string nonfiniteField(const PartState& s) {
  if (!isFinite(s.position)) return "position";
  if (!isFinite(s.velocity)) return "velocity";
  if (!isFinite(s.angular_velocity)) return "angular velocity";
  return "rotation";
}

/// R^T a (world to body) with R row-major body to world.
Vec3 toBody(const double* r, const Vec3& a) {
  return {r[0] * a.x + r[3] * a.y + r[6] * a.z, r[1] * a.x + r[4] * a.y + r[7] * a.z,
          r[2] * a.x + r[5] * a.y + r[8] * a.z};
}

/// Extent (m) of a part along the unit world direction n from its centre: max over the
/// part's points p of n . (p - centre) (support function).
double extent(const Shape& shape, const double* rot, const Vec3& n) {
  const Vec3 b = toBody(rot, n);  // n in the body frame
  switch (shape.kind) {
    case Shape::Kind::Box:
      return 0.5 * (std::abs(b.x) * shape.size.x + std::abs(b.y) * shape.size.y +
                    std::abs(b.z) * shape.size.z);
    case Shape::Kind::Sphere:
      return shape.radius;
    case Shape::Kind::Cylinder:
      return shape.radius * std::sqrt(std::max(0.0, 1 - b.z * b.z)) +
             0.5 * shape.length * std::abs(b.z);
    case Shape::Kind::Capsule:
      return shape.radius + 0.5 * shape.length * std::abs(b.z);
    default:  // meshes are not used by the matrix: their bounding radius
      return shape.mesh_scale;
  }
}

/// Thinnest dimension (m) and size (bounding radius, m) of a part.
double thinnest(const Shape& s) {
  switch (s.kind) {
    case Shape::Kind::Box:
      return std::min({s.size.x, s.size.y, s.size.z});
    case Shape::Kind::Cylinder:
      return std::min(2 * s.radius, s.length);
    default:
      return 2 * s.radius;
  }
}
double boundingRadius(const Shape& s) {
  switch (s.kind) {
    case Shape::Kind::Box:
      return 0.5 * norm(s.size);
    case Shape::Kind::Cylinder:
      return std::hypot(s.radius, 0.5 * s.length);
    case Shape::Kind::Capsule:
      return s.radius + 0.5 * s.length;
    default:
      return s.radius;
  }
}

bool inRegion(const Surface& f, const Vec3& c) {
  if (f.disc_radius > 0) {
    return std::hypot(c.x - f.disc_centre.x, c.y - f.disc_centre.y) <= f.disc_radius;
  }
  return c.x >= f.region_min.x && c.x <= f.region_max.x && c.y >= f.region_min.y &&
         c.y <= f.region_max.y && c.z >= f.region_min.z && c.z <= f.region_max.z;
}

/// The surface plane (unit normal, offset) at time t of a full-vibration run: moved by its
/// fixture's vibration; at rest otherwise.
std::pair<Vec3, double> planeAt(const Surface& f, const Scene& scene, bool full_vibration,
                                double t) {
  if (!full_vibration || f.fixture < 0) return {f.normal, f.offset};
  const FeederLaw& law = scene.fixtures[static_cast<std::size_t>(f.fixture)].law;
  if (law.kind != FeederLaw::Kind::Vibration) return {f.normal, f.offset};
  const Pose d = law.vibration.displacement(t);
  const Vec3 n = d.rotate(f.normal);
  return {n, dot(n, d.transform(f.offset * f.normal))};
}

// Any printf conversion of one double: the report's columns mix significant digits (%.3g) with
// fixed decimals (%.2f, %.3f), which formatNumber (significant digits only) does not print.
std::string fmt(double v, const char* format = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void addCause(RunRecord& r, const std::string& why) {
  r.cause += (r.cause.empty() ? "" : "; ") + why;
}

}  // namespace

RunRecord runCase(const StabilityCase& c, Method method, const Limits& limits) {
  RunRecord r;
  r.case_name = c.name;
  r.method = toString(method);
  r.covers = c.covers;
  const Scene scene = sceneFor(c, method);
  const bool fv = isFullVibration(method);
  r.time_step = scene.solver.time_step;
  r.duration = 0;
  const auto start = std::chrono::steady_clock::now();
  auto finishClock = [&] {
    r.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };

  // The scene check's warnings before the run (issue 7 item 2): a run outside the safe
  // settings is a known limit when the check named it, a silent failure when it did not.
  try {
    for (const Hazard& hz : checkScene(scene, method)) {
      ++r.check_warnings;
      r.hazards += (r.hazards.empty() ? "" : "; ") + std::string(toString(hz.kind));
      r.safe_settings += (r.safe_settings.empty() ? "" : "; ") + hz.safe_setting;
    }
  } catch (const std::exception&) {
    // An invalid scene: makeSimulation below refuses it with the message.
  }

  std::unique_ptr<Simulation> sim;
  std::vector<PartInstance> instances;
  try {
    sim = makeSimulation(scene, method);
    instances = drawParts(scene);
  } catch (const std::exception& e) {
    r.status = "refused";
    r.message = e.what();
    finishClock();
    r.pass = c.expect_refusal;
    r.verdict = r.pass ? "pass" : "FAIL";
    addCause(r, c.expect_refusal ? "refused as expected" : "refused unexpectedly");
    if (!c.note.empty()) addCause(r, c.note);
    return r;
  }

  // Budgets from the spawn states (stability_cases.hpp).
  const double g = norm(scene.gravity);
  const double e = scene.material.restitution;
  const double v_corr = scene.solver.max_correcting_velocity;
  double z_ref = 0, max_size = 0, z_top = 0, v0_max = 0;
  for (const PartInstance& p : instances) {
    z_ref = std::min(z_ref, p.pose.position.z);
    max_size = std::max(max_size, boundingRadius(p.shape));
    z_top = std::max(z_top, p.pose.position.z);
    v0_max = std::max(v0_max, norm(p.velocity));
  }
  z_ref -= max_size;
  const double v_s = (1 + e) * c.surface_speed;
  r.speed_bound = v_s + v_corr + std::sqrt(v0_max * v0_max + 2 * g * (z_top - z_ref));
  for (const PartInstance& p : instances) {
    r.energy_budget += 0.5 * p.mass * dot(p.velocity, p.velocity) +
                       p.mass * g * (p.pose.position.z - z_ref) +
                       p.mass * (v_s * v_s + v_corr * v_corr);
  }

  // Out of the scene: beyond the engine's own scene bounds (the scene's definition of where
  // parts may be, SceneLimits in simulation.hpp) or below the removal height.
  Bounds bounds = sceneLimits(scene).bounds;
  bounds.min.z = scene.removal_height;
  std::vector<char> lost(instances.size(), 0);
  // Per part: seen yet; the allowed depth: its depth at spawn (the scene put it there) and the
  // largest landing overshoot so far, h times the fastest approach of any of its points during
  // the step (|v_n| + |w| r + |g_n| h + the surface's speed), which no discrete step avoids.
  std::vector<char> seen(instances.size(), 0);
  std::vector<double> allowed(instances.size(), 0.0);
  std::vector<PartState> prev(instances.size());
  const double h_step = scene.solver.time_step;
  const double surface_normal_speed = fv ? c.surface_speed : 0.0;
  std::map<std::string, int> lost_by;
  // Per part: the surface its centre is beyond (deeper than the part's size), empty if none.
  // A part that comes back out (pushed back by the engine) is not lost; one still beyond a
  // surface when the run ends is (it went through).
  std::vector<std::string> under(instances.size());
  auto lose = [&](std::size_t i, const std::string& how) {
    lost[i] = 1;
    ++r.lost_measured;
    ++lost_by[how];
  };
  double max_energy = 0;

  auto measure = [&](double t_prev, double t) {
    double energy = 0;
    const int n = sim->numParts();
    for (int i = 0; i < n; ++i) {
      const std::size_t k = static_cast<std::size_t>(i);
      if (lost[k]) continue;
      const PartState s = sim->part(i);
      if (!finite(s)) {
        if (r.nonfinite_parts++ == 0) {
          r.nonfinite_where =
              nonfiniteField(s) + " of part " + std::to_string(i) + " at t = " + fmt(t) + " s";
        }
        lose(k, "non-finite");
        continue;
      }
      if (!s.active) {
        lose(k, "removed by the engine");
        continue;
      }
      const Shape& shape = instances[k].shape;
      const double size = boundingRadius(shape);
      const Vec3& x = s.position;
      if (x.x < bounds.min.x || x.y < bounds.min.y || x.z < bounds.min.z || x.x > bounds.max.x ||
          x.y > bounds.max.y || x.z > bounds.max.z) {
        lose(k, "out of bounds");
        continue;
      }
      bool through = false;
      under[k].clear();
      for (const Surface& f : c.surfaces) {
        if (!inRegion(f, x)) continue;
        // Lowest position of a vibrating surface over the step: the smaller depth.
        const auto [n0, d0] = planeAt(f, scene, fv, t_prev);
        const auto [n1, d1] = planeAt(f, scene, fv, t);
        const double centre_depth = std::min(d0 - dot(n0, x), d1 - dot(n1, x));
        if (centre_depth > size) {  // beyond the surface now; lost if it ends the run there
          under[k] = "through " + f.name;
          through = true;
          break;
        }
        const double depth = std::min(d0 - dot(n0, x) + extent(shape, s.rotation, n0),
                                      d1 - dot(n1, x) + extent(shape, s.rotation, n1));
        if (!seen[k]) allowed[k] = std::max(allowed[k], depth);
        if (depth > r.max_penetration) r.max_penetration = depth;
        if (seen[k]) {
          const double approach_speed =
              std::max(0.0, -dot(n1, prev[k].velocity)) + norm(prev[k].angular_velocity) * size +
              std::abs(dot(n1, scene.gravity)) * h_step + surface_normal_speed;
          allowed[k] = std::max(allowed[k], h_step * approach_speed);
        }
        const double ratio = (depth - allowed[k]) / thinnest(shape);
        if (ratio > r.penetration_ratio) {
          r.penetration_ratio = ratio;
          r.penetration_where =
              "part " + std::to_string(i) + " into " + f.name + " at t = " + fmt(t) + " s";
        }
      }
      seen[k] = 1;
      prev[k] = s;
      if (through) continue;
      r.max_speed = std::max(r.max_speed, norm(s.velocity));
      const Vec3 wb = toBody(s.rotation, s.angular_velocity);
      const double* in = instances[k].inertia;
      const Vec3 iw{in[0] * wb.x + in[1] * wb.y + in[2] * wb.z,
                    in[3] * wb.x + in[4] * wb.y + in[5] * wb.z,
                    in[6] * wb.x + in[7] * wb.y + in[8] * wb.z};
      const double m = instances[k].mass;
      energy += 0.5 * m * dot(s.velocity, s.velocity) + 0.5 * dot(wb, iw) + m * g * (x.z - z_ref);
    }
    max_energy = std::max(max_energy, energy);
  };

  measure(0, 0);
  const long steps = std::lround(scene.duration / scene.solver.time_step);
  try {
    for (long k = 0; k < steps; ++k) {
      const double t_prev = sim->time();
      sim->step();
      measure(t_prev, sim->time());
    }
    r.status = "finished";
  } catch (const std::exception& ex) {
    r.status = "aborted";
    r.message = ex.what();
  }
  finishClock();
  for (std::size_t k = 0; k < under.size(); ++k) {
    if (!lost[k] && !under[k].empty()) lose(k, under[k]);
  }
  r.duration = sim->time();
  r.parts = sim->numParts();
  r.energy_ratio = r.energy_budget > 0 ? max_energy / r.energy_budget : 0;

  const RunHealth& h = sim->health();
  r.steps = h.steps > 0 ? h.steps : std::lround(r.duration / r.time_step);
  r.lost_reported = h.partsLost();
  r.parts_fell = h.parts_fell;
  r.parts_through_fixture = h.parts_through_fixture;
  r.parts_out_of_bounds = h.parts_out_of_bounds;
  r.parts_nonfinite = h.parts_nonfinite;
  r.parts_too_fast = h.parts_too_fast;
  r.fallback_steps = h.coulomb_fallback_steps;
  r.unconverged_steps = h.solver_unconverged_steps;
  for (const std::string& s : h.ignored_settings) {
    r.ignored_settings += (r.ignored_settings.empty() ? "" : "; ") + s;
  }
  for (const auto& [how, count] : lost_by) {
    r.lost_how += (r.lost_how.empty() ? "" : ", ") + std::to_string(count) + " " + how;
  }

  // Verdict.
  r.pass = true;
  auto fail = [&](const std::string& why) {
    r.pass = false;
    addCause(r, why);
  };
  if (r.status == "aborted") fail("aborted at t = " + fmt(r.duration) + " s: " + r.message);
  if (c.expect_refusal) fail("expected a refusal, ran");
  if (r.nonfinite_parts > 0) {
    fail(std::to_string(r.nonfinite_parts) + " part(s) non-finite (first: " + r.nonfinite_where +
         ")");
  }
  // Speed: beyond the bound is a physical limit when warned (pushes out of overlaps chain
  // up); beyond kBlowUp times the bound it is a blow-up, warned or not.
  constexpr double kBlowUp = 3;
  if (r.max_speed > kBlowUp * limits.speed_slack * r.speed_bound) {
    fail("speed " + fmt(r.max_speed) + " m/s > " + fmt(kBlowUp) + " x bound " + fmt(r.speed_bound) +
         " m/s (blow-up)");
  }

  // Physical limits (ODE's, the discrete step's): a known limit when the scene check warned.
  bool beyond_limit = false;
  auto limit = [&](const std::string& why) {
    beyond_limit = true;
    addCause(r, why);
  };
  if (r.penetration_ratio > limits.penetration_ratio) {
    limit("penetration beyond spawn depth and landing overshoot " +
          fmt(r.penetration_ratio, "%.2f") + " x thinnest (" + r.penetration_where + "; deepest " +
          fmt(r.max_penetration * 1e3) + " mm)");
  }
  if (r.max_speed > limits.speed_slack * r.speed_bound &&
      r.max_speed <= kBlowUp * limits.speed_slack * r.speed_bound) {
    limit("speed " + fmt(r.max_speed) + " m/s > bound " + fmt(r.speed_bound) + " m/s");
  }
  if (r.energy_ratio > limits.energy_slack) {
    limit("energy x" + fmt(r.energy_ratio, "%.3g") + " of budget " + fmt(r.energy_budget) + " J");
  }
  if (r.lost_measured > r.lost_reported) {
    fail(std::to_string(r.lost_measured) + " lost (" + r.lost_how + "), " +
         std::to_string(r.lost_reported) + " reported");
  } else if (r.lost_measured > 0 && c.expect_losses) {
    addCause(r, std::to_string(r.lost_measured) + " lost (" + r.lost_how +
                    "), all reported, as the case's physics expects");
  } else if (r.lost_measured > 0) {
    limit(std::to_string(r.lost_measured) + " lost (" + r.lost_how + "), all reported");
  }
  if (beyond_limit && r.check_warnings == 0) fail("no scene-check warning before the run");
  r.verdict = !r.pass ? "FAIL" : (beyond_limit ? "warned" : "pass");
  if (beyond_limit && r.check_warnings > 0) {
    addCause(r, "warned: " + r.hazards + " (safe: " + r.safe_settings + ")");
  }
  // Tunnelling hint: a part at its measured top speed moves further in one step than the
  // thinnest fixture geom or part is thick.
  if (r.verdict != "pass") {
    double thin = 1e300;
    for (const Fixture& f : scene.fixtures) {
      for (const Fixture::Geom& gm : f.geoms) {
        if (gm.shape.kind == Shape::Kind::Box) thin = std::min(thin, thinnest(gm.shape));
      }
    }
    for (const PartInstance& p : instances) thin = std::min(thin, thinnest(p.shape));
    if (r.max_speed * r.time_step > thin) {
      addCause(r, "tunnelling possible: h v_max = " + fmt(r.max_speed * r.time_step * 1e3) +
                      " mm > thinnest " + fmt(thin * 1e3) + " mm");
    }
  }
  if (!c.note.empty()) addCause(r, c.note);
  return r;
}

// ---- CSV ---------------------------------------------------------------------------------------

namespace {

std::string quote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"') out += '"';
    out += ch == '\n' ? ' ' : ch;
  }
  return out + "\"";
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quoted) {
      if (ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        out.back() += '"';
        ++i;
      } else if (ch == '"') {
        quoted = false;
      } else {
        out.back() += ch;
      }
    } else if (ch == '"') {
      quoted = true;
    } else if (ch == ',') {
      out.emplace_back();
    } else {
      out.back() += ch;
    }
  }
  return out;
}

}  // namespace

std::string csvHeader() {
  return "case,method,time_step_s,steps,duration_s,parts,status,wall_s,nonfinite_parts,"
         "max_speed_mps,speed_bound_mps,energy_budget_J,energy_ratio,max_penetration_m,"
         "penetration_ratio,lost_measured,lost_reported,parts_fell,parts_through_fixture,"
         "parts_out_of_bounds,parts_nonfinite,parts_too_fast,fallback_steps,"
         "fallback_share,unconverged_steps,check_warnings,verdict,covers,message,"
         "lost_how,ignored_settings,hazards,safe_settings,cause";
}

std::string csvRow(const RunRecord& r) {
  std::ostringstream o;
  const double share = r.steps > 0 ? double(r.fallback_steps) / double(r.steps) : 0;
  o << quote(r.case_name) << ',' << quote(r.method) << ',' << formatNumber(r.time_step, 17) << ','
    << r.steps << ',' << formatNumber(r.duration, 17) << ',' << r.parts << ',' << r.status << ','
    << fmt(r.wall_seconds, "%.3f") << ',' << r.nonfinite_parts << ','
    << formatNumber(r.max_speed, 17) << ',' << formatNumber(r.speed_bound, 17) << ','
    << formatNumber(r.energy_budget, 17) << ',' << formatNumber(r.energy_ratio, 17) << ','
    << formatNumber(r.max_penetration, 17) << ',' << formatNumber(r.penetration_ratio, 17) << ','
    << r.lost_measured << ',' << r.lost_reported << ',' << r.parts_fell << ','
    << r.parts_through_fixture << ',' << r.parts_out_of_bounds << ',' << r.parts_nonfinite << ','
    << r.parts_too_fast << ',' << r.fallback_steps << ',' << formatNumber(share, 17) << ','
    << r.unconverged_steps << ',' << r.check_warnings << ',' << r.verdict << ',' << quote(r.covers)
    << ',' << quote(r.message) << ',' << quote(r.lost_how) << ',' << quote(r.ignored_settings)
    << ',' << quote(r.hazards) << ',' << quote(r.safe_settings) << ',' << quote(r.cause);
  return o.str();
}

RunRecord parseCsvRow(const std::string& line) {
  const std::vector<std::string> f = splitCsv(line);
  if (f.size() != 34) {
    throw std::runtime_error("stability row with " + std::to_string(f.size()) +
                             " fields (34 expected): " + line.substr(0, 80));
  }
  RunRecord r;
  std::size_t i = 0;
  auto d = [&] { return std::stod(f[i++]); };
  auto l = [&] { return std::stol(f[i++]); };
  auto n = [&] { return std::stoi(f[i++]); };
  r.case_name = f[i++];
  r.method = f[i++];
  r.time_step = d();
  r.steps = l();
  r.duration = d();
  r.parts = n();
  r.status = f[i++];
  r.wall_seconds = d();
  r.nonfinite_parts = n();
  r.max_speed = d();
  r.speed_bound = d();
  r.energy_budget = d();
  r.energy_ratio = d();
  r.max_penetration = d();
  r.penetration_ratio = d();
  r.lost_measured = n();
  r.lost_reported = n();
  r.parts_fell = n();
  r.parts_through_fixture = n();
  r.parts_out_of_bounds = n();
  r.parts_nonfinite = n();
  r.parts_too_fast = n();
  r.fallback_steps = l();
  ++i;  // fallback_share: derived
  r.unconverged_steps = l();
  r.check_warnings = n();
  r.verdict = f[i++];
  r.pass = r.verdict != "FAIL";
  r.covers = f[i++];
  r.message = f[i++];
  r.lost_how = f[i++];
  r.ignored_settings = f[i++];
  r.hazards = f[i++];
  r.safe_settings = f[i++];
  r.cause = f[i++];
  return r;
}

// ---- Markdown ----------------------------------------------------------------------------------

std::string markdownReport(const std::vector<RunRecord>& records, const std::string& header) {
  std::ostringstream o;
  int failed = 0, warned = 0;
  for (const RunRecord& r : records) {
    failed += r.verdict == "FAIL" ? 1 : 0;
    warned += r.verdict == "warned" ? 1 : 0;
  }
  o << "# Stability matrix\n\n" << header << "\n\n";
  o << records.size() << " runs: " << records.size() - failed - warned << " pass, " << warned
    << " beyond a physical limit that the scene check warned about, " << failed
    << " fail (silent or unbounded).\n\n";
  // One line per case: its verdict per method (the README's table).
  o << "## By case\n\n| case | what it covers | ODE rheonomic | reference rheonomic | ODE full "
       "vibration | reference full vibration |\n|---|---|---|---|---|---|\n";
  const char* methods[] = {"ode_rheonomic", "reference_rheonomic", "ode_full_vibration",
                           "reference_full_vibration"};
  for (std::size_t k = 0; k < records.size(); ++k) {
    if (k > 0 && records[k].case_name == records[k - 1].case_name) continue;
    o << "| " << records[k].case_name << " | " << records[k].covers;
    for (const char* m : methods) {
      std::string cell = "-";
      for (std::size_t j = k; j < records.size() && records[j].case_name == records[k].case_name;
           ++j) {
        if (records[j].method != m) continue;
        cell = records[j].verdict == "FAIL" ? "**FAIL**" : records[j].verdict;
        if (records[j].lost_reported > 0) {
          cell += " (" + std::to_string(records[j].lost_reported) + " lost)";
        }
      }
      o << " | " << cell;
    }
    o << " |\n";
  }
  o << "\n## All runs\n\n";
  o << "| case | method | h (s) | status | v max / bound (m/s) | E / budget | deepest (mm), excess "
       "(x thinnest) | lost (ours / reported) | fallback steps | check warnings | wall (s) | "
       "verdict |\n"
    << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const RunRecord& r : records) {
    o << "| " << r.case_name << " | " << r.method << " | " << fmt(r.time_step, "%.3g") << " | "
      << r.status << " | " << fmt(r.max_speed, "%.3g") << " / " << fmt(r.speed_bound, "%.3g")
      << " | " << fmt(r.energy_ratio, "%.3g") << " | " << fmt(r.max_penetration * 1e3, "%.3g")
      << " (" << fmt(r.penetration_ratio, "%.2f") << ") | " << r.lost_measured << " / "
      << r.lost_reported << " | " << r.fallback_steps << " | " << r.check_warnings << " | "
      << fmt(r.wall_seconds, "%.1f") << " | " << (r.verdict == "FAIL" ? "**FAIL**" : r.verdict)
      << " |\n";
  }
  auto list = [&](const char* verdict) {
    int n = 0;
    for (const RunRecord& r : records) {
      if (r.verdict != verdict) continue;
      ++n;
      std::string cause = r.cause;
      for (char& ch : cause) {
        if (ch == '|') ch = '/';
      }
      o << "- **" << r.case_name << "** (" << r.method << ", h = " << fmt(r.time_step, "%.3g")
        << " s; " << r.covers << "): " << cause << "\n";
    }
    if (n == 0) o << "None.\n";
  };
  o << "\n## Failures (silent or unbounded)\n\n";
  list("FAIL");
  o << "\n## Beyond a physical limit, warned before the run (why, and the safe settings)\n\n";
  list("warned");
  return o.str();
}

}  // namespace rheofeed::stability
