// `irbench train rest`: train the tracker's rest-state SVM from simulated truth.

#include <iostream>
#include <memory>
#include <string>

#include "ci/train/rest_training.h"
#include "cli/commands.h"
#include "cli/option_checks.h"

namespace irbench::cli {
namespace {

// What `irbench train rest`'s flags bind to.
struct TrainRestArgs {
  RestTrainingOptions job;
  std::string out;
};

// Trains the rest-state SVM; prints its cross-validated accuracy and the model file.
int RunTrainRest(const CLI::App& cmd, TrainRestArgs& args) {
  RestTrainingOptions& train_rest = args.job;
  RequireNotEmpty(cmd, "--out", args.out);
  train_rest.out = args.out;
  const RestTrainingResult r = RunRestTraining(train_rest);
  std::cout << "rest-state SVM: " << r.samples << " arm samples (" << r.at_rest << " at rest), "
            << train_rest.folds << "-fold cross-validated accuracy " << r.cv_accuracy * 100 << "%\n"
            << r.model.string() << "\n";
  return kExitOk;
}

}  // namespace

std::vector<Command> AddTrainCommand(CLI::App& app) {
  CLI::App* train_cmd =
      app.add_subcommand("train", "Train the tracker's learned parts from simulated truth");
  train_cmd->require_subcommand(1);
  auto args = std::make_shared<TrainRestArgs>();
  RestTrainingOptions& train_rest = args->job;
  CLI::App* cmd = train_cmd->add_subcommand(
      "rest",
      "Rest-state SVM (thesis 6.4): RBF SVM on elbow and wrist in the upper-body frame, C and "
      "gamma\n"
      "by k-fold cross-validation, from library motions played on avatars (no rendering)");
  cmd->add_option("--avatars", train_rest.avatars, "avatars to sample")->capture_default_str();
  cmd->add_option("--motions", train_rest.motions, "library motions or motion files")
      ->capture_default_str();
  cmd->add_option("--fps", train_rest.sample_fps, "samples per second of motion")
      ->capture_default_str();
  cmd->add_option("--folds", train_rest.folds, "cross-validation folds")
      ->capture_default_str()
      ->transform(IntegerIn(2, 100));
  cmd->add_option("--seed", train_rest.seed, "seed of the motions' styles")
      ->capture_default_str()
      ->transform(Uint64Text());
  cmd->add_option("--out", args->out, "model file (default: tracker/models/rest_svm.yml)");
  return {{cmd, [cmd, args] { return RunTrainRest(*cmd, *args); }}};
}

}  // namespace irbench::cli
