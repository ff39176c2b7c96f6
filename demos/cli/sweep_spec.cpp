// SPDX-License-Identifier: MIT
// The sweep spec: reading, checking, expansion into jobs (sweep.hpp; format in
// demos/sweeps/README.md).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "cli/run_plan.hpp"
#include "cli/shipped_scenes.hpp"
#include "cli/sweep.hpp"
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/number_format.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::cli::sweep {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Pointer = Json::json_pointer;

namespace {

// Limits, each with its reason.
constexpr std::uintmax_t kMaxSpecBytes = 1 << 20;  // a hand-written file; bounds the JSON DOM
constexpr int kMaxValues = 10000;                  // values of one parameter (a range's count)
constexpr int kMaxJobs = 100000;                   // each job is a folder and a record in DIR
constexpr std::uint64_t kMaxSeedCount = 1000;      // "seeds": n means seeds 1..n
constexpr int kMaxReported = 10;                   // bad points listed before "and N more"

// A refusal of the spec: "spec FILE: ENTRY: PROBLEM".
[[noreturn]] void fail(const fs::path& file, const std::string& entry, const std::string& what) {
  throw std::invalid_argument("spec " + file.string() + ": " + entry + ": " + what);
}

std::string show(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.12g", v);
  return b;
}

// A value rounded to 12 significant digits: what the CSV shows is what the scene gets (a range
// 0.1, 0.15, ... must not become 0.15000000000000002).
double rounded(double v) {
  return std::strtod(show(v).c_str(), nullptr);
}

bool validName(const std::string& name) {
  return !name.empty() && name.find_first_not_of(
                              "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUV"
                              "WXYZ0123456789_.-") == std::string::npos;
}

// The spec's reading context: the file and helpers that name the entry in every message.
struct Reader {
  fs::path file;

  void keys(const Json& o, const std::string& entry, const std::set<std::string>& allowed) const {
    if (!o.is_object()) fail(file, entry, "must be a JSON object");
    for (auto it = o.begin(); it != o.end(); ++it) {
      if (allowed.count(it.key())) continue;
      std::string list;
      for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(file, entry + "." + it.key(), "unknown key; expected one of " + list);
    }
  }
  double number(const Json& v, const std::string& entry) const {
    if (!v.is_number()) fail(file, entry, "must be a number, not " + v.dump());
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(file, entry, "must be finite");
    return x;
  }
  long long integer(const Json& v, const std::string& entry, long long lo, long long hi) const {
    if (!v.is_number_integer() && !v.is_number_unsigned()) {
      fail(file, entry, "must be an integer, not " + v.dump());
    }
    const long long x = v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(hi)
                            ? hi + 1
                            : v.get<long long>();
    if (x < lo || x > hi) {
      fail(file, entry,
           v.dump() + " is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return x;
  }
  std::string string(const Json& v, const std::string& entry) const {
    if (!v.is_string()) fail(file, entry, "must be a string, not " + v.dump());
    return v.get<std::string>();
  }
  Pointer pointer(const Json& v, const std::string& entry) const {
    const std::string text = string(v, entry);
    try {
      return Pointer(text);
    } catch (const std::exception&) {
      fail(file, entry,
           "\"" + text +
               "\" is not a JSON pointer (RFC 6901: \"/key/index/...\", e.g. "
               "\"/fixtures/0/law/vibration/amplitude\")");
    }
  }
  // The "name" (a valid name, not in `names` yet; added) and "pointer" of a parameter or metric
  // `o`; `entry` gets the name appended for later messages.
  std::string namedPointer(const Json& o, std::string& entry, std::set<std::string>& names,
                           Pointer& pointer_out) const {
    if (!o.contains("name")) fail(file, entry + ".name", "missing");
    const std::string name = string(o["name"], entry + ".name");
    if (!validName(name))
      fail(file, entry + ".name", "\"" + name + "\": use letters, digits, _ . -");
    if (!names.insert(name).second) fail(file, entry + ".name", "\"" + name + "\" repeated");
    entry += " '" + name + "'";
    if (!o.contains("pointer")) fail(file, entry + ".pointer", "missing");
    pointer_out = pointer(o["pointer"], entry + ".pointer");
    return name;
  }
};

// The deepest prefix of `p` that names a value in `doc`, and why the next token names nothing.
std::string whyNothing(const Json& doc, const Pointer& p) {
  std::vector<std::string> tokens;
  for (Pointer q = p; !q.empty(); q.pop_back()) tokens.insert(tokens.begin(), q.back());
  const Json* at = &doc;
  std::string path;
  for (const std::string& t : tokens) {
    const std::string where = path.empty() ? "the scene" : path;
    if (at->is_object()) {
      if (!at->contains(t)) {
        std::string keys;
        for (auto it = at->begin(); it != at->end(); ++it)
          keys += (keys.empty() ? "" : ", ") + it.key();
        return where + " has no key \"" + t + "\" (keys: " + keys + ")";
      }
      at = &(*at)[t];
    } else if (at->is_array()) {
      const bool digits = !t.empty() && t.find_first_not_of("0123456789") == std::string::npos;
      if (!digits || std::stoull(t) >= at->size()) {
        return where + " is an array of " + std::to_string(at->size()) + " elements; \"" + t +
               "\" is not an index in it";
      }
      at = &(*at)[std::stoull(t)];
    } else {
      return where + " is " + at->dump() + ", which has no \"" + t + "\"";
    }
    path += "/" + t;
  }
  return "";
}

// A pointer may name an existing number, or a new key of an existing object (e.g. "angle_deg"
// of a vibration that gave a direction; the scene check refuses a key the format does not
// know). Anything else names nothing (or something that is not a number) and is refused.
void checkTarget(const Reader& r, const Json& scene, const Pointer& p, const std::string& entry,
                 bool number_only) {
  if (p.empty()) fail(r.file, entry, "the pointer \"\" names the whole scene, not a value in it");
  if (scene.contains(p)) {
    const Json& v = scene.at(p);
    if (number_only && !v.is_number()) {
      fail(r.file, entry,
           "the pointer " + p.to_string() + " names " +
               (v.is_object()  ? "an object"
                : v.is_array() ? "an array"
                               : v.dump()) +
               " in the base scene, not a number");
    }
    return;
  }
  const Pointer parent = p.parent_pointer();
  if (!scene.contains(parent) || !scene.at(parent).is_object()) {
    fail(r.file, entry,
         "the pointer " + p.to_string() +
             " names nothing in the base scene: " + whyNothing(scene, p));
  }
}

// JSON for a scene value: an integral number as an integer (counts and iteration limits are
// integers in the scene format), else the double rounded to 12 significant digits.
Json sceneNumber(double v) {
  const double r = rounded(v);
  if (r == std::floor(r) && std::abs(r) < 9.0e15) return Json(static_cast<long long>(r));
  return Json(r);
}

// File names of the base scene (its meshes and its drift table) made absolute (relative to the
// base scene's folder), so that a generated scene works from its own folder.
void absoluteFileNames(Json& scene, const fs::path& folder) {
  auto fixKey = [&](Json& o, const char* key) {
    if (!o.is_object() || !o.contains(key) || !o[key].is_string()) return;
    const fs::path m(o[key].get<std::string>());
    if (!m.empty() && m.is_relative()) o[key] = (folder / m).lexically_normal().string();
  };
  auto fix = [&](Json& o) { fixKey(o, "mesh"); };
  fixKey(scene, "drift_table");
  if (scene.contains("fixtures") && scene["fixtures"].is_array()) {
    for (Json& f : scene["fixtures"]) {
      if (f.is_object() && f.contains("geoms") && f["geoms"].is_array()) {
        for (Json& g : f["geoms"]) fix(g);
      }
    }
  }
  if (scene.contains("parts") && scene["parts"].is_array()) {
    for (Json& p : scene["parts"]) fix(p);
  }
}

std::string readFile(const fs::path& file, const std::string& what) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    throw std::invalid_argument(what + " " + file.string() +
                                (fs::exists(file, ec) ? ": not a regular file" : ": not found"));
  }
  if (fs::file_size(file, ec) > kMaxSpecBytes) {
    throw std::invalid_argument(what + " " + file.string() + ": larger than 1 MiB");
  }
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  if (!in && !in.eof()) throw std::invalid_argument(what + " " + file.string() + ": cannot read");
  return s.str();
}

}  // namespace

std::string sceneHash(const std::string& text) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char b[32];
  std::snprintf(b, sizeof b, "fnv1a64:%016llx", static_cast<unsigned long long>(h));
  return b;
}

