// SPDX-License-Identifier: MIT
// Belt line (draft).
#include <cstdio>
#include <exception>

#include "common/demo_runner.hpp"
#include "rheofeed/scene/scene_io.hpp"

#ifndef RHEOFEED_DEMO_SCENES_DIR
#error "RHEOFEED_DEMO_SCENES_DIR must name the folder of the built-in scene files"
#endif

int main(int argc, char** argv) {
  rheofeed::scene::Scene scene;
  try {
    scene = rheofeed::scene::loadScene(RHEOFEED_DEMO_SCENES_DIR "/belt_conveyor.json");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "belt_line: built-in scene: %s\n", e.what());
    return 2;
  }
  return rheofeed::demo::runDemo(argc, argv, "belt_line",
                                 "rheofeed belt line",
                                 scene);
}
