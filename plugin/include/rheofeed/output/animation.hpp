// SPDX-License-Identifier: MIT
/// @file animation.hpp
/// An animation of a run: a glTF 2.0 binary file (.glb) that opens in Blender and any glTF
/// viewer, and a page (view.html) that plays it offline in a browser beside the run's plots.
///
/// The file holds one root node, "rheofeed_world", whose children are one node per fixture (named
/// after the fixture) and one node per spawned part (named "part_<i>_<family>", i the spawn index
/// of the simulation, family the PartSpec name; names are reduced to [A-Za-z0-9_-], other
/// characters become '_'). Each node has its own mesh: the fixture's geoms (boxes, spheres,
/// cylinders, capsules tessellated; planes as a finite square around the scene,
/// kPlaneMargin; meshes from Shape::mesh_data) in the world frame at rest, a part's shape in
/// its body frame about its centre of mass. Colours: one per part family (PartSpec index),
/// fixtures grey.
///
/// Units and frames: metres and seconds; the children's translations and rotations are the
/// simulation's world frame (a part's translation is its centre of mass, Simulation::part). glTF
/// is y-up: the root node rotates the scene's "up" (-gravity, +z when gravity is zero) onto +y,
/// so a z-up scene stands upright in every viewer (Blender's importer turns it back to z-up).
///
/// Animation "run": per part, translation and rotation (unit quaternion x, y, z, w) at the
/// recorded times with LINEAR interpolation, and scale with STEP interpolation: 0 before the part
/// spawned (it is hidden there, at its first recorded pose), 1 while it is in the simulation, 0
/// again from the first sample at which it was removed (PartState::active false: fell, exited
/// below the removal height, lost). In full-vibration runs (isFullVibration) each vibrating
/// fixture (FeederLaw::Kind::Vibration) is animated with Vibration::displacement(t) at the same
/// recorded times. The recorded times are the output samples (Outputs::sample_interval), which
/// are usually much coarser than a vibration period: the feeder's motion is then aliased (it
/// shows the displacement at the sample instants, e.g. a feeder that seems still when the
/// interval is a whole number of periods), the parts' transport is not.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "rheofeed/simulation/run.hpp"
#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {

/// Margin (m) of the square that stands for an infinite plane fixture: its half edge is half the
/// diagonal of the scene's extent (SceneLimits::extent) plus this margin.
constexpr double kPlaneMargin = 0.5;

/// Records a run's part poses at the output samples and writes them as a .glb file. As a
/// RunObserver (run.hpp) it records at t = 0, at every metric sample and after the last step.
class AnimationRecorder : public RunObserver {
 public:
  /// Prepares the geometry of `scene` (validated by the caller, as makeSimulation does) for
  /// `method`; the parts are drawn as the simulation draws them (drawParts, same seed). Throws
  /// std::invalid_argument for a mesh shape without mesh_data.
  AnimationRecorder(const Scene& scene, Method method);

  /// Records the state of `sim` at sim.time() (s): every spawned part's pose and active flag,
  /// and the vibrating fixtures' displacement. Call it at t = 0 before the first step and then
  /// at every output sample (as a RunObserver of measureRun it does). A second call at the same time is ignored;
  /// a time earlier than the last one, a simulation of another method or with more parts than
  /// the scene draws throws std::invalid_argument naming the value.
  void record(const Simulation& sim);

  /// RunObserver: record() at the start, on the sample steps and at the end.
  void onStart(const Simulation& sim) override { record(sim); }
  void onStep(const Simulation& sim, long, bool sample) override {
    if (sample) record(sim);
  }
  void onEnd(const Simulation& sim) override { record(sim); }

  /// Writes the .glb to `path` atomically (temporary file and rename). Throws
  /// std::runtime_error naming the path on failure, std::logic_error when nothing was recorded.
  void write(const std::filesystem::path& path) const;

  /// Number of recorded samples, and the last recorded time (s): the animation's duration when
  /// the first sample is at t = 0.
  int samples() const { return static_cast<int>(times_.size()); }
  double duration() const { return times_.empty() ? 0.0 : times_.back(); }
  /// Node names of the fixtures and of the parts seen so far, in node order.
  std::vector<std::string> nodeNames() const;

 private:
  struct PartTrack {
    int first_sample = -1;                     // sample at which the part was first seen
    int removed_sample = -1;                   // first sample at which it was inactive, or -1
    std::vector<float> translation, rotation;  // from first_sample on: 3 and 4 per sample
  };
  Scene scene_;
  Method method_;
  std::vector<PartInstance> drawn_;
  std::vector<double> times_;
  std::vector<PartTrack> parts_;
  std::vector<std::vector<float>> fixture_translation_, fixture_rotation_;  // vibrating only
};

/// Writes `folder`/view.html, the three.js files it needs (copied from Debian's libjs-three:
/// the folder named by the environment variable RHEOFEED_THREE_DIR, else the folder found at
/// build time, else /usr/share/javascript/three) and `glb_name`.js, the .glb's bytes as a script
/// (a page opened from file:// may not fetch a file, it may load a script). The page plays the
/// animation with a time slider, play/pause and the time in s, and shows the images `plots`
/// (file names in `folder`, PNG or SVG). Everything is written atomically. Returns the path of
/// view.html. Throws std::runtime_error when the .glb or three.js cannot be read (naming the
/// paths tried and the package) or a file cannot be written.
std::filesystem::path writeViewer(const std::filesystem::path& folder, const std::string& glb_name,
                                  const std::vector<std::string>& plots);

}  // namespace rheofeed::scene
