// SPDX-License-Identifier: MIT
// libFuzzer target: a drift table file from bytes through parseDriftTable
// (rheofeed/scene/drift_table_file.hpp), i.e. JSON parse, the header checks against a table of
// the default point-mass settings, the corner rows and LocalDriftTable::addCorners.
//
// SceneFileError (the documented refusal) is the expected outcome for most inputs. Anything
// else is a finding: a crash or sanitizer report, another exception type escaping, a timeout,
// an input refused after adding corners, or a broken round trip: a table that parseDriftTable
// accepts must be written by driftTableJson as text that parseDriftTable reads into a fresh
// table with the same corners, and that writes back to the same text.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "rheofeed/scene/drift_table_file.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "rheofeed/vibration_drift.hpp"

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_drift_table finding: %s\n%s\n", what, detail.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using rheofeed::LocalDriftTable;
  using rheofeed::scene::SceneFileError;
  const std::string text(reinterpret_cast<const char*>(data), size);
  LocalDriftTable table;
  try {
    rheofeed::scene::parseDriftTable(text, "fuzz", table);
  } catch (const SceneFileError&) {
    if (table.numCorners() != 0) finding("refused after adding corners", text);
    return 0;
  }
  const std::string written = rheofeed::scene::driftTableJson(table);
  LocalDriftTable again;
  try {
    rheofeed::scene::parseDriftTable(written, "round trip", again);
  } catch (const SceneFileError& e) {
    finding("the written table is refused", std::string(e.what()) + "\n" + written);
  }
  if (again.numCorners() != table.numCorners()) finding("corners lost in the round trip", written);
  if (rheofeed::scene::driftTableJson(again) != written) {
    finding("the round trip writes other text", written);
  }
  return 0;
}