namespace {

// A uniform number in [0, 1) from the 53 high bits (std::mt19937_64 is specified by the
// standard; the distributions are not, and a sweep must expand alike on every machine).
double unit(std::mt19937_64& rng) {
  return double(rng() >> 11) * 0x1.0p-53;
}

// Latin hypercube: `n` samples of each of `dims` coordinates in [0, 1), one per stratum
// [k/n, (k+1)/n) of every coordinate, strata shuffled independently (Fisher-Yates).
std::vector<std::vector<double>> latinHypercube(int n, int dims, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::vector<double>> x(static_cast<std::size_t>(n), std::vector<double>(dims));
  for (int d = 0; d < dims; ++d) {
    std::vector<int> strata(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) strata[k] = k;
    for (int k = n - 1; k > 0; --k) {
      const int j = static_cast<int>(unit(rng) * (k + 1));
      std::swap(strata[k], strata[std::min(j, k)]);
    }
    for (int k = 0; k < n; ++k) x[k][d] = (strata[k] + unit(rng)) / n;
  }
  return x;
}

// The run JSON a run of `scene` would write, with every key present (values of a run that has
// not started): metric pointers are checked against it before any job starts. Arrays in it are
// empty (their length depends on the run), so a pointer into an array is checked up to it.
Json runJsonSkeleton(const scene::Scene& s, const std::string& method) {
  scene::RunMetrics r;
  r.scene = s.name;
  r.method = parseMethod(method);
  r.feeder.exit_plane = s.outputs.exit_plane;
  for (const scene::PartSpec& p : s.parts) {
    scene::FamilyExits f;
    f.name = p.name;
    f.shape = p.shape;
    r.feeder.families.push_back(f);
  }
  return Json::parse(scene::summaryJson(r));
}

void checkMetric(const Reader& r, const Json& skeleton, const Pointer& p,
                 const std::string& entry) {
  Pointer prefix;
  const Json* at = &skeleton;
  std::vector<std::string> tokens;
  for (Pointer q = p; !q.empty(); q.pop_back()) tokens.insert(tokens.begin(), q.back());
  if (tokens.empty())
    fail(r.file, entry, "the pointer \"\" names the whole run JSON, not a number");
  for (const std::string& t : tokens) {
    if (at->is_array()) return;  // an element of a list whose length only the run knows
    if (!at->is_object() || !at->contains(t)) {
      fail(r.file, entry,
           "the pointer " + p.to_string() +
               " names nothing in a run's JSON (<method>.json of "
               "`rheofeed run`): " +
               whyNothing(skeleton, p));
    }
    at = &(*at)[t];
  }
  if (!(at->is_number() || at->is_null() || at->is_boolean())) {
    fail(r.file, entry,
         "the pointer " + p.to_string() + " names " +
             (at->is_object()  ? "an object"
              : at->is_array() ? "a list"
                               : "a string") +
             " in a run's JSON, not a number");
  }
}

// Checks a generated scene the way `rheofeed run` does (load, overrides, every method at its
// step) from a file in `tmp`. Returns "" or the problem, the temporary name replaced.
std::string checkScene(const std::string& text, const std::vector<std::string>& methods,
                       const fs::path& tmp) {
  const fs::path file = tmp / "scene.json";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + file.string());
  }
  SceneArgs args;
  args.scene = file.string();
  args.methods = methods;
  try {
    makePlan(args, methods);
  } catch (const std::exception& e) {
    std::string m = e.what();
    for (std::size_t at; (at = m.find(file.string())) != std::string::npos;) {
      m.replace(at, file.string().size(), "the generated scene");
    }
    return m;
  }
  return "";
}

