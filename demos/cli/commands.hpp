// SPDX-License-Identifier: MIT
// The subcommands of `rheofeed` (main.cpp parses the command line). Each returns the process exit
// code: 0 success, 2 bad input (a message on stderr naming the value, where it came from and the
// allowed range; nothing has run), 1 a failure while running (e.g. an output that cannot be
// written); `check` returns 1 when the scene has hazards; `run` returns kNoAnswerExitCode when a
// run gave no answer (runAnswer: no part measured, or more than --max-lost-fraction lost).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "cli/run_plan.hpp"
#include "rheofeed/measure/calibration.hpp"
#include "rheofeed/measure/metrics.hpp"

namespace rheofeed::cli {

using rheofeed::scene::CalibrateOptions;

/// `rheofeed run SCENE`: runs every method, writes <method>.csv/.json/.png, methods.png,
/// mean_height.png and, with `animation`, <first method>.glb and view.html into `out`. Prints a
/// table on stdout; its last line names view.html when it was written.
struct RunArgs {
  SceneArgs scene;
  std::string out;  ///< output folder (out_given); else out/<scene name>
  bool out_given = false;
  bool animation = true;
  CalibrateOptions calibrate;
  /// --drift-table FILE: the local law's drift table (rheofeed/scene/drift_table_file.hpp), read
  /// before the runs when the file exists and written back, with the corners the runs added,
  /// after them; empty: none.
  std::string drift_table;
  bool drift_table_given = false;
  /// --warmup-cycles or --measure-cycles given (noteIgnoredCycleOptions).
  bool cycles_given = false;
  /// --max-lost-fraction: a run that loses more than this share of the parts it spawned has no
  /// answer (RunMetrics::max_lost_fraction, runAnswer); in [0, 1] (main.cpp checks it).
  double max_lost_fraction = rheofeed::scene::kDefaultMaxLostFraction;
};
int runCommand(const RunArgs& args);
/// `rheofeed run`'s exit code when every run finished and its outputs are written but a run
/// has no answer (runAnswer, metrics.hpp): it measured no part and saw none cross the exit
/// (every part lost, spawned beyond the exit plane, or none spawned), or it lost more than
/// --max-lost-fraction of the parts it spawned. stderr says why, and so does each run JSON's
/// "answer". Sweep jobs record such a point as done, with status "no_answer" and its health
/// (sweep_job.cpp); it is not run again and collect leaves it out of the means.
inline constexpr int kNoAnswerExitCode = 3;

/// Says on stderr ("<program>: note: ... ignored: <why>") that --warmup-cycles / --measure-cycles
/// were given but no sampling run took them: nothing calibrated, or --classical.
void noteIgnoredCycleOptions(const char* program, bool cycles_given, bool calibrated,
                             bool classical);

/// Why the calibration of `fixture` (uncheckedCalibration, scene.hpp) cannot be checked
/// against the scene, with the command that records it; said by `run` and `check` for `scene`.
std::string uncheckedCalibrationNote(const scene::Fixture& fixture, const std::string& scene);
/// Why the calibration of `fixture` (missingDigests, scene.hpp) is checked against
/// the feeder but not against the parts or fixtures, with the command that records them.
std::string partlyCheckedCalibrationNote(const scene::Fixture& fixture, const std::string& scene);

/// `rheofeed check SCENE`: loads and validates the scene, then prints the hazards of the scene
/// check (check.hpp) for each method at the step it would take. Exit code 0 when there is no
/// hazard, 1 when there is one (printed on stdout), 2 when the scene or the command line is
/// invalid.
int checkCommand(const SceneArgs& args);

/// `rheofeed calibrate SCENE --out NEW.json`: calibrates the vibrating fixtures and writes the
/// scene with their calibrated drift (scene_io toJson) to `out`, mesh paths relative to its
/// folder, so that later runs of NEW.json start at once.
struct CalibrateArgs {
  SceneArgs scene;
  std::string out;
  CalibrateOptions calibrate;
  /// --warmup-cycles or --measure-cycles given: said to be ignored when no sampling run takes
  /// them (--classical, or every calibration given by the scene without --force).
  bool cycles_given = false;
};
int calibrateCommand(const CalibrateArgs& args);

/// `rheofeed study SCENE`: the error-vs-cost study (demos/common/study.hpp) of the scene.
struct StudyArgs {
  SceneArgs scene;
  std::string out;  ///< output folder (out_given); else out/<scene name>_study
  bool out_given = false;
  int seeds = 3;
  bool quick = false;
};
int studyCommand(const StudyArgs& args);

/// `rheofeed sweep SPEC`: checks the sweep spec, writes the sweep folder and runs its unfinished
/// jobs with a backend (local, parallel) or writes (and with `submit` submits) the Slurm scripts;
/// then collects (sweep.hpp). Exit code 0 when every job has finished (a job whose run has no
/// answer has: status no_answer, listed by collect on stderr), 1 when some failed, 2 for a bad
/// spec or command line (nothing run), 130 when interrupted.
struct SweepArgs {
  std::string spec;
  std::string backend = "local";  ///< local, parallel or slurm
  int jobs = 0;                   ///< jobs at a time (local, parallel); 0: the available cores
  std::string out;                ///< sweep folder (out_given); else out/<spec name>
  bool out_given = false;
  std::string sshlogin;   ///< parallel: GNU parallel's --sshlogin
  int jobs_per_task = 0;  ///< slurm: jobs per array task; 0: the spec's (default 1)
  bool submit = false;    ///< slurm: submit with sbatch
  bool check = false;     ///< check the spec and list the jobs, write nothing
};
int sweepCommand(const SweepArgs& args);

/// `rheofeed sweep job DIR ID...` (or `--tasks FILE --task K`, a Slurm array task): runs jobs of
/// a sweep folder, each unless it has finished. Exit code 0, 1 when a job failed, 2 for bad
/// input, 130/143 when interrupted.
struct SweepJobArgs {
  std::string dir;
  std::vector<std::string> ids;
  std::string tasks;
  int task = -1;
};
int sweepJobCommand(const SweepJobArgs& args);

/// `rheofeed sweep collect DIR`: the CSV and plots of a sweep folder (exit code 1 when jobs are
/// unfinished, after writing what there is).
int sweepCollectCommand(const std::string& dir);

/// Runs the part of `command` ("rheofeed run", ...) that comes after its input was checked and
/// returns the exit code: 0, or with a message on stderr 2 for a std::invalid_argument (bad input
/// found while running) and 1 for any other exception.
int runChecked(const char* command, const std::function<void()>& body);

}  // namespace rheofeed::cli
