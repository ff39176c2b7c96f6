// SPDX-License-Identifier: MIT
// Drift table files (drift_table_file.hpp): LocalDriftTable corners <-> JSON. The header keys
// are checked against the table before any corner is read, so that a file of other settings
// never mixes its values into a run.
#include "rheofeed/scene/drift_table_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <tuple>
#include <vector>

#include "rheofeed/scene/scene_io.hpp"
#include "scene_io_internal.hpp"
#include "scene_limits.hpp"

namespace rheofeed::scene {
namespace {

using io::json;

constexpr const char* kFormat = "rheofeed local drift table";

json settingsJson(const PointMassSettings& s) {
  return json{{"steps_per_cycle", s.steps_per_cycle},
              {"max_cycles", s.max_cycles},
              {"average_cycles", s.average_cycles},
              {"max_period", s.max_period},
              {"periodic_tolerance", s.periodic_tolerance}};
}

json gridJson() {
  return json{{"normal_throw", LocalDriftTable::kNormalThrowStep},
              {"tangential_throw", LocalDriftTable::kTangentialThrowStep},
              {"slope", LocalDriftTable::kSlopeStep}};
}

json columnsJson() {
  return json{"normal_throw_index",
              "tangential_throw_index",
              "slope_along_index",
              "slope_across_index",
              "mu",
              "along",
              "across",
              "valid"};
}

// Throws naming `key` when the file's object `found` differs from the table's `expected`.
void requireSame(const std::string& file, const std::string& key, const json& found,
                 const json& expected) {
  if (found.is_null()) throw SceneFileError(file, key, "is missing");
  if (!found.is_object()) {
    throw SceneFileError(file, key, "must be an object, found " + io::describe(found));
  }
  for (const auto& [name, value] : expected.items()) {
    const auto it = found.find(name);
    if (it == found.end()) throw SceneFileError(file, key + "." + name, "is missing");
    if (*it != value) {
      throw SceneFileError(file, key + "." + name,
                           "is " + io::describe(*it) + " in the file and " + value.dump() +
                               " in this build: the table was made with other settings (delete "
                               "the file to rebuild it)");
    }
  }
  if (found.size() != expected.size()) {
    throw SceneFileError(file, key, "has keys this build does not know");
  }
}

DriftTableCorner readCorner(const std::string& file, std::size_t index, const json& row) {
  const std::string where = "corners[" + std::to_string(index) + "]";
  if (!row.is_array() || row.size() != 8) {
    throw SceneFileError(file, where, "must be an array of 8 numbers, found " + io::describe(row));
  }
  DriftTableCorner c;
  for (int d = 0; d < 4; ++d) {
    const json& v = row[static_cast<std::size_t>(d)];
    if (!v.is_number_integer()) {
      throw SceneFileError(file, where + "[" + std::to_string(d) + "]",
                           "must be an integer grid index, found " + io::describe(v));
    }
    c.grid[d] = v.get<std::int64_t>();
    // Gamma, tau and s2 (mirror symmetry: only s2 >= 0 is tabulated) are never negative.
    if (d != 2 && c.grid[d] < 0) {
      throw SceneFileError(file, where + "[" + std::to_string(d) + "]",
                           "must be >= 0, found " + std::to_string(c.grid[d]));
    }
  }
  double values[3];
  for (int k = 0; k < 3; ++k) {
    const json& v = row[static_cast<std::size_t>(4 + k)];
    if (!v.is_number()) {
      throw SceneFileError(file, where + "[" + std::to_string(4 + k) + "]",
                           "must be a number, found " + io::describe(v));
    }
    values[k] = v.get<double>();
  }
  c.mu = values[0];
  c.along = values[1];
  c.across = values[2];
  if (!(c.mu >= 0)) {
    throw SceneFileError(file, where + "[4]", "mu must be >= 0, found " + io::show(c.mu));
  }
  const json& valid = row[7];
  if (!valid.is_number_integer() ||
      (valid.get<std::int64_t>() != 0 && valid.get<std::int64_t>() != 1)) {
    throw SceneFileError(file, where + "[7]", "must be 0 or 1, found " + io::describe(valid));
  }
  c.valid = valid.get<std::int64_t>() == 1;
  return c;
}

}  // namespace

std::string driftTableJson(const LocalDriftTable& table) {
  const json header{{"format", kFormat},
                    {"model_revision", LocalDriftTable::kModelRevision},
                    {"point_mass_settings", settingsJson(table.settings())},
                    {"grid_steps", gridJson()},
                    {"columns", columnsJson()}};
  std::string text = header.dump();
  text.pop_back();  // the closing brace: the corners follow, one per line
  text += ",\n\"corners\": [";
  const std::vector<DriftTableCorner> corners = table.corners();
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const DriftTableCorner& c = corners[k];
    // nlohmann writes the shortest text that reads back to the same double.
    const json row{c.grid[0], c.grid[1], c.grid[2], c.grid[3],
                   c.mu,      c.along,   c.across,  c.valid ? 1 : 0};
    text += (k ? ",\n" : "\n") + row.dump();
  }
  text += "\n]}\n";
  return text;
}

