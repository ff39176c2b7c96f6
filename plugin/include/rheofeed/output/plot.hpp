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
/// then not created and no partial file is left.
bool plotPng(const std::string& script,
             const std::vector<std::pair<std::string, std::string>>& datablocks,
             const std::string& path);

}  // namespace rheofeed::scene
