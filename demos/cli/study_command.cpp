// SPDX-License-Identifier: MIT
// `rheofeed study SCENE`.
#include <cstdio>
#include <exception>
#include <stdexcept>

#include "cli/commands.hpp"
#include "common/study.hpp"

namespace rheofeed::cli {

int studyCommand(const StudyArgs& args) {
  Plan plan;
  rheofeed::demo::StudyOptions options;
  try {
    plan = makePlan(args.scene, {"ode_rheonomic"});
    if (!plan.scene.hasVibration()) {
      throw std::invalid_argument("scene " + plan.file.string() +
                                  ": no vibrating feeder; the study compares a vibrating feeder "
                                  "with its rheonomic replacement");
    }
    options.out_dir = !args.out_given ? "out/" + plan.name + "_study" : args.out;
    options.seeds = args.seeds;
    options.quick = args.quick;
    prepareOutputFolder(options.out_dir, "--out");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rheofeed study: %s\n", e.what());
    return 2;
  }
  return runChecked("rheofeed study", [&] {
    const std::string md = rheofeed::demo::runStudy(plan.scene, options);
    std::printf("%s\nwrote %s/study.{csv,md,png}\n", md.c_str(), options.out_dir.c_str());
  });
}

}  // namespace rheofeed::cli
