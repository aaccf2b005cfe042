// `irbench train rest`: train the tracker's rest-state SVM from simulated truth.
// `irbench train atoms`: learn the posture atoms from rendered sequences.

#include <iostream>
#include <memory>
#include <string>

#include "ci/train/atom_training.h"
#include "ci/train/gesture_training.h"
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

// What `irbench train gestures`' flags bind to.
struct TrainGesturesArgs {
  GestureTrainingJob job;
  std::vector<std::string> train, test;
  std::string atoms, out, table;
};

int RunTrainGestures(const CLI::App& cmd, TrainGesturesArgs& args) {
  RequireNotEmpty(cmd, "--out", args.out);
  GestureTrainingJob& job = args.job;
  for (const std::string& s : args.train) job.train.emplace_back(s);
  for (const std::string& s : args.test) job.test.emplace_back(s);
  job.posture_atoms = args.atoms;
  job.out = args.out;
  job.table = args.table;
  const GestureTrainingResult r = RunGestureTraining(job);
  std::cout << "gesture models: " << r.segments << " training segments\n";
  if (!r.evaluation.counts.empty()) {
    std::cout << r.evaluation.Markdown();
    for (const char* kind : {"hmm", "pahmm", "fhmm"}) {
      std::cout << kind << ": mean identification rate " << 100 * r.evaluation.MeanRate(kind) << "%\n";
    }
  }
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
  auto gesture_args = std::make_shared<TrainGesturesArgs>();
  CLI::App* gestures_cmd = train_cmd->add_subcommand(
      "gestures",
      "Gesture models (thesis 5.2): HMM, PaHMM and FHMM per gesture over the posture decomposition,\n"
      "from rendered gesture sessions (irbench render --motion gesture_set) tracked by the tracker;\n"
      "with --test or --leave-one-out, the identification rates of Table 5.2");
  gestures_cmd->add_option("--train", gesture_args->train, "rendered gesture sessions to train on")
      ->required()
      ->check(CLI::ExistingDirectory);
  gestures_cmd->add_option("--test", gesture_args->test, "rendered gesture sessions to score the models on")
      ->check(CLI::ExistingDirectory);
  gestures_cmd->add_flag("--leave-one-out", gesture_args->job.leave_one_out,
                         "score each --train session with models trained on the others");
  gestures_cmd->add_option("--posture-atoms", gesture_args->atoms,
                           "posture atoms (default: tracker/models/posture_atoms.json)");
  gestures_cmd->add_option("--restarts", gesture_args->job.options.restarts, "EM starts per model")
      ->capture_default_str()
      ->transform(IntegerIn(1, 100));
  gestures_cmd->add_option("--seed", gesture_args->job.options.seed, "seed of the EM starts")
      ->capture_default_str()
      ->transform(Uint64Text());
  gestures_cmd->add_option("--table", gesture_args->table, "also write the tables as Markdown to this file");
  gestures_cmd->add_option("--out", gesture_args->out, "model file (default: tracker/models/gesture_models.json)");
  return {{cmd, [cmd, args] { return RunTrainRest(*cmd, *args); }},
          {gestures_cmd, [gestures_cmd, gesture_args] { return RunTrainGestures(*gestures_cmd, *gesture_args); }},
          {atoms_cmd, [atoms_cmd, atom_args] { return RunTrainAtoms(*atoms_cmd, *atom_args); }}};
}

}  // namespace irbench::cli
