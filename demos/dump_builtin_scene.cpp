// SPDX-License-Identifier: MIT
// Writes a built-in scene (common/builtin_scenes.hpp) as a scene file on stdout, the way the
// files of demos/scenes/ that come from code are made (their comments are added by hand):
//   dump_builtin_scene bowl_feeder_fill > demos/scenes/bowl_feeder_fill.json
#include <CLI/CLI.hpp>
#include <iostream>

#include "common/builtin_scenes.hpp"
#include "rheofeed/scene/scene_io.hpp"

int main(int argc, char** argv) {
  CLI::App app{"write a built-in scene as JSON on stdout"};
  std::string name;
  app.add_option("SCENE", name,
                 "bowl_feeder_primitives (12 nuts) or bowl_feeder_fill (240 nuts poured in)")
      ->required()
      ->check(CLI::IsMember({"bowl_feeder_primitives", "bowl_feeder_fill"}));
  CLI11_PARSE(app, argc, argv);
  using namespace rheofeed::scene;
  const Scene scene =
      name == "bowl_feeder_fill" ? bowlFeederScene(240, 6, true, 120) : bowlFeederScene();
  std::cout << toJson(scene);
  return 0;
}
