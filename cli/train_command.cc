// `irbench train rest`: train the tracker's rest-state SVM from simulated truth.
// `irbench train atoms`: learn the posture atoms from rendered sequences.

#include <iostream>
#include <memory>
#include <string>

#include "ci/train/atom_training.h"
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

// What `irbench train atoms`' flags bind to.
struct TrainAtomsArgs {
  AtomTrainingOptions job;
  std::vector<std::string> sequences;
  std::string out, weights = "non_negative", rule = "centroids";
};

// Learns the atoms; prints the training and held-out accuracies and the model file.
int RunTrainAtoms(const CLI::App& cmd, TrainAtomsArgs& args) {
  RequireNotEmpty(cmd, "--out", args.out);
  AtomTrainingOptions& job = args.job;
  for (const std::string& s : args.sequences) job.sequences.emplace_back(s);
  job.out = args.out;
  job.weights = args.weights == "matching_pursuit" ? AtomWeights::kMatchingPursuit : AtomWeights::kNonNegative;
  job.rule = args.rule == "thresholds" ? PairRule::kThresholds : PairRule::kCentroids;
  const AtomTrainingResult r = RunAtomTraining(job);
  std::cout << "posture atoms: " << r.frames << " frames, pairs right on " << r.training_accuracy * 100
            << "% of the training frames\n";
  for (const auto& [name, acc] : r.held_out) std::cout << "  " << name << " held out: " << acc * 100 << "%\n";
  std::cout << r.model.string() << "\n";
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
  auto atom_args = std::make_shared<TrainAtomsArgs>();
  CLI::App* atoms_cmd = train_cmd->add_subcommand(
      "atoms",
      "Posture atoms (thesis 5.1): the resting posture and four arm atoms of the shape descriptor,\n"
      "and the rule from atom weights to the recognised pair, from rendered sequences of the atom\n"
      "tour (irbench render --motion atom_tour) on training persons, tracked by the front end");
  atoms_cmd->add_option("SEQ", atom_args->sequences, "rendered sequences with truth, one person each")
      ->required()
      ->check(CLI::ExistingDirectory);
  atoms_cmd->add_option("--weights", atom_args->weights, "how atom weights are found")
      ->capture_default_str()
      ->check(CLI::IsMember({"non_negative", "matching_pursuit"}));
  atoms_cmd->add_option("--rule", atom_args->rule, "how the pair follows from the weights")
      ->capture_default_str()
      ->check(CLI::IsMember({"centroids", "thresholds"}));
  atoms_cmd->add_flag("!--no-cross-validation", atom_args->job.cross_validate,
                      "skip the leave-one-sequence-out accuracies");
  atoms_cmd->add_option("--out", atom_args->out, "model file (default: tracker/models/posture_atoms.json)");
  return {{cmd, [cmd, args] { return RunTrainRest(*cmd, *args); }},
          {atoms_cmd, [atoms_cmd, atom_args] { return RunTrainAtoms(*atoms_cmd, *atom_args); }}};
}

}  // namespace irbench::cli