std::size_t loadDriftTable(const std::filesystem::path& path, LocalDriftTable& table) {
  const std::string file = path.string();
  const std::string problem = limits::regularFileProblem(path, limits::kMaxSceneFileBytes);
  if (!problem.empty()) throw SceneFileError(file, "", problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneFileError(file, "", "cannot open the file for reading");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw SceneFileError(file, "", "cannot read the file");
  return parseDriftTable(text.str(), file, table);
}

std::size_t parseDriftTable(const std::string& text, const std::string& file,
                            LocalDriftTable& table) {
  json doc;
  try {
    doc = io::parseText(text);
  } catch (const SceneFileError& e) {
    throw SceneFileError(file, e.path(), e.problem(), e.line(), e.column());
  }
  if (!doc.is_object()) throw SceneFileError(file, "", "must be a JSON object");
  const auto format = doc.find("format");
  if (format == doc.end() || *format != kFormat) {
    throw SceneFileError(file, "format",
                         std::string("must be \"") + kFormat + "\": not a drift table file");
  }
  const auto revision = doc.find("model_revision");
  if (revision == doc.end() || *revision != LocalDriftTable::kModelRevision) {
    throw SceneFileError(
        file, "model_revision",
        "is " + (revision == doc.end() ? std::string("missing") : io::describe(*revision)) +
            "; this build's point-mass model is revision " +
            std::to_string(LocalDriftTable::kModelRevision) + " (delete the file to rebuild it)");
  }
  requireSame(file, "point_mass_settings", doc.value("point_mass_settings", json()),
              settingsJson(table.settings()));
  requireSame(file, "grid_steps", doc.value("grid_steps", json()), gridJson());
  if (doc.value("columns", json()) != columnsJson()) {
    throw SceneFileError(file, "columns", "must be " + columnsJson().dump());
  }
  for (const auto& [key, value] : doc.items()) {
    (void)value;
    if (key != "format" && key != "model_revision" && key != "point_mass_settings" &&
        key != "grid_steps" && key != "columns" && key != "corners") {
      throw SceneFileError(file, key, "unknown key");
    }
  }
  const auto rows = doc.find("corners");
  if (rows == doc.end() || !rows->is_array()) {
    throw SceneFileError(file, "corners", "must be an array of corners");
  }
  std::vector<DriftTableCorner> corners;
  corners.reserve(rows->size());
  for (std::size_t k = 0; k < rows->size(); ++k) corners.push_back(readCorner(file, k, (*rows)[k]));
  // The same grid point twice: a table written by driftTableJson never has it.
  std::vector<std::size_t> order(corners.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  auto key = [&](std::size_t k) {
    const DriftTableCorner& c = corners[k];
    return std::make_tuple(c.mu, c.grid[0], c.grid[1], c.grid[2], c.grid[3]);
  };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return key(a) < key(b) || (key(a) == key(b) && a < b);
  });
  for (std::size_t k = 1; k < order.size(); ++k) {
    if (key(order[k]) == key(order[k - 1])) {
      throw SceneFileError(
          file, "corners[" + std::to_string(order[k]) + "]",
          "the same grid point and mu as corners[" + std::to_string(order[k - 1]) + "]");
    }
  }
  try {
    return table.addCorners(corners);
  } catch (const std::invalid_argument& e) {
    throw SceneFileError(file, "corners", e.what());
  }
}

}  // namespace rheofeed::scene
