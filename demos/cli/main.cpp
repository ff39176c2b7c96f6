// SPDX-License-Identifier: MIT
// `rheofeed`: the feeder engineer's command. Subcommands
//   rheofeed run SCENE        run a scene (methods, step, duration, seed, output folder),
//                             write CSV/JSON/plots and an animation (run.glb + view.html)
//   rheofeed calibrate SCENE  calibrate the vibrating feeders, write the scene with the result
//   rheofeed check SCENE      validate the scene and print the hazards of the scene check
//   rheofeed study SCENE      the error-vs-cost study (rheonomic vs full vibration)
//   rheofeed sweep SPEC       a design sweep (sweep.hpp): its jobs on this machine's cores, with
//                             GNU parallel or on Slurm; `sweep collect DIR` gathers the results
// SCENE is the name of a shipped scene (demos/scenes, installed in share/rheofeed/scenes; see
// shipped_scenes.hpp) or a scene file. Exit codes: 0 success, 1 a failure while running (check:
// the scene has hazards), 2 bad input (command line or scene; nothing has run), 3 (run) a run
// gave no answer: it measured no part and none crossed the exit, or it lost more than
// --max-lost-fraction of its parts (kNoAnswerExitCode; a sweep records such a job as
// "no_answer").
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "cli/commands.hpp"
#include "cli/shipped_scenes.hpp"
#include "rheofeed/version.hpp"

namespace {

using namespace rheofeed::cli;

std::string shippedList() {
  std::string names;
  for (const std::string& n : shippedSceneNames()) names += (names.empty() ? "" : ", ") + n;
  return names.empty() ? std::string("none found") : names;
}

// The options every subcommand that loads a scene takes.
void addSceneArgs(CLI::App* sub, SceneArgs& a, bool with_methods, bool with_overrides,
                  bool with_drift_model) {
  sub->add_option("SCENE", a.scene,
                  "a shipped scene (" + shippedList() +
                      ") or a scene file (a path with a '/' or ending in .json)")
      ->required();
  if (with_drift_model) {
    sub->add_option("--drift-model", a.drift_model,
                    "what the rheonomic runs use instead of a feeder's vibration, for every "
                    "vibrating feeder: local (the local vibration law, no calibration), "
                    "local_sampled (the local law times each part family's efficiency, measured "
                    "by a short sampling run unless the scene gives it), calibrated_drift (one "
                    "constant drift twist, calibrated unless the scene gives it)")
        ->default_str("each feeder's drift_model in the scene");
  }
  if (with_methods) {
    sub->add_option("--method", a.methods, "methods, repeated or comma-separated: " + methodNames())
        ->delimiter(',');
  }
  if (!with_overrides) return;
  sub->add_option("--dt", a.dt,
                  "time step (s) of EVERY run (rheonomic and full-vibration alike); without it "
                  "a rheonomic run takes the scene's solver.rheonomic_time_step (or its "
                  "solver.time_step when it gives none) and a full-vibration run the scene's "
                  "solver.time_step. Finite, in [1e-6, 1] s")
      ->default_str("scene's step")
      ->each([&a](const std::string&) { a.dt_given = true; });
  sub->add_option("--duration", a.duration, "simulated time (s), finite, > 0")
      ->default_str("scene's duration")
      ->each([&a](const std::string&) { a.duration_given = true; });
  sub->add_option("--warmup", a.warmup,
                  "time (s) excluded from the mean drift at the start of the run, finite, >= 0 and "
                  "below the duration (give it with a short --duration)")
      ->default_str("scene's outputs.warmup")
      ->each([&a](const std::string&) { a.warmup_given = true; });
  sub->add_option("--seed", a.seed,
                  "random seed of the part sizes, positions and orientations (an integer >= 0)")
      ->default_str("scene's seed")
      ->check(CLI::Validator(
          [](std::string& v) {
            return v.find_first_not_of("0123456789") == std::string::npos && !v.empty()
                       ? std::string()
                       : "--seed " + v + ": must be an integer >= 0 (decimal digits only)";
          },
          ""))
      ->each([&a](const std::string&) { a.seed_given = true; });
}

// The whole of `text` as a number; nan when it is not one (trailing characters included).
double wholeNumber(const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    return used == text.size() ? v : std::nan("");
  } catch (const std::exception&) {
    return std::nan("");
  }
}

// CLI11 check: a finite number of vibration cycles, >= 0 (or > 0 when `positive`).
CLI::Validator cyclesCheck(const char* option, bool positive) {
  return CLI::Validator(
      [positive](std::string& text) {
        const double v = wholeNumber(text);
        if (std::isfinite(v) && (positive ? v > 0 : v >= 0) && v <= 1e6) return std::string();
        return "got " + text + ": must be a finite number of vibration cycles " +
               (positive ? "> 0" : ">= 0") + " and at most 1e6";
      },
      "", option);
}

