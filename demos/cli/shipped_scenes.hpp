// SPDX-License-Identifier: MIT
// Where the `rheofeed` command finds the scenes and meshes shipped with the project, relative to
// its own executable (no path of the source tree is compiled in):
//   <prefix>/bin/rheofeed         -> <prefix>/share/rheofeed/scenes   (installed)
//   <build>/bin/rheofeed          -> <build>/share/rheofeed/scenes    (build tree: links to the
//                                    source tree's demos/scenes and demos/meshes, made by cmake)
// The environment variable RHEOFEED_DATA_DIR, when set, names the data folder instead (the one
// holding scenes/ and meshes/). Scene files name their meshes relative to their own folder
// ("../meshes/vibratory_bowl.stl"), which holds in both layouts.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace rheofeed::cli {

/// The data folder (holding scenes/ and meshes/): $RHEOFEED_DATA_DIR if set, else
/// <folder of the executable>/../share/rheofeed. Empty when the executable's path is unknown.
std::filesystem::path dataDir();

/// Names of the shipped scenes (file stems of <dataDir>/scenes/*.json), sorted; empty when the
/// folder does not exist.
std::vector<std::string> shippedSceneNames();

/// The scene file that the command-line argument `scene` names. An argument with a '/' or
/// ending in ".json" is a path, taken as it is (never a shipped scene: a binary moved anywhere
/// runs a scene given by path). Any other argument is the name of a shipped scene. Throws
/// std::invalid_argument for an unknown name, listing the shipped names and the folder searched.
std::filesystem::path resolveScene(const std::string& scene);

}  // namespace rheofeed::cli
