// SPDX-License-Identifier: MIT
// `rheofeed sweep collect DIR` (sweep.hpp): the sweep's CSV and plots from its records.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include "cli/sweep.hpp"
#include "rheofeed/measure/statistics.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/output/plot.hpp"

namespace rheofeed::cli::sweep {

namespace fs = std::filesystem;

namespace {

// Plots: at most this many curves in one figure (one per value of the other parameters); more
// are drawn as points.
constexpr std::size_t kMaxCurves = 8;

std::string num(double v) {
  if (!std::isfinite(v)) return "";
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

// Mean and 95 % half-width (Student t over n - 1 degrees of freedom) of `v`.
struct Stats {
  int n = 0;
  double mean = NAN, ci95 = NAN;
};
Stats stats(const std::vector<double>& v) {
  Stats s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / s.n;
  if (s.n < 2) return s;
  double ss = 0;
  for (double x : v) ss += (x - s.mean) * (x - s.mean);
  s.ci95 = scene::studentT95(s.n - 1) * std::sqrt(ss / (s.n - 1)) / std::sqrt(double(s.n));
  return s;
}

// One row of sweep.csv: a point and a method.
struct Row {
  int point = 0;
  std::vector<double> values;  // parameters
  int ok = 0, failed = 0, missing = 0, no_answer = 0;
  std::vector<Stats> metrics;
  std::vector<double> health;  // summed over the seeds that ran (ok and no answer)
};

bool uniform(const std::vector<double>& sorted) {
  if (sorted.size() < 2) return true;
  const double step = sorted[1] - sorted[0];
  for (std::size_t k = 2; k < sorted.size(); ++k) {
    if (std::abs(sorted[k] - sorted[k - 1] - step) > 1e-9 * std::abs(step) + 1e-300) return false;
  }
  return true;
}

std::string suffix(const Manifest& m, std::size_t method) {
  return m.methods.size() > 1 ? "_" + m.methods[method] : std::string();
}

// Each metric against each parameter: one curve per combination of the other parameters' values
// when there are few, else points; 95 % intervals as error bars.
bool plotLines(const Manifest& m, const std::vector<Row>& rows, std::size_t method,
               std::size_t metric, std::size_t param, const fs::path& file) {
  std::map<std::vector<double>, std::vector<const Row*>> groups;
  for (const Row& r : rows) {
    std::vector<double> others;
    for (std::size_t k = 0; k < m.parameters.size(); ++k) {
      if (k != param) others.push_back(r.values[k]);
    }
    groups[others].push_back(&r);
  }
  const bool curves = groups.size() <= kMaxCurves;
  std::vector<std::pair<std::string, std::string>> blocks;
  std::string plot;
  int g = 0;
  for (auto& [others, members] : groups) {
    std::sort(members.begin(), members.end(),
              [&](const Row* a, const Row* b) { return a->values[param] < b->values[param]; });
    std::string csv = "x,mean,ci95\n";
    for (const Row* r : members) {
      const Stats& s = r->metrics[metric];
      csv += num(r->values[param]) + "," + (std::isfinite(s.mean) ? num(s.mean) : "NaN") + "," +
             (std::isfinite(s.ci95) ? num(s.ci95) : "0") + "\n";
    }
    std::string title;
    std::size_t o = 0;
    for (std::size_t k = 0; k < m.parameters.size(); ++k) {
      if (k == param) continue;
      title += (title.empty() ? "" : ", ") + m.parameters[k].name + " = " + num(others[o++]);
    }
    const std::string name = "d" + std::to_string(g++);
    blocks.emplace_back(name, csv);
    plot += (plot.empty() ? "" : ", ") + std::string("$") + name +
            (curves ? " using 1:2:3 with yerrorlines lw 2 pt 7 title '" +
                          (title.empty() ? m.metrics[metric].name : title) + "'"
                    : " using 1:2:3 with yerrorbars pt 7 lc rgb '#1f77b4' notitle");
  }
  const std::string script =
      "set datafile separator ','\nset datafile missing 'NaN'\nset grid\nset key outside right "
      "top\nset xlabel '" +
      m.parameters[param].name + "'\nset ylabel '" + m.metrics[metric].name + "'\nset title '" +
      m.metrics[metric].name + " (" + m.methods[method] +
      "): mean over the seeds, 95 % interval'\nplot " + plot;
  return scene::plotPng(script, blocks, file.string());
}

// The map over two parameters: the metric's mean as colour, the value printed in each cell.
// Drawn only where every point has its own position in the two parameters.
bool plotMap(const Manifest& m, const std::vector<Row>& rows, std::size_t method,
             std::size_t metric, const fs::path& file, std::string* why) {
  const int x = m.map_x, y = m.map_y;
  std::set<std::pair<double, double>> positions;
  std::set<double> xs, ys;
  for (const Row& r : rows) {
    positions.insert({r.values[x], r.values[y]});
    xs.insert(r.values[x]);
    ys.insert(r.values[y]);
  }
  if (positions.size() != rows.size()) {
    *why = "several points share a position in (" + m.parameters[x].name + ", " +
           m.parameters[y].name +
           ") (other parameters vary too): no map (give a sweep of two "
           "parameters, or \"map\" two that identify the points)";
    return false;
  }
  const std::vector<double> vx(xs.begin(), xs.end()), vy(ys.begin(), ys.end());
  const bool grid = xs.size() * ys.size() == rows.size() && uniform(vx) && uniform(vy) &&
                    xs.size() > 1 && ys.size() > 1;
  std::string csv = "x,y,mean\n";
  std::vector<const Row*> sorted;
  for (const Row& r : rows) sorted.push_back(&r);
  std::sort(sorted.begin(), sorted.end(), [&](const Row* a, const Row* b) {
    return std::make_pair(a->values[y], a->values[x]) < std::make_pair(b->values[y], b->values[x]);
  });
  for (const Row* r : sorted) {
    const double v = r->metrics[metric].mean;
    csv += num(r->values[x]) + "," + num(r->values[y]) + "," + (std::isfinite(v) ? num(v) : "NaN") +
           "\n";
  }
  const std::string cells = grid ? "$d using 1:2:3 with image notitle"
                                 : "$d using 1:2:3 with points pt 5 ps 5 lc palette notitle";
  const std::string script =
      "set datafile separator ','\nset xlabel '" + m.parameters[x].name + "'\nset ylabel '" +
      m.parameters[y].name + "'\nset cblabel '" + m.metrics[metric].name + "'\nset title '" +
      m.name + ": " + m.metrics[metric].name + " (" + m.methods[method] +
      "), mean over the seeds; blank (NaN): no value'\nset palette rgb 33,13,10\n" +
      (grid ? "set autoscale fix\n"
            : "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n") +
      "plot " + cells + ", $d using 1:2:(sprintf('%.4g', $3)) with labels font ',9' notitle";
  return scene::plotPng(script, {{"d", csv}}, file.string());
}

}  // namespace

int collect(const Folder& folder, const Manifest& manifest) {
  const int total = static_cast<int>(manifest.jobs.size());
  const std::size_t methods = manifest.methods.size();
  const std::size_t metrics = manifest.metrics.size();
  const std::size_t health = healthKeys().size();

  // Records, per point.
  std::map<int, std::vector<double>> point_values;
  std::map<int, std::vector<Record>> answered;    // status ok: the seeds of the means
  std::map<int, std::vector<Record>> no_answer;   // finished with no answer: counted apart
  std::map<int, std::pair<int, int>> unfinished;  // point -> (failed, missing)
  std::vector<std::string> problems;
  std::vector<std::string> unanswered;  // the no-answer jobs, with why
  std::string jobs_csv = "id,point,seed";
  for (const Parameter& p : manifest.parameters) jobs_csv += "," + p.name;
  jobs_csv += ",method,status,cpu_s";
  for (const Metric& m : manifest.metrics) jobs_csv += "," + m.name;
  for (const std::string& h : healthKeys()) jobs_csv += "," + h;
  jobs_csv += ",error\n";
  for (const Job& job : manifest.jobs) {
    const std::string id = jobId(job.index, total);
    point_values[job.point] = job.values;
    std::optional<Record> r;
    std::string error;
    try {
      r = readRecord(folder, manifest, id);
    } catch (const std::exception& e) {
      error = e.what();
    }
    auto& [n_failed, n_missing] = unfinished[job.point];
    std::string status;
    if (r && r->status == "ok") {
      answered[job.point].push_back(*r);
      status = "ok";
    } else if (r && r->status == "no_answer") {
      no_answer[job.point].push_back(*r);
      status = "no_answer";
      unanswered.push_back(
          "job " + id + " (point " + std::to_string(job.point) + ", seed " +
          std::to_string(job.seed) +
          "): " + (r->no_answer.empty() ? std::string("no reason recorded") : r->no_answer));
    } else if (r) {
      ++n_failed;
      status = "failed";
      problems.push_back("job " + id + " failed: " + r->error +
                         "\n    rerun: " + jobCommand(folder, id));
    } else {
      ++n_missing;
      status = "missing";
      problems.push_back("job " + id + " " +
                         (error.empty() ? "has no record (not run, or "
                                          "interrupted)"
                                        : error) +
                         "\n    run: " + jobCommand(folder, id));
    }
    for (std::size_t mt = 0; mt < methods; ++mt) {
      jobs_csv += id + "," + std::to_string(job.point) + "," + std::to_string(job.seed);
      for (double v : job.values) jobs_csv += "," + num(v);
      // a job with no answer: per method, the ones whose runs have one are ok
      const bool answers = r && status == "no_answer" && r->trusted[mt];
      jobs_csv += "," + manifest.methods[mt] + "," + (answers ? "ok" : status) + "," +
                  (r ? num(r->cpu_seconds) : "");
      for (std::size_t k = 0; k < metrics; ++k) {
        jobs_csv += "," + (r && r->metrics[mt][k] ? num(*r->metrics[mt][k]) : std::string());
      }
      for (std::size_t k = 0; k < health; ++k) {
        jobs_csv += "," + (r && finished(*r) ? num(r->health[mt][k]) : std::string());
      }
      std::string e = !r                         ? error
                      : answers                  ? ""
                      : r->status == "no_answer" ? r->no_answer
                                                 : r->error;
      std::replace(e.begin(), e.end(), '"', '\'');
      jobs_csv += ",\"" + e + "\"\n";
    }
  }

  // sweep.csv: one row per point and method.
  std::string csv = "point";
  for (const Parameter& p : manifest.parameters) csv += "," + p.name;
  csv += ",method,seeds_ok,seeds_failed,seeds_missing,seeds_no_answer";
  for (const Metric& m : manifest.metrics)
    csv += "," + m.name + "_mean," + m.name + "_ci95," + m.name + "_n";
  for (const std::string& h : healthKeys()) csv += "," + h;
  csv += "\n";
  std::vector<std::vector<Row>> rows(methods);
  for (const auto& [point, values] : point_values) {
    for (std::size_t mt = 0; mt < methods; ++mt) {
      Row row;
      row.point = point;
      row.values = values;
      row.failed = unfinished[point].first;
      row.missing = unfinished[point].second;
      // Per method: a job without an answer (one of its methods has none) still answers for
      // the methods whose runs have one.
      std::vector<const Record*> trusted;
      for (const auto* records : {&answered[point], &no_answer[point]}) {
        for (const Record& r : *records) {
          if (r.trusted[mt]) {
            trusted.push_back(&r);
          } else {
            ++row.no_answer;
          }
        }
      }
      row.ok = static_cast<int>(trusted.size());
      row.health.assign(health, 0.0);
      for (std::size_t k = 0; k < metrics; ++k) {
        std::vector<double> v;
        for (const Record* r : trusted) {
          if (r->metrics[mt][k] && std::isfinite(*r->metrics[mt][k])) {
            v.push_back(*r->metrics[mt][k]);
          }
        }
        row.metrics.push_back(stats(v));
      }
      for (const auto* records : {&answered[point], &no_answer[point]}) {
        for (const Record& r : *records) {
          for (std::size_t k = 0; k < health; ++k) {
            // a count a record does not have (scene_check before it was recorded) adds nothing
            if (std::isfinite(r.health[mt][k])) row.health[k] += r.health[mt][k];
          }
        }
      }
      csv += std::to_string(point);
      for (double v : values) csv += "," + num(v);
      csv += "," + manifest.methods[mt] + "," + std::to_string(row.ok) + "," +
             std::to_string(row.failed) + "," + std::to_string(row.missing) + "," +
             std::to_string(row.no_answer);
      for (const Stats& s : row.metrics) {
        csv += "," + num(s.mean) + "," + num(s.ci95) + "," + std::to_string(s.n);
      }
      for (double h : row.health) {
        csv += "," + (row.ok + row.no_answer > 0 ? num(h) : std::string());
      }
      csv += "\n";
      rows[mt].push_back(row);
    }
  }
  const fs::path out = folder.results();
  scene::writeFileAtomically(out / "sweep.csv", csv);
  scene::writeFileAtomically(out / "jobs.csv", jobs_csv);

  // Plots (of the metrics that have a value somewhere).
  int plots = 0;
  for (std::size_t mt = 0; mt < methods; ++mt) {
    for (std::size_t k = 0; k < metrics; ++k) {
      if (std::none_of(rows[mt].begin(), rows[mt].end(),
                       [&](const Row& r) { return std::isfinite(r.metrics[k].mean); })) {
        std::printf("collect: %s (%s) has no value at any point (%s): not plotted\n",
                    manifest.metrics[k].name.c_str(), manifest.methods[mt].c_str(),
                    unanswered.empty() ? "null in every run's JSON"
                                       : "null in the JSON of every run with an answer; the "
                                         "runs with no answer are left out");
        continue;
      }
      for (std::size_t p = 0; p < manifest.parameters.size(); ++p) {
        // A parameter held at one value has no curve to draw (gnuplot would only warn).
        std::set<double> values;
        for (const Row& row : rows[mt]) values.insert(row.values[p]);
        if (values.size() < 2) continue;
        plots += plotLines(manifest, rows[mt], mt, k, p,
                           out / (manifest.metrics[k].name + "_vs_" + manifest.parameters[p].name +
                                  suffix(manifest, mt) + ".png"));
      }
      if (manifest.map_x >= 0) {
        std::string why;
        if (plotMap(manifest, rows[mt], mt, k,
                    out / (manifest.metrics[k].name + "_map" + suffix(manifest, mt) + ".png"),
                    &why)) {
          ++plots;
        } else if (!why.empty() && k == 0 && mt == 0) {
          std::printf("collect: %s\n", why.c_str());
        }
      }
    }
  }

  // Failed and missing jobs, on stdout and in results/unfinished.txt; jobs with no answer on
  // stderr.
  const fs::path unfinished_file = out / "unfinished.txt";
  std::error_code ec;
  const int finished_count = total - static_cast<int>(problems.size());
  std::printf(
      "collect: %d of %d jobs finished%s; %s/sweep.csv (%zu points x %zu methods), "
      "jobs.csv and %d plots\n",
      finished_count, total,
      unanswered.empty()
          ? ""
          : (", " + std::to_string(unanswered.size()) + " of them with no answer").c_str(),
      fs::absolute(out).lexically_normal().string().c_str(), point_values.size(), methods, plots);
  // Jobs with no answer: finished (a rerun gives none again), so not in unfinished.txt, but
  // never silent: on stderr with why, status no_answer in jobs.csv, seeds_no_answer in
  // sweep.csv, and left out of its means.
  if (!unanswered.empty()) {
    std::fflush(stdout);
    std::fprintf(stderr,
                 "collect: %zu of %d jobs have no answer (status no_answer in jobs.csv, counted "
                 "in sweep.csv's seeds_no_answer, left out of its means and plots):\n",
                 unanswered.size(), total);
    for (const std::string& u : unanswered) std::fprintf(stderr, "  %s\n", u.c_str());
    std::fflush(stderr);
  }
  // Points whose runs had scene-check hazards (a unit slip, a step too coarse): their numbers
  // stand in sweep.csv, but so does the warning count, and stderr names them.
  const auto hazard_key = std::find(healthKeys().begin(), healthKeys().end(), "scene_check");
  const std::size_t hazard_column = static_cast<std::size_t>(hazard_key - healthKeys().begin());
  std::vector<std::string> warned;
  for (std::size_t mt = 0; mt < methods; ++mt) {
    for (const Row& row : rows[mt]) {
      if (!(row.health[hazard_column] > 0)) continue;
      std::string where = "point " + std::to_string(row.point) + " (";
      for (std::size_t p = 0; p < manifest.parameters.size(); ++p) {
        where += (p ? ", " : "") + manifest.parameters[p].name + " " + num(row.values[p]);
      }
      warned.push_back(where + "), " + manifest.methods[mt] + ": " +
                       num(row.health[hazard_column]) + " hazard warnings over its seeds");
    }
  }
  if (!warned.empty()) {
    std::fflush(stdout);
    std::fprintf(stderr,
                 "collect: %zu point(s) ran with scene-check hazards (sweep.csv's scene_check "
                 "column; each run's JSON scene_check and the job's run.log say which):\n",
                 warned.size());
    for (const std::string& w : warned) std::fprintf(stderr, "  %s\n", w.c_str());
    std::fflush(stderr);
  }
  if (problems.empty()) {
    fs::remove(unfinished_file, ec);
  } else {
    std::string text = std::to_string(problems.size()) + " of " + std::to_string(total) +
                       " jobs unfinished (their points have fewer seeds in sweep.csv):\n";
    for (const std::string& p : problems) text += "  " + p + "\n";
    text += "`rheofeed sweep SPEC --out " + fs::absolute(folder.root).lexically_normal().string() +
            "` runs every unfinished job again.\n";
    scene::writeFileAtomically(unfinished_file, text);
    std::printf("collect: %s", text.c_str());
  }
  std::fflush(stdout);
  return static_cast<int>(problems.size());
}

}  // namespace rheofeed::cli::sweep