// CLI11 check of --max-lost-fraction: a number in [0, 1] (nan refused).
CLI::Validator fractionCheck() {
  return CLI::Validator(
      [](std::string& text) {
        const double v = wholeNumber(text);
        if (v >= 0 && v <= 1) return std::string();
        return "got " + text +
               ": must be a number in [0, 1] (the share of the parts it spawned a run may lose "
               "and still have an answer)";
      },
      "", "--max-lost-fraction");
}

void addCalibrateOptions(CLI::App* sub, CalibrateOptions& c) {
  sub->add_flag("--classical", c.classical,
                "calibrate with the classical single-part model (milliseconds, a straight-track "
                "estimate) instead of a short full-vibration sample run")
      ->default_str("off");
  sub->add_option("--warmup-cycles", c.warmup_cycles,
                  "vibration cycles the sampling run lets pass before it measures (0 to 1e6); "
                  "a phase the parts reach later, such as a bowl's ramp, needs more")
      ->check(cyclesCheck("--warmup-cycles", false))
      ->default_val(c.warmup_cycles);
  sub->add_option("--measure-cycles", c.measure_cycles,
                  "vibration cycles the sampling run measures (> 0, at most 1e6)")
      ->check(cyclesCheck("--measure-cycles", true))
      ->default_val(c.measure_cycles);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "rheofeed: vibratory feeders, belts and turntables at large time steps (ODE + "
      "rheonomic contacts)"};
  app.set_version_flag("--version", std::string("rheofeed ") + rheofeed::kVersion);
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 success; 1 a failure while running (check: hazards found); 2 bad input "
      "(command line or scene), nothing has run; 3 (run) a run gave no answer: it measured no "
      "part and none crossed the exit (every part lost, say), or it lost more than "
      "--max-lost-fraction of its parts; its outputs written.\nShipped "
      "scenes (" +
      (dataDir() / "scenes").string() + "): " + shippedList());

  RunArgs run;
  CLI::App* run_cmd = app.add_subcommand("run", "run a scene and write its outputs");
  addSceneArgs(run_cmd, run.scene, true, true, true);
  run_cmd->get_option("--method")->default_str("ode_rheonomic");
  run_cmd->add_option("--out", run.out, "output folder")
      ->default_str("out/<scene name>")
      ->each([&run](const std::string&) { run.out_given = true; });
  bool no_animation = false;
  run_cmd
      ->add_flag("--no-animation", no_animation,
                 "do not write the animation; by default the first method's run is written as "
                 "<method>.glb (glTF 2.0, opens in Blender) and view.html, which plays it in a "
                 "browser beside the plots")
      ->default_str("off");
  run_cmd
      ->add_option(
          "--drift-table", run.drift_table,
          "the local vibration law's table of point-mass results (JSON): read before the runs when "
          "FILE exists, written back after them with what they added, so that later runs of the "
          "scene skip those model runs (same drifts, bit for bit)")
      ->each([&run](const std::string&) { run.drift_table_given = true; });
  run_cmd
      ->add_option("--max-lost-fraction", run.max_lost_fraction,
                   "a run that loses more than this share of the parts it spawned (through a "
                   "fixture, off the feeder, blown up...) has no answer: its outputs are written, "
                   "stderr and the JSON's \"answer\" say why, and the exit code is 3. In [0, 1]; "
                   "1 accepts any loss")
      ->check(fractionCheck())
      ->default_val(run.max_lost_fraction);
  addCalibrateOptions(run_cmd, run.calibrate);

  CalibrateArgs cal;
  CLI::App* cal_cmd = app.add_subcommand(
      "calibrate",
      "calibrate the drift of the scene's vibrating feeders and write the scene with it, so "
      "that later runs start at once");
  addSceneArgs(cal_cmd, cal.scene, false, false, true);
  cal_cmd->add_option("--out", cal.out, "the new scene file (.json)")->required();
  addCalibrateOptions(cal_cmd, cal.calibrate);
  cal_cmd
      ->add_flag("--force", cal.calibrate.force,
                 "calibrate also the feeders whose drift the scene already gives")
      ->default_str("off");

  SceneArgs check;
  CLI::App* check_cmd = app.add_subcommand(
      "check",
      "validate a scene and print the hazards of the scene check for each method at the step it "
      "takes (exit code 0: none, 1: hazards, 2: invalid)");
  addSceneArgs(check_cmd, check, true, true, true);
  check_cmd->get_option("--method")
      ->default_str("ode_rheonomic, and ode_full_vibration when a feeder vibrates");

  StudyArgs study;
  CLI::App* study_cmd = app.add_subcommand(
      "study", "the error-vs-cost study: rheonomic vs full vibration over a sweep of steps");
  addSceneArgs(study_cmd, study.scene, false, false, false);
  study_cmd->add_option("--out", study.out, "output folder")
      ->default_str("out/<scene name>_study")
      ->each([&study](const std::string&) { study.out_given = true; });
  study_cmd->add_option("--seeds", study.seeds, "seeds of the converged reference")
      ->check(CLI::Range(1, 50))
      ->capture_default_str();
  study_cmd->add_flag("--quick", study.quick, "coarser sweeps and a shorter reference")
      ->default_str("off");

  SweepArgs sweep;
  SweepJobArgs sweep_job;
  std::string collect_dir;
  CLI::App* sweep_cmd = app.add_subcommand(
      "sweep",
      "a design sweep over a scene (spec format: demos/sweeps/README.md): one `rheofeed run` per "
      "point and seed, on this machine's cores (local), with GNU parallel (parallel) or as a "
      "Slurm job array (slurm), then `sweep collect`");
  sweep_cmd->add_option("SPEC", sweep.spec, "the sweep spec (.json)");
  sweep_cmd->add_option("--backend", sweep.backend, "local, parallel or slurm")
      ->capture_default_str();
  sweep_cmd->add_option("--jobs", sweep.jobs, "jobs at a time (local, parallel), 1 to 1024")
      ->default_str("the available cores")
      ->check(CLI::Range(1, 1024));
  sweep_cmd
      ->add_option("--out", sweep.out,
                   "the sweep folder (a folder of an earlier run of "
                   "the same spec is resumed)")
      ->default_str("out/<spec name>")
      ->each([&sweep](const std::string&) { sweep.out_given = true; });
  sweep_cmd
      ->add_option("--sshlogin", sweep.sshlogin,
                   "parallel: GNU parallel's --sshlogin (e.g. 8/node1,8/node2,: for two "
                   "hosts and this one; DIR and rheofeed at the same paths on every host)")
      ->default_str("this machine only");
  sweep_cmd
      ->add_option("--jobs-per-task", sweep.jobs_per_task,
                   "slurm: jobs run one after the other by one array task (batch short jobs)")
      ->default_str("the spec's slurm.jobs_per_task, else 1")
      ->check(CLI::Range(1, 100000));
  sweep_cmd->add_flag("--submit", sweep.submit, "slurm: submit the scripts with sbatch")
      ->default_str("off: write them");
  sweep_cmd->add_flag("--check", sweep.check, "check the spec and list the jobs; write nothing")
      ->default_str("off");
  CLI::App* job_cmd = sweep_cmd->add_subcommand(
      "job",
      "run jobs of a sweep folder (what every backend runs; a finished job is not run "
      "again)");
  job_cmd->add_option("DIR", sweep_job.dir, "the sweep folder")->required();
  job_cmd->add_option("ID", sweep_job.ids, "job ids (e.g. 0007)");
  job_cmd->add_option("--tasks", sweep_job.tasks, "a Slurm task file (one line of ids per task)");
  job_cmd->add_option("--task", sweep_job.task, "the line of --tasks to run (0-based)");
  CLI::App* collect_cmd = sweep_cmd->add_subcommand(
      "collect",
      "write DIR/results: sweep.csv (means and 95 % intervals over the seeds), "
      "jobs.csv, plots; list the unfinished jobs");
  collect_cmd->add_option("DIR", collect_dir, "the sweep folder")->required();

  try {
    app.parse(argc, argv);
    if (sweep_cmd->parsed() && !job_cmd->parsed() && !collect_cmd->parsed() && sweep.spec.empty()) {
      throw CLI::RequiredError("SPEC (or a subcommand: job, collect)");
    }
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;  // --help and --version: 0; any bad command line: 2
  }
  run.animation = !no_animation;
  if (run_cmd->parsed()) {
    run.cycles_given = run_cmd->count("--warmup-cycles") + run_cmd->count("--measure-cycles") > 0;
    return runCommand(run);
  }
  if (cal_cmd->parsed()) {
    cal.cycles_given = cal_cmd->count("--warmup-cycles") + cal_cmd->count("--measure-cycles") > 0;
    return calibrateCommand(cal);
  }
  if (check_cmd->parsed()) return checkCommand(check);
  if (study_cmd->parsed()) return studyCommand(study);
  if (job_cmd->parsed()) return sweepJobCommand(sweep_job);
  if (collect_cmd->parsed()) return sweepCollectCommand(collect_dir);
  if (sweep_cmd->parsed()) return sweepCommand(sweep);
  return 2;
}
