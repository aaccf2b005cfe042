// `irbench train rest`: train the tracker's rest-state SVM from simulated truth.
// `irbench train atoms`: learn the posture atoms from rendered sequences.
// `irbench train gestures`: the gesture HMMs; `irbench train motion-labels`:
// the motion-label CRF and LDCRF.

#include <iostream>
#include <memory>
#include <string>

#include "ci/train/atom_training.h"
#include "ci/train/gesture_training.h"
#include "ci/train/motion_label_training.h"
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
  if (r.test_samples > 0) {
    const size_t motions = train_rest.test_motions.size(), avatars = train_rest.test_avatars.size();
    std::cout << "held out: " << r.test_samples << " arm samples (" << r.test_at_rest << " at rest) of " << motions
              << (motions == 1 ? " motion" : " motions") << " on " << avatars << (avatars == 1 ? " avatar" : " avatars")
              << ", accuracy " << r.test_accuracy * 100 << "%\n";
  }
  return kExitOk;
}

// What `irbench train atoms`' flags bind to.
struct TrainAtomsArgs {
  AtomTrainingOptions job;
  std::vector<std::string> sequences, candidates;
  std::string out, weights = "non_negative", rule = "centroids", selection_table;
};

// Learns the atoms; prints the training and held-out accuracies and the model file.
int RunTrainAtoms(const CLI::App& cmd, TrainAtomsArgs& args) {
  RequireNotEmpty(cmd, "--out", args.out);
  AtomTrainingOptions& job = args.job;
  for (const std::string& s : args.sequences) job.sequences.emplace_back(s);
  for (const std::string& s : args.candidates) job.candidates.emplace_back(s);
  if (cmd.count("--selection-table")) RequireNotEmpty(cmd, "--selection-table", args.selection_table);
  job.selection_table = args.selection_table;
  job.out = args.out;
  job.weights = args.weights == "matching_pursuit" ? AtomWeights::kMatchingPursuit : AtomWeights::kNonNegative;
  job.rule = args.rule == "thresholds" ? PairRule::kThresholds : PairRule::kCentroids;
  const AtomTrainingResult r = RunAtomTraining(job);
  if (r.selection) {
    std::cout << "atoms selected among " << r.selection->candidates.size() << " candidate postures:";
    for (int i : r.selection->selected) {
      const auto& c = r.selection->candidates[i];
      std::cout << " " << c.name << " (A" << c.atom << ": " << c.about << ")";
    }
    std::cout << "\n";
  }
  std::cout << "posture atoms: " << r.frames << " frames, pairs right on " << r.training_accuracy * 100
            << "% of the training frames (by the weights alone)\n";
  for (const auto& [name, acc] : r.held_out) std::cout << "  " << name << " held out: " << acc * 100 << "%\n";
  std::cout << r.model.string() << "\n";
  return kExitOk;
}

// What `irbench train gestures`' flags bind to.
struct TrainGesturesArgs {
  GestureTrainingJob job;
  std::vector<std::string> train, test;
  std::string atoms, out, table, observation = "pair";
};

