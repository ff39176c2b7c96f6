// SPDX-License-Identifier: MIT
/// @file plot.hpp
/// PNG plots through gnuplot (Debian's gnuplot-nox), written atomically.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace rheofeed::scene {

/// Renders a gnuplot `script` to the PNG `path` (1000 x 600, pngcairo). Each (name, csv) in
/// `datablocks` is available to the script as the datablock `$name` (CSV text, header line
/// skipped). Returns false (and says why on stderr) if gnuplot is missing or fails; the PNG is
/// then not created and no partial file is left. gnuplot's own messages (warnings such as a
/// series with no valid points) go to stderr, each line prefixed with `path`.
bool plotPng(const std::string& script,
             const std::vector<std::pair<std::string, std::string>>& datablocks,
             const std::string& path);

/// `text` as one word for a POSIX shell: in single quotes, each ' written as '\''.
std::string shellQuoted(const std::string& text);

}  // namespace rheofeed::scene
