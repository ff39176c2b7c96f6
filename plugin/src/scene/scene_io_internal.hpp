// SPDX-License-Identifier: MIT
// Internal: what the scene file reader's files share (scene_io.hpp): refusing a value with
// its JSON path, quoting a value, and the text -> DOM step (scene_io_json.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::scene::io {

using json = nlohmann::json;

// Throws a SceneFileError naming `path` (the source and position are added by the caller).
[[noreturn]] void fail(const std::string& path, const std::string& problem);
// A value as an error quotes it: "an object", "an array of 3", or its JSON text (<= 40 chars).
std::string describe(const json& v);
// A number with 10 significant digits.
std::string show(double v);
// The DOM of a scene file's text, with duplicate keys and overflowing numbers refused by path
// and syntax errors by line and column (scene_io_json.cpp).
json parseText(const std::string& text);
// Loads the meshes a scene names and checks them against the scene limits
// (scene_io_mesh.cpp; declared for parseScene, defined public in scene_io.hpp).

}  // namespace rheofeed::scene::io