// A temporary folder removed when it goes out of scope.
struct TempFolder {
  fs::path path;
  TempFolder() {
    path = fs::temp_directory_path() / ("rheofeed-sweep-" + std::to_string(::getpid()));
    fs::create_directories(path);
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// "scene path" form of a pointer ("/fixtures/0/law" -> "fixtures[0].law"), as the scene loader
// names values in its messages.
std::string scenePath(const Pointer& p) {
  std::vector<std::string> tokens;
  for (Pointer q = p; !q.empty(); q.pop_back()) tokens.insert(tokens.begin(), q.back());
  std::string out;
  for (const std::string& t : tokens) {
    if (!t.empty() && t.find_first_not_of("0123456789") == std::string::npos) {
      out += "[" + t + "]";
    } else {
      out += (out.empty() ? "" : ".") + t;
    }
  }
  return out;
}

}  // namespace

std::string jobId(int index, int count) {
  const int width = std::max(4, static_cast<int>(std::to_string(std::max(count - 1, 0)).size()));
  std::string id = std::to_string(index);
  return std::string(static_cast<std::size_t>(std::max(0, width - static_cast<int>(id.size()))),
                     '0') +
         id;
}

Spec loadSpec(const fs::path& file) {
  Spec spec;
  spec.file = file;
  spec.text = readFile(file, "spec");
  const Reader r{file};
  Json j;
  try {
    j = Json::parse(spec.text);
  } catch (const Json::parse_error& e) {
    fail(file, "JSON", e.what());
  }
  r.keys(j, "spec",
         {"comment", "name", "scene", "methods", "set", "remove", "parameters", "latin_hypercube",
          "seeds", "metrics", "map", "slurm", "max_lost_fraction"});
  spec.name = j.contains("name") ? r.string(j["name"], "name") : file.stem().string();
  if (!validName(spec.name))
    fail(file, "name", "\"" + spec.name + "\": use letters, digits, _ . -");

  // The base scene: a shipped name, or a file relative to the spec's folder.
  if (!j.contains("scene")) fail(file, "scene", "missing (a shipped scene name or a scene file)");
  scene::Scene base_scene;
  const std::string scene_arg = r.string(j["scene"], "scene");
  try {
    fs::path s = resolveScene(scene_arg);
    const bool is_path = scene_arg.find('/') != std::string::npos || s.extension() == ".json";
    if (is_path && s.is_relative()) s = file.parent_path() / s;  // relative to the spec
    spec.scene_file = fs::absolute(s).lexically_normal();
    base_scene = scene::loadScene(spec.scene_file);  // the base scene itself is valid
  } catch (const std::exception& e) {
    fail(file, "scene", e.what());
  }
  Json base;
  try {
    base = Json::parse(readFile(spec.scene_file, "scene"));
  } catch (const std::exception& e) {
    fail(file, "scene", e.what());
  }
  absoluteFileNames(base, spec.scene_file.parent_path());

  // Methods.
  spec.methods = {"ode_rheonomic"};
  if (j.contains("methods")) {
    if (!j["methods"].is_array() || j["methods"].empty()) {
      fail(file, "methods", "must be a non-empty list of method names (" + methodNames() + ")");
    }
    spec.methods.clear();
    for (std::size_t k = 0; k < j["methods"].size(); ++k) {
      const std::string entry = "methods[" + std::to_string(k) + "]";
      const std::string m = r.string(j["methods"][k], entry);
      try {
        parseMethod(m);
      } catch (const std::exception& e) {
        fail(file, entry, e.what());
      }
      if (std::count(spec.methods.begin(), spec.methods.end(), m))
        fail(file, entry, m + " repeated");
      spec.methods.push_back(m);
    }
  }

  // Fixed changes to the base scene: removals first, then the values set.
  if (j.contains("remove")) {
    if (!j["remove"].is_array()) fail(file, "remove", "must be a list of JSON pointers");
    for (std::size_t k = 0; k < j["remove"].size(); ++k) {
      const std::string entry = "remove[" + std::to_string(k) + "]";
      const Pointer p = r.pointer(j["remove"][k], entry);
      if (p.empty() || !base.contains(p)) {
        fail(file, entry,
             "the pointer " + p.to_string() +
                 " names nothing in the base scene: " + whyNothing(base, p));
      }
      Json& parent = base.at(p.parent_pointer());
      if (parent.is_object()) {
        parent.erase(p.back());
      } else {
        parent.erase(static_cast<std::size_t>(std::stoull(p.back())));
      }
    }
  }
  if (j.contains("set")) {
    if (!j["set"].is_object()) fail(file, "set", "must be an object {\"/json/pointer\": value}");
    for (auto it = j["set"].begin(); it != j["set"].end(); ++it) {
      const std::string entry = "set[\"" + it.key() + "\"]";
      const Pointer p = r.pointer(Json(it.key()), entry);
      checkTarget(r, base, p, entry, false);
      base[p] = it.value();
    }
  }

  // Parameters.
  if (!j.contains("parameters") || !j["parameters"].is_array() || j["parameters"].empty()) {
    fail(file, "parameters",
         "must be a non-empty list of {name, pointer, values | range | latin_hypercube}");
  }
  std::set<std::string> names;
  for (std::size_t k = 0; k < j["parameters"].size(); ++k) {
    const Json& o = j["parameters"][k];
    std::string entry = "parameters[" + std::to_string(k) + "]";
    r.keys(o, entry, {"comment", "name", "pointer", "scale", "values", "range", "latin_hypercube"});
    Parameter p;
    Pointer ptr;
    p.name = r.namedPointer(o, entry, names, ptr);
    checkTarget(r, base, ptr, entry + ".pointer", true);
    p.pointer = ptr.to_string();
    if (o.contains("scale")) {
      p.scale = r.number(o["scale"], entry + ".scale");
      if (p.scale == 0) fail(file, entry + ".scale", "must not be 0");
    }
    const int given =
        int(o.contains("values")) + int(o.contains("range")) + int(o.contains("latin_hypercube"));
    if (given != 1) fail(file, entry, "give exactly one of values, range, latin_hypercube");
    if (o.contains("values")) {
      p.kind = Parameter::Kind::List;
      const Json& v = o["values"];
      if (!v.is_array() || v.empty() || v.size() > std::size_t(kMaxValues)) {
        fail(file, entry + ".values",
             "must be a list of 1 to " + std::to_string(kMaxValues) + " numbers");
      }
      for (std::size_t i = 0; i < v.size(); ++i) {
        p.values.push_back(rounded(r.number(v[i], entry + ".values[" + std::to_string(i) + "]")));
      }
    } else if (o.contains("range")) {
      p.kind = Parameter::Kind::Range;
      const Json& g = o["range"];
      r.keys(g, entry + ".range", {"from", "to", "count", "log"});
      for (const char* key : {"from", "to", "count"}) {
        if (!g.contains(key)) fail(file, entry + ".range." + key, "missing");
      }
      const double from = r.number(g["from"], entry + ".range.from");
      const double to = r.number(g["to"], entry + ".range.to");
      const int count =
          static_cast<int>(r.integer(g["count"], entry + ".range.count", 1, kMaxValues));
      bool log = false;
      if (g.contains("log")) {
        if (!g["log"].is_boolean()) fail(file, entry + ".range.log", "must be true or false");
        log = g["log"].get<bool>();
      }
      if (log && !(from > 0 && to > 0))
        fail(file, entry + ".range", "a log range needs from > 0 and to > 0");
      if (count == 1 && from != to) fail(file, entry + ".range", "count 1 needs from == to");
      for (int i = 0; i < count; ++i) {
        const double f = count == 1 ? 0.0 : double(i) / (count - 1);
        p.values.push_back(rounded(log ? from * std::pow(to / from, f) : from + (to - from) * f));
      }
    } else {
      p.kind = Parameter::Kind::LatinHypercube;
      const Json& g = o["latin_hypercube"];
      r.keys(g, entry + ".latin_hypercube", {"from", "to"});
      for (const char* key : {"from", "to"}) {
        if (!g.contains(key)) fail(file, entry + ".latin_hypercube." + key, "missing");
      }
      p.from = r.number(g["from"], entry + ".latin_hypercube.from");
      p.to = r.number(g["to"], entry + ".latin_hypercube.to");
      if (!(p.to > p.from)) fail(file, entry + ".latin_hypercube", "needs from < to");
    }
    spec.parameters.push_back(p);
  }
  const bool any_lhs =
      std::any_of(spec.parameters.begin(), spec.parameters.end(),
                  [](const Parameter& p) { return p.kind == Parameter::Kind::LatinHypercube; });
  if (j.contains("latin_hypercube")) {
    if (!any_lhs) fail(file, "latin_hypercube", "given, but no parameter is sampled by it");
    const Json& g = j["latin_hypercube"];
    r.keys(g, "latin_hypercube", {"samples", "seed"});
    if (!g.contains("samples")) fail(file, "latin_hypercube.samples", "missing");
    spec.lhs_samples =
        static_cast<int>(r.integer(g["samples"], "latin_hypercube.samples", 1, kMaxJobs));
    spec.lhs_seed = g.contains("seed") ? static_cast<std::uint64_t>(r.integer(
                                             g["seed"], "latin_hypercube.seed", 0, (1ll << 62)))
                                       : 0;
  } else if (any_lhs) {
    fail(
        file, "latin_hypercube",
        "missing: a parameter is sampled by a Latin hypercube; give {\"samples\": n, \"seed\": s}");
  }

  // The runs' bound on lost parts (rheofeed run --max-lost-fraction): a feeder with a reject
  // slot loses parts by design.
  if (j.contains("max_lost_fraction")) {
    const double f = r.number(j["max_lost_fraction"], "max_lost_fraction");
    if (!(f >= 0 && f <= 1)) {
      fail(file, "max_lost_fraction",
           "got " + formatNumber(f) + ": must be a fraction of the parts in [0, 1]");
    }
    spec.max_lost_fraction = f;
  }

  // Seeds: a list, or a count n (seeds 1..n); default the base scene's seed.
  if (j.contains("seeds")) {
    const Json& s = j["seeds"];
    if (s.is_array()) {
      if (s.empty()) fail(file, "seeds", "must not be empty");
      for (std::size_t k = 0; k < s.size(); ++k) {
        const auto seed = static_cast<std::uint64_t>(
            r.integer(s[k], "seeds[" + std::to_string(k) + "]", 0, (1ll << 62)));
        if (std::count(spec.seeds.begin(), spec.seeds.end(), seed))
          fail(file, "seeds[" + std::to_string(k) + "]", "repeated");
        spec.seeds.push_back(seed);
      }
    } else {
      const auto n = static_cast<std::uint64_t>(r.integer(s, "seeds", 1, kMaxSeedCount));
      for (std::uint64_t k = 1; k <= n; ++k) spec.seeds.push_back(k);
    }
  }

  // Metrics, checked against a run's JSON.
  if (!j.contains("metrics") || !j["metrics"].is_array() || j["metrics"].empty()) {
    fail(file, "metrics",
         "must be a non-empty list of {name, pointer} (pointers into a run's JSON, e.g. "
         "\"/mean_drift\")");
  }
  const Json skeleton = runJsonSkeleton(base_scene, spec.methods[0]);
  std::set<std::string> metric_names;
  for (std::size_t k = 0; k < j["metrics"].size(); ++k) {
    const Json& o = j["metrics"][k];
    std::string entry = "metrics[" + std::to_string(k) + "]";
    r.keys(o, entry, {"comment", "name", "pointer"});
    Metric m;
    Pointer ptr;
    m.name = r.namedPointer(o, entry, metric_names, ptr);
    checkMetric(r, skeleton, ptr, entry + ".pointer");
    m.pointer = ptr.to_string();
    spec.metrics.push_back(m);
  }

  // The map's two parameters.
  auto parameterIndex = [&](const Json& v, const std::string& entry) {
    const std::string name = r.string(v, entry);
    for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
      if (spec.parameters[k].name == name) return static_cast<int>(k);
    }
    fail(file, entry, "\"" + name + "\" is not a parameter's name");
  };
  if (j.contains("map")) {
    if (!j["map"].is_array() || j["map"].size() != 2)
      fail(file, "map", "must be a list of two parameter names");
    spec.map_x = parameterIndex(j["map"][0], "map[0]");
    spec.map_y = parameterIndex(j["map"][1], "map[1]");
    if (spec.map_x == spec.map_y) fail(file, "map", "needs two different parameters");
  } else if (spec.parameters.size() >= 2) {
    spec.map_x = 0;
    spec.map_y = 1;
  }

