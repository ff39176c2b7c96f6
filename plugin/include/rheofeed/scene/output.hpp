// SPDX-License-Identifier: MIT
/// @file output.hpp
/// Writing result files so that no reader ever sees a half-written one.
#pragma once

#include <filesystem>
#include <string>

namespace rheofeed::scene {

/// Writes `text` to `path` through a temporary file in the same folder and a rename, creating
/// the folder if needed. Throws std::runtime_error naming the path on failure (the old file,
/// if any, is then untouched).
void writeFileAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace rheofeed::scene
