// SPDX-License-Identifier: MIT
// Links the scene layer of the installed package (rheofeed::scene_io pulls rheofeed::scene, the
// reference solver, Eigen, nlohmann-json and assimp): writes an empty scene as JSON.
#include <cstdio>
#include <rheofeed/scene/scene_io.hpp>
#include <string>

int main() {
  const std::string json = rheofeed::scene::toJson(rheofeed::scene::Scene{});
  const bool ok = !json.empty() && json.front() == '{';
  std::printf("consumer_scene: %zu bytes of scene JSON: %s\n", json.size(), ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
