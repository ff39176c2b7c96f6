// SPDX-License-Identifier: MIT
// Cost of the friction cone of the patched ODE (patches/0002, friction_model.hpp) against ODE's
// pyramid, measured with Google Benchmark on the pile of plugin_overhead_bench: 400 boxes on a
// ground that is a belt feeder (FeederSet drives every ground contact), dWorldQuickStep with 20
// sweeps, h = 0.005 s. Every contact (box-box and box-ground) gets the variant's model.
//
// Each repetition builds a fresh, identical pile, settles it untimed (100 steps) and times the
// same fixed number of steps; repetitions are randomly interleaved (pass
// --benchmark_enable_random_interleaving=true). The program ends with a table: the ratio of the
// medians of a step (cone / pyramid), and the extra cost per contact joint per step (ns) and
// per contact per sweep. Goal of issue 15: a step with the cone at most 1.10 x the pyramid.
//
//   friction_cone_bench [--boxes N] [google benchmark flags]
#include <benchmark/benchmark.h>
#include <ode/ode.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench/box_pile.hpp"
#include "rheofeed/feeder_set.hpp"

namespace {

using rheofeed::FeederSet;
using rheofeed::FrictionModel;
using rheofeed::MotionLaw;

constexpr double kStep = 0.005;    // s
constexpr int kSweeps = 20;        // quickstep iterations
constexpr int kSettleSteps = 100;  // untimed steps before timing: the pile is in contact
constexpr int kTimedSteps = 200;   // steps per repetition
constexpr int kRepetitions = 15;
int g_boxes = 400;

// The pile with the ground as a belt feeder, every contact with friction model `model`.
struct Pile {
  rheofeed::demo::BoxPile pile;
  FeederSet feeders;

  explicit Pile(FrictionModel model)
      : pile(g_boxes, withFrictionModel(dContactApprox1, model), kSweeps), feeders(options(model)) {
    feeders.add(pile.ground(), MotionLaw::belt({1, 0, 0}, 0.2));
    pile.setFeeders(&feeders);
    for (int i = 0; i < kSettleSteps; ++i) step();
    pile.resetJointCount();
  }
  static FeederSet::Options options(FrictionModel model) {
    FeederSet::Options o;
    o.friction = model;
    return o;
  }
  void step() { pile.step(kStep, kStep); }
};

std::map<int, double> g_joints_per_step;  // by model, from the last repetition

void BM_PileStep(benchmark::State& state) {
  const auto model = static_cast<FrictionModel>(state.range(0));
  Pile pile(model);
  for (auto _ : state) pile.step();
  state.counters["bodies"] = g_boxes;
  state.counters["joints_per_step"] = static_cast<double>(pile.pile.jointCount()) / kTimedSteps;
  g_joints_per_step[static_cast<int>(model)] =
      static_cast<double>(pile.pile.jointCount()) / kTimedSteps;
}
BENCHMARK(BM_PileStep)
    ->ArgName("cone")
    ->Arg(static_cast<int>(FrictionModel::Pyramid))
    ->Arg(static_cast<int>(FrictionModel::Cone))
    ->Iterations(kTimedSteps)
    ->Repetitions(kRepetitions)
    ->ReportAggregatesOnly(true)
    ->Unit(benchmark::kMicrosecond);

class MedianReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name == "median") {
        medians[r.run_name.function_name + "/" + r.run_name.args] = r.GetAdjustedCPUTime();
      }
    }
  }
  std::map<std::string, double> medians;  // in microseconds
};

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--boxes") == 0) {
      g_boxes = std::atoi(argv[i + 1]);
      if (g_boxes < 1 || g_boxes > 100000) {
        std::fprintf(stderr, "friction_cone_bench: --boxes %s must be in 1..100000\n", argv[i + 1]);
        return 2;
      }
      for (int k = i; k + 2 < argc + 1; ++k) argv[k] = argv[k + 2];
      argc -= 2;
      break;
    }
  }
  dInitODE2(0);
  if (!rheofeed::odeHasFrictionCone()) {
    std::fprintf(stderr,
                 "friction_cone_bench: the linked ODE has no friction cone (%s); build with "
                 "RHEOFEED_ODE=patched\n",
                 dGetConfiguration());
    dCloseODE();
    return 2;
  }
  benchmark::Initialize(&argc, argv);
  MedianReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();

  auto get = [&](const std::string& key) {
    auto it = reporter.medians.find(key);
    return it == reporter.medians.end() ? -1.0 : it->second;
  };
  const double pyramid = get("BM_PileStep/cone:0");
  const double cone = get("BM_PileStep/cone:1");
  std::printf(
      "\n## Friction cone cost (medians of %d repetitions x %d steps, %d boxes, %d "
      "sweeps)\n\n",
      kRepetitions, kTimedSteps, g_boxes, kSweeps);
  std::printf("| quantity | value |\n|---|---|\n");
  if (pyramid > 0) std::printf("| pile step, pyramid (us) | %.1f |\n", pyramid);
  if (cone > 0) std::printf("| pile step, cone (us) | %.1f |\n", cone);
  if (pyramid > 0 && cone > 0) {
    std::printf("| pile step, cone / pyramid | %.4f |\n", cone / pyramid);
    const double joints = g_joints_per_step[static_cast<int>(FrictionModel::Cone)];
    if (joints > 0) {
      std::printf("| contact joints per step (cone run) | %.0f |\n", joints);
      std::printf("| cone - pyramid per contact per step (ns) | %.1f |\n",
                  1e3 * (cone - pyramid) / joints);
      std::printf("| cone - pyramid per contact per sweep (ns) | %.2f |\n",
                  1e3 * (cone - pyramid) / joints / kSweeps);
    }
  }
  dCloseODE();
  return 0;
}