int RunTrainGestures(const CLI::App& cmd, TrainGesturesArgs& args) {
  RequireNotEmpty(cmd, "--out", args.out);
  GestureTrainingJob& job = args.job;
  for (const std::string& s : args.train) job.train.emplace_back(s);
  for (const std::string& s : args.test) job.test.emplace_back(s);
  job.posture_atoms = args.atoms;
  job.out = args.out;
  job.table = args.table;
  job.options.observation = *ParseGestureObservationKind(args.observation);
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

// What `irbench train motion-labels`' flags bind to.
struct TrainMotionArgs {
  MotionLabelTrainingJob job;
  std::vector<std::string> train, test, models = {"crf", "ldcrf"};
  std::string out, table, rest, decision = "balanced";
};

// Trains the models; prints the training summary, the tables with test
// sequences, and the model files.
int RunTrainMotionLabels(const CLI::App& cmd, TrainMotionArgs& args) {
  RequireNotEmpty(cmd, "--out", args.out);
  MotionLabelTrainingJob& job = args.job;
  for (const std::string& s : args.train) job.train.emplace_back(s);
  for (const std::string& s : args.test) job.test.emplace_back(s);
  job.kinds.clear();
  for (const std::string& m : args.models) job.kinds.push_back(m == "crf" ? MotionModelKind::kCrf : MotionModelKind::kLdcrf);
  job.out_dir = args.out;
  job.table = args.table;
  job.rest_model = args.rest;
  job.decision = args.decision == "balanced" ? MotionDecision::kBalanced : MotionDecision::kMaxMarginal;
  const MotionLabelTrainingResult r = RunMotionLabelTraining(job);
  std::cout << "motion labels: " << r.train_frames << " training arm-frames\n";
  for (const auto& [kind, report] : r.reports) {
    std::cout << kind << ": " << report.status_text << " after " << report.iterations << " L-BFGS iterations in "
              << r.train_seconds.at(kind) << " s\n";
  }
  if (!r.evaluation.confusion.empty()) {
    std::cout << r.evaluation.frames << " test arm-frames\n" << r.evaluation.Markdown();
  }
  for (const auto& path : r.models) std::cout << path.string() << "\n";
  return kExitOk;
}

Command AddTrainMotionLabels(CLI::App* train_cmd) {
  auto args = std::make_shared<TrainMotionArgs>();
  CLI::App* cmd = train_cmd->add_subcommand(
      "motion-labels",
      "Motion labels (thesis 7.1): CRF and LDCRF over the tracked arms' features, from rendered\n"
      "sequences with motion labels (story-telling, gesture sessions) as the tracker tracked them\n"
      "(SEQ/track when it holds a pose-stage track, else tracked here); with --test, Tables 7.1-7.2");
  cmd->add_option("--train", args->train, "rendered sequences to train on")->required()->check(CLI::ExistingDirectory);
  cmd->add_option("--test", args->test, "rendered sequences to score the models on")->check(CLI::ExistingDirectory);
  cmd->add_option("--models", args->models, "which models to train")
      ->capture_default_str()
      ->check(CLI::IsMember({"crf", "ldcrf"}));
  cmd->add_option("--window", args->job.window, "frames before and after in each frame's features")
      ->capture_default_str()
      ->transform(IntegerIn(0, 100));
  cmd->add_option("--ldcrf-states", args->job.ldcrf_states, "hidden states per label of the LDCRF")
      ->capture_default_str()
      ->transform(IntegerIn(1, 16));
  cmd->add_option("--sigma", args->job.options.sigma,
                  "regularisation: the Gaussian prior's sigma, |theta|^2 / (2 sigma^2); 0 for none")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  cmd->add_option("--iterations", args->job.options.max_iterations, "L-BFGS iterations at most")
      ->capture_default_str()
      ->transform(IntegerIn(1, 100000));
  cmd->add_option("--seed", args->job.options.seed, "seed of the LDCRF's starting weights")
      ->capture_default_str()
      ->transform(Uint64Text());
  cmd->add_option("--decision", args->decision,
                  "a frame's label: balanced (largest p(label | x) / training share: the rule for the mean\n"
                  "per-label recall) or max_marginal (largest p(label | x))")
      ->capture_default_str()
      ->check(CLI::IsMember({"balanced", "max_marginal"}));
  cmd->add_option("--prior-power", args->job.prior_power,
                  "balanced decision: divide by the training shares to this power, 0-1")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--retrack", args->job.retrack, "track every sequence here even when it has a track/");
  cmd->add_option("--rest-model", args->rest, "rest-state SVM for the margin feature (default: the shipped one)");
  cmd->add_option("--table", args->table, "also write the tables as Markdown to this file");
  cmd->add_option("--out", args->out, "folder of the model files (default: tracker/models)");
  return {cmd, [cmd, args] { return RunTrainMotionLabels(*cmd, *args); }};
}

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
  cmd->add_option("--test-motions", train_rest.test_motions,
                  "held-out motions the trained SVM is scored on (none trained on)");
  cmd->add_option("--test-avatars", train_rest.test_avatars, "avatars that play the held-out motions")
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
  atoms_cmd->add_option("--candidates", atom_args->candidates,
                        "renders of the 30 candidate postures (irbench render --motion posture_candidates),\n"
                        "one person each: the arm atoms are the candidates selected by the SVD of their\n"
                        "matching-pursuit weights (thesis 5.1.2) instead of the truth's atoms' frames")
      ->check(CLI::ExistingDirectory);
  atoms_cmd->add_option("--selection-table", atom_args->selection_table,
                        "with --candidates: write the selection, the singular values and the weight\n"
                        "matrix (Figs. 5.1, 5.2) as Markdown to this file");
  atoms_cmd->add_option("--weights", atom_args->weights, "how atom weights are found")
      ->capture_default_str()
      ->check(CLI::IsMember({"non_negative", "matching_pursuit"}));
  atoms_cmd->add_option("--rule", atom_args->rule, "how the pair follows from the weights")
      ->capture_default_str()
      ->check(CLI::IsMember({"centroids", "thresholds"}));
  atoms_cmd->add_flag("!--no-rest-state", atom_args->job.pair_rest_state,
                      "the tracker's pair from the atom weights alone; by default it agrees with the\n"
                      "pose tracker's rest state (as many A0s as arms it finds at rest)");
  atoms_cmd->add_flag("!--no-cross-validation", atom_args->job.cross_validate,
                      "skip the leave-one-sequence-out accuracies");
  atoms_cmd->add_option("--out", atom_args->out, "model file (default: tracker/models/posture_atoms.json)");
  auto gesture_args = std::make_shared<TrainGesturesArgs>();
  CLI::App* gestures_cmd = train_cmd->add_subcommand(
      "gestures",
      "Gesture models (thesis 5.2): HMM, PaHMM and FHMM per gesture over the posture decomposition,\n"
      "from rendered gesture sessions (irbench render --motion gesture_set) as the tracker tracked them\n"
      "(each session's track/ when made with the same posture atoms, else tracked here);\n"
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
  gestures_cmd->add_option("--observation", gesture_args->observation,
                           "what the HMM and FHMM observe: weights (the atom weights, the thesis's) or pair\n"
                           "(the recognised pair as weights, --pair-scale per arm on its atoms)")
      ->capture_default_str()
      ->check(CLI::IsMember({"weights", "pair"}));
  gestures_cmd->add_option("--pair-scale", gesture_args->job.options.pair_scale,
                           "with --observation pair: one arm's weight on its atom")
      ->capture_default_str()
      ->check(CLI::Range(1e-6, 100.0));
  gestures_cmd->add_flag("--retrack", gesture_args->job.retrack,
                         "track every session here even when its track/ was made with these posture atoms");
  gestures_cmd->add_option("--table", gesture_args->table, "also write the tables as Markdown to this file");
  gestures_cmd->add_option("--out", gesture_args->out, "model file (default: tracker/models/gesture_models.json)");
  return {{cmd, [cmd, args] { return RunTrainRest(*cmd, *args); }},
          {gestures_cmd, [gestures_cmd, gesture_args] { return RunTrainGestures(*gestures_cmd, *gesture_args); }},
          {atoms_cmd, [atoms_cmd, atom_args] { return RunTrainAtoms(*atoms_cmd, *atom_args); }},
          AddTrainMotionLabels(train_cmd)};
}

}  // namespace irbench::cli
