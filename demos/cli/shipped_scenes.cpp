// SPDX-License-Identifier: MIT
#include "cli/shipped_scenes.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <system_error>

namespace rheofeed::cli {

namespace fs = std::filesystem;

fs::path dataDir() {
  if (const char* env = std::getenv("RHEOFEED_DATA_DIR"); env && *env) return fs::path(env);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec || exe.empty()) return {};
  return (exe.parent_path() / ".." / "share" / "rheofeed").lexically_normal();
}

std::vector<std::string> shippedSceneNames() {
  std::vector<std::string> names;
  const fs::path dir = dataDir();
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir / "scenes", ec)) return names;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "scenes", ec)) {
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

fs::path resolveScene(const std::string& scene) {
  if (scene.empty()) throw std::invalid_argument("SCENE \"\": must name a scene or a scene file");
  const bool is_path = scene.find('/') != std::string::npos ||
                       (scene.size() > 5 && scene.compare(scene.size() - 5, 5, ".json") == 0);
  if (is_path) return fs::path(scene);
  const std::vector<std::string> names = shippedSceneNames();
  if (std::find(names.begin(), names.end(), scene) != names.end()) {
    return dataDir() / "scenes" / (scene + ".json");
  }
  std::string message = "SCENE " + scene + ": not a shipped scene (";
  if (names.empty()) {
    message += "no shipped scenes found in " +
               (dataDir().empty() ? std::string("<unknown>") : (dataDir() / "scenes").string()) +
               "; set RHEOFEED_DATA_DIR to the folder holding scenes/";
  } else {
    message += "shipped scenes:";
    for (const std::string& n : names) message += " " + n;
    message += ", in " + (dataDir() / "scenes").string();
  }
  message += "); give a scene file by a path with a '/' or ending in .json";
  throw std::invalid_argument(message);
}

}  // namespace rheofeed::cli
