// SPDX-License-Identifier: MIT
#include "rheofeed/output/output.hpp"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "output_json.hpp"
#include "rheofeed/number_format.hpp"
#include "rheofeed/output/plot.hpp"

namespace rheofeed::scene {

void writeFileAtomically(const std::filesystem::path& path, const std::string& text) {
  std::error_code ec;
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), ec);
  if (ec) {
    throw std::runtime_error("cannot create folder " + path.parent_path().string() + ": " +
                             ec.message());
  }
  // A temporary file of this writer's own (process and call): concurrent writers of one path
  // (sweep jobs sharing a drift table) never write into each other's file; the last rename wins.
  static std::atomic<unsigned long> calls{0};
  const std::filesystem::path tmp = path.string() + ".partial." + std::to_string(::getpid()) + "." +
                                    std::to_string(calls.fetch_add(1));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot open " + tmp.string() + " for writing");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(tmp, ec);
      throw std::runtime_error("write failed: " + tmp.string());
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("cannot rename " + tmp.string() + " to " + path.string() + ": " + why);
  }
}

std::string jsonQuoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\u%04x", static_cast<unsigned>(c));
      out += esc;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string jsonNumber(double x) {
  if (!std::isfinite(x)) return "null";
  return formatNumber(x, 8);
}

namespace {

// The families' keys in the JSON and CSV: their names (familyKeys made a run's unique), made
// unique again for metrics filled by hand.
std::vector<std::string> familyNames(const FeederMetrics& f) {
  std::vector<std::string> names;
  for (const FamilyExits& family : f.families) names.push_back(family.name);
  return uniqueNames(names);
}

// A family name as a file name part: letters, digits, '-' and '_' kept, others '_'.
std::string fileNamePart(const std::string& name) {
  std::string out;
  for (char c : name) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '-' || c == '_';
    out += keep ? c : '_';
  }
  return out.empty() ? "family" : out;
}

// Text for a single-quoted gnuplot string.
std::string gnuplotText(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '\'' ? '"' : c;
  return out;
}

}  // namespace

std::string exitsCsv(const FeederMetrics& feeder) {
  std::ostringstream s;
  s << "window_start_s,window_end_s,exits,rate_per_min,cumulative_exits\n";
  char line[160];
  for (const RateWindow& w : feeder.rate) {
    std::snprintf(line, sizeof line, "%.6f,%.6f,%d,%.8g,%d\n", w.start, w.end, w.exits,
                  w.rate_per_min, w.cumulative);
    s << line;
  }
  return s.str();
}

std::string orientationCsv(const FeederMetrics& feeder) {
  std::ostringstream s;
  s << "family,shape,spawned,exited,removed_without_exit,lost_before_exit,orientation_meaningful";
  for (int a = 0; a < kUpAxisCount; ++a) s << "," << toString(static_cast<UpAxis>(a));
  s << "\n";
  const std::vector<std::string> keys = familyNames(feeder);
  for (std::size_t k = 0; k < feeder.families.size(); ++k) {
    const FamilyExits& f = feeder.families[k];
    std::string name = keys[k];  // CSV: a name with a comma or quote is quoted
    if (name.find_first_of(",\"\n") != std::string::npos) {
      std::string q = "\"";
      for (char c : name) q += c == '"' ? std::string("\"\"") : std::string(1, c);
      name = q + "\"";
    }
    s << name << "," << toString(f.shape) << "," << f.spawned << "," << f.exited << ","
      << f.removed_without_exit << "," << f.lost_before_exit << ","
      << (f.orientation_meaningful ? "true" : "false");
    for (int n : f.up_axis) s << "," << n;
    s << "\n";
  }
  return s.str();
}

OrderedJson feederJsonValue(const FeederMetrics& f) {
  OrderedJson rate = OrderedJson::array();
  for (const RateWindow& w : f.rate) {
    rate.push_back({{"t_s", 0.5 * (w.start + w.end)},
                    {"t_start_s", w.start},
                    {"t_end_s", w.end},
                    {"exits", w.exits},
                    {"rate_per_min", w.rate_per_min},
                    {"cumulative_exits", w.cumulative}});
  }
  const std::vector<std::string> keys = familyNames(f);
  OrderedJson families = OrderedJson::object(), orientation = OrderedJson::object();
  for (std::size_t k = 0; k < f.families.size(); ++k) {
    const FamilyExits& fam = f.families[k];
    families[keys[k]] = {{"shape", toString(fam.shape)},
                         {"spawned", fam.spawned},
                         {"exited", fam.exited},
                         {"removed_without_exit", fam.removed_without_exit},
                         {"lost_before_exit", fam.lost_before_exit},
                         {"orientation_meaningful", fam.orientation_meaningful}};
    OrderedJson bins = OrderedJson::object();
    for (int a = 0; a < kUpAxisCount; ++a) {
      bins[toString(static_cast<UpAxis>(a))] = fam.up_axis[static_cast<std::size_t>(a)];
    }
    orientation[keys[k]] = std::move(bins);
  }
  OrderedJson j;
  j["exit_plane"] = f.exit_plane;
  j["up"] = {f.up.x, f.up.y, f.up.z};
  j["first_exit_time_s"] = f.first_exit_time;  // NaN without an exit: null
  j["note"] = f.note.empty() ? OrderedJson() : OrderedJson(f.note);
  j["mean_exit_rate_per_min"] = f.mean_rate_per_min;
  j["rate_window_s"] = f.rate_window;
  j["parts_exited"] = f.exit_times.size();
  j["spawned_beyond_exit"] = f.spawned_beyond_exit;
  j["exit_rate_per_min"] = std::move(rate);
  j["exit_times_s"] = f.exit_times;
  j["families"] = std::move(families);
  j["exit_orientation"] = std::move(orientation);
  return j;
}

