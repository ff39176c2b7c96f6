// SPDX-License-Identifier: MIT
// `rheofeed calibrate SCENE --out NEW.json`.
#include <cstdio>
#include <exception>
#include <iterator>
#include <stdexcept>
#include <system_error>

#include "cli/commands.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::cli {

using namespace rheofeed::scene;

namespace {

// A mesh path (absolute after loading) relative to the folder of the file written, so that the
// new scene keeps working when that folder moves together with its meshes.
std::string relativeTo(const std::string& mesh, const std::filesystem::path& folder) {
  if (mesh.empty()) return mesh;
  std::error_code ec;
  const std::filesystem::path base = std::filesystem::absolute(folder, ec);
  const std::filesystem::path file(mesh);
  // Only within one top-level folder: "../../../work/x.stl" from /tmp is no better than
  // /work/x.stl.
  if (ec || !file.is_absolute() || std::distance(base.begin(), base.end()) < 2 ||
      std::distance(file.begin(), file.end()) < 2 ||
      *std::next(base.begin()) != *std::next(file.begin())) {
    return mesh;
  }
  const std::filesystem::path rel = std::filesystem::relative(file, base, ec);
  return ec || rel.empty() ? mesh : rel.generic_string();
}

// Escapes `text` as the contents of a JSON string.
std::string jsonString(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

}  // namespace

void noteIgnoredCycleOptions(const char* program, bool cycles_given, bool calibrated,
                             bool classical) {
  if (!cycles_given || (calibrated && !classical)) return;
  std::fprintf(stderr, "%s: note: --warmup-cycles / --measure-cycles ignored: %s\n", program,
               classical ? "--classical runs no sampling run" : "nothing was calibrated");
}

int calibrateCommand(const CalibrateArgs& args) {
  Plan plan;
  const std::filesystem::path out(args.out);
  try {
    if (args.out.empty()) throw std::invalid_argument("--out \"\": must name the new scene file");
    if (out.extension() != ".json") {
      throw std::invalid_argument("--out " + args.out + ": the new scene file must end in .json");
    }
    plan = makePlan(args.scene, {"ode_rheonomic"});
    if (!plan.scene.hasVibration()) {
      throw std::invalid_argument("scene " + plan.file.string() +
                                  ": no vibrating feeder, nothing to calibrate");
    }
    const std::filesystem::path folder = out.parent_path().empty() ? "." : out.parent_path();
    prepareOutputFolder(folder, "--out");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rheofeed calibrate: %s\n", e.what());
    return 2;
  }
  return runChecked("rheofeed calibrate", [&] {
    Scene scene = plan.scene;
    CalibrateOptions options = args.calibrate;
    options.rheonomic_time_step = runStep(scene, Method::OdeRheonomic).time_step;
    const CalibrateReport report = calibrateScene(scene, options, "rheofeed calibrate", stderr);
    if (report.calibrated == 0 && report.given == 0) {
      throw std::invalid_argument(
          "scene " + plan.file.string() +
          ": every vibrating feeder uses the local vibration law, which needs no calibration "
          "(nothing written); --drift-model local_sampled or calibrated_drift calibrates one");
    }
    if (report.calibrated == 0) {
      std::fprintf(stderr,
                   "rheofeed calibrate: the scene gives the calibration of every vibrating "
                   "fixture that takes one: nothing calibrated (--force calibrates again); "
                   "writing the scene with that calibration and the drift model used here "
                   "(--drift-model, if given), without its comments\n");
    }
    noteIgnoredCycleOptions("rheofeed calibrate", args.cycles_given, report.calibrated > 0,
                            options.classical);
    const std::filesystem::path folder = out.parent_path().empty() ? "." : out.parent_path();
    for (Fixture& f : scene.fixtures) {
      for (Fixture::Geom& g : f.geoms) g.shape.mesh = relativeTo(g.shape.mesh, folder);
    }
    for (PartSpec& p : scene.parts) p.mesh = relativeTo(p.mesh, folder);
    std::string text = toJson(scene);
    const std::string comment =
        "Written by rheofeed calibrate from " + plan.file.string() +
        " (its comments are not copied). " +
        (report.calibrated > 0
             ? "Calibrated: " + report.summary.substr(0, report.summary.size() - 1)
             : std::string("No fixture calibrated: the scene gave them.")) +
        " Each fixture's drift_model is the one this calibration used." +
        " Re-run the calibration whenever the vibration, the parts or mu change.";
    const std::size_t brace = text.find('{');
    text.insert(brace + 1, "\n  \"comment\": \"" + jsonString(comment) + "\",");
    parseScene(text, out.string());  // the file written reads back (meshes and all)
    writeFileAtomically(out, text);
    std::printf("%swrote %s\n", report.summary.c_str(), out.string().c_str());
  });
}

}  // namespace rheofeed::cli
