// SPDX-License-Identifier: MIT
// Shared command line and run loop of the feeder demos: each demo file builds its scene (or
// loads one with --scene), and this runs it headless with the chosen methods, calibrating a
// vibrating feeder first when a rheonomic method needs it, and writes CSV + JSON + PNG outputs.
#pragma once

#include <string>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::demo {

/// Parses the demo's command line (--scene, --duration, --dt, --out, --method, --full, ...),
/// runs the scene and prints a summary. Returns the process exit code (0 on success, 2 on bad
/// input with the message on stderr).
int runDemo(int argc, char** argv, const std::string& name, const std::string& description,
            scene::Scene builtin);

}  // namespace rheofeed::demo