std::string oneLineJson(const OrderedJson& value) {
  return value.dump(-1, ' ', false, OrderedJson::error_handler_t::replace);
}

std::string feederJson(const FeederMetrics& f) {
  return oneLineJson(feederJsonValue(f));
}

std::vector<std::string> writeFeederOutputs(const FeederMetrics& feeder,
                                            const std::filesystem::path& folder,
                                            const std::string& stem, const std::string& title) {
  std::vector<std::string> written;
  if (!feeder.exit_plane) return written;
  const std::string base = (folder / stem).string();
  const std::string exits = exitsCsv(feeder);
  writeFileAtomically(base + "_exits.csv", exits);
  written.push_back(base + "_exits.csv");
  writeFileAtomically(base + "_orientation.csv", orientationCsv(feeder));
  written.push_back(base + "_orientation.csv");

  // Cumulative count as a step function of the exact exit times.
  const double end = feeder.rate.empty() ? 0 : feeder.rate.back().end;
  std::ostringstream times;
  times << "t_s,cumulative\n0,0\n";
  for (std::size_t k = 0; k < feeder.exit_times.size(); ++k) {
    times << jsonNumber(feeder.exit_times[k]) << "," << k + 1 << "\n";
  }
  times << jsonNumber(end) << "," << feeder.exit_times.size() << "\n";
  // The mean rate over the span it is measured on.
  std::string mean = "t_s,rate_per_min\n";
  if (std::isfinite(feeder.mean_rate_per_min)) {
    const std::string rate = jsonNumber(feeder.mean_rate_per_min);
    mean += jsonNumber(feeder.exit_times.front()) + "," + rate + "\n" +
            jsonNumber(feeder.exit_times.back()) + "," + rate + "\n";
  }
  const std::string heading = gnuplotText(title);
  std::ostringstream gp;
  gp << "set datafile separator ','\nset grid\nset key top left opaque\n"
     << "set multiplot layout 2,1 title '" << heading << ": " << feeder.exit_times.size()
     << " parts out"
     << (feeder.exit_times.empty() ? " (" + gnuplotText(feeder.note) + ")" : std::string()) << "'\n"
     << "set xrange [0:" << jsonNumber(end)
     << "]\nset yrange [0:" << (feeder.exit_times.empty() ? "1" : "*") << "]\n"
     << "set ylabel 'output rate (parts/min)'\nset style fill solid 0.5\nset offsets 0, 0, graph "
        "0.15, 0\n"
     << "plot $exits using (($1+$2)/2):4:($2-$1) with boxes lc rgb '#1040a0' title 'window of "
     << jsonNumber(feeder.rate_window) << " s'"
     << (std::isfinite(feeder.mean_rate_per_min)
             ? ", $mean using 1:2 with lines dt 2 lw 2 lc rgb '#a02010' title 'mean, first to "
               "last exit'"
             : std::string())
     << "\n"
     << "set offsets 0, 0, 0, 0\nset xlabel 'time (s)'\nset ylabel 'parts out (cumulative)'\n"
     << "plot $times using 1:2 with steps lw 2 lc rgb '#a02010' title 'cumulative'\n"
     << "unset multiplot\n";
  const std::string exits_png = base + "_exits.png";
  if (plotPng(gp.str(), {{"exits", exits}, {"times", times.str()}, {"mean", mean}}, exits_png)) {
    written.push_back(exits_png);
  }

  const std::vector<std::string> keys = familyNames(feeder);
  std::set<std::string> used;
  for (std::size_t k = 0; k < feeder.families.size(); ++k) {
    const FamilyExits& f = feeder.families[k];
    std::string part = fileNamePart(f.name);
    if (!used.insert(part).second) {
      part += "_" + std::to_string(k);
      used.insert(part);
    }
    std::ostringstream bins;
    bins << "axis,parts\n";
    for (int a = 0; a < kUpAxisCount; ++a) {
      bins << toString(static_cast<UpAxis>(a)) << "," << f.up_axis[static_cast<std::size_t>(a)]
           << "\n";
    }
    std::ostringstream hp;
    hp << "set datafile separator ','\nset grid ytics\nset key off\n"
       << "set title '" << heading << ": " << gnuplotText(keys[k]) << " (" << toString(f.shape)
       << "), " << f.exited << " of " << f.spawned << " parts out"
       << (f.orientation_meaningful ? "" : "; a sphere has no axis: orientation meaningless")
       << "'\n"
       << "set xlabel 'body axis pointing up at the exit'\nset ylabel 'parts'\n"
       << "set yrange [0:" << (f.exited > 0 ? "*" : "1") << "]\nset xrange [-0.5:5.5]\n"
       << "set boxwidth 0.6\nset style fill solid 0.6\n"
       << "plot $bins using 0:2:xtic(1) with boxes lc rgb '#208040'\n";
    const std::string png = base + "_orientation_" + part + ".png";
    if (plotPng(hp.str(), {{"bins", bins.str()}}, png)) written.push_back(png);
  }
  return written;
}

}  // namespace rheofeed::scene
