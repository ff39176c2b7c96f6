// SPDX-License-Identifier: MIT
// Links the scene description of the installed package (rheofeed::scene: scenes and their JSON
// files, no engine, plot or animation): writes an empty scene as JSON.
#include <cstdio>
#include <rheofeed/scene/scene_io.hpp>
#include <string>

int main() {
  const std::string json = rheofeed::scene::toJson(rheofeed::scene::Scene{});
  const bool ok = !json.empty() && json.front() == '{';
  std::printf("consumer_scene: %zu bytes of scene JSON: %s\n", json.size(), ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