  // Slurm settings.
  if (j.contains("slurm")) {
    const Json& s = j["slurm"];
    r.keys(s, "slurm", {"comment", "jobs_per_task", "time", "partition", "account", "sbatch"});
    if (s.contains("jobs_per_task"))
      spec.slurm.jobs_per_task =
          static_cast<int>(r.integer(s["jobs_per_task"], "slurm.jobs_per_task", 1, kMaxJobs));
    if (s.contains("time")) spec.slurm.time = r.string(s["time"], "slurm.time");
    if (s.contains("partition")) spec.slurm.partition = r.string(s["partition"], "slurm.partition");
    if (s.contains("account")) spec.slurm.account = r.string(s["account"], "slurm.account");
    if (s.contains("sbatch")) {
      if (!s["sbatch"].is_array()) fail(file, "slurm.sbatch", "must be a list of sbatch options");
      for (std::size_t k = 0; k < s["sbatch"].size(); ++k) {
        spec.slurm.sbatch.push_back(
            r.string(s["sbatch"][k], "slurm.sbatch[" + std::to_string(k) + "]"));
      }
    }
  }

  // Expansion: the list and range parameters' grid (the first parameter varies slowest), each
  // grid point crossed with the Latin hypercube samples, each point with every seed.
  std::vector<int> grid_params, lhs_params;
  for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
    (spec.parameters[k].kind == Parameter::Kind::LatinHypercube ? lhs_params : grid_params)
        .push_back(static_cast<int>(k));
  }
  long long grid_points = 1;
  for (int k : grid_params) grid_points *= static_cast<long long>(spec.parameters[k].values.size());
  const long long lhs_points = any_lhs ? spec.lhs_samples : 1;
  const long long seeds = spec.seeds.empty() ? 1 : static_cast<long long>(spec.seeds.size());
  if (grid_points * lhs_points * seeds > kMaxJobs) {
    fail(file, "parameters",
         std::to_string(grid_points * lhs_points * seeds) + " jobs (" +
             std::to_string(grid_points * lhs_points) + " points x " + std::to_string(seeds) +
             " seeds): at most " + std::to_string(kMaxJobs) +
             " in one sweep folder (each job is a folder and a record); split the sweep");
  }
  const std::vector<std::vector<double>> lhs =
      any_lhs ? latinHypercube(spec.lhs_samples, static_cast<int>(lhs_params.size()), spec.lhs_seed)
              : std::vector<std::vector<double>>(1);
  std::vector<std::vector<double>> points;
  for (long long g = 0; g < grid_points; ++g) {
    std::vector<double> values(spec.parameters.size());
    long long rest = g;
    for (auto it = grid_params.rbegin(); it != grid_params.rend(); ++it) {
      const std::vector<double>& v = spec.parameters[*it].values;
      values[*it] = v[static_cast<std::size_t>(rest % static_cast<long long>(v.size()))];
      rest /= static_cast<long long>(v.size());
    }
    for (const std::vector<double>& sample : lhs) {
      for (std::size_t d = 0; d < lhs_params.size(); ++d) {
        const Parameter& p = spec.parameters[lhs_params[d]];
        values[lhs_params[d]] = rounded(p.from + (p.to - p.from) * sample[d]);
      }
      points.push_back(values);
    }
  }
  spec.points = static_cast<int>(points.size());

  // Every point's scene, checked as `rheofeed run` checks it, before any job starts.
  const TempFolder tmp;
  std::vector<std::string> bad;
  std::vector<Json> point_scenes;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Json s = base;
    std::string where;
    for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
      const Parameter& p = spec.parameters[k];
      s[Pointer(p.pointer)] = sceneNumber(points[i][k] * p.scale);
      where += (where.empty() ? "" : ", ") + p.name + " = " + show(points[i][k]);
    }
    point_scenes.push_back(s);
    if (!spec.seeds.empty()) s["seed"] = spec.seeds[0];
    const std::string problem = checkScene(s.dump(2) + "\n", spec.methods, tmp.path);
    if (problem.empty()) continue;
    // Name the parameter whose value the scene check refused, when its message names it.
    std::string entry = "point " + std::to_string(i) + " (" + where + ")";
    for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
      const Parameter& p = spec.parameters[k];
      const std::string path = scenePath(Pointer(p.pointer));
      if (problem.find(path) != std::string::npos) {
        entry = "parameters[" + std::to_string(k) + "] '" + p.name + "' = " + show(points[i][k]) +
                " (scene value " + show(points[i][k] * p.scale) + " at " + p.pointer + "), " +
                entry;
        break;
      }
    }
    bad.push_back(entry + ": " + problem);
  }
  if (!bad.empty()) {
    std::string message = std::to_string(bad.size()) + " of " + std::to_string(points.size()) +
                          " points give a scene that `rheofeed run` refuses:";
    for (std::size_t k = 0; k < bad.size() && k < std::size_t(kMaxReported); ++k)
      message += "\n  " + bad[k];
    if (bad.size() > std::size_t(kMaxReported))
      message += "\n  and " + std::to_string(bad.size() - kMaxReported) + " more";
    fail(file, "parameters", message);
  }

  // The jobs.
  const int count = static_cast<int>(points.size() * static_cast<std::size_t>(seeds));
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (long long s = 0; s < seeds; ++s) {
      Job job;
      job.index = static_cast<int>(spec.jobs.size());
      job.point = static_cast<int>(i);
      job.values = points[i];
      Json scene = point_scenes[i];
      if (!spec.seeds.empty()) scene["seed"] = spec.seeds[static_cast<std::size_t>(s)];
      job.seed = scene.contains("seed") && scene["seed"].is_number_unsigned()
                     ? scene["seed"].get<std::uint64_t>()
                     : base_scene.seed;
      std::string comment = "Generated by rheofeed sweep '" + spec.name + "' (" +
                            file.filename().string() + "), job " + jobId(job.index, count) + ": ";
      for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
        comment += spec.parameters[k].name + " = " + show(points[i][k]) + " (" +
                   spec.parameters[k].pointer + "), ";
      }
      comment += "seed " + std::to_string(job.seed) + "; base scene " +
                 spec.scene_file.filename().string() + ".";
      scene["comment"] = comment;
      job.scene_text = scene.dump(2) + "\n";
      job.scene_hash = sceneHash(job.scene_text);
      spec.jobs.push_back(std::move(job));
    }
  }
  return spec;
}

}  // namespace rheofeed::cli::sweep
