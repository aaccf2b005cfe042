#pragma once
// `irbench train rest`: trains the tracker's rest-state SVM (thesis 6.4) from
// simulated truth — the exact joints and the truth's rest labels of library
// motions played on avatars — without rendering. The tracker reads only the
// model file it writes (architecture.md: learned parts come from *other*
// sequences' truth).

#include <filesystem>
#include <string>
#include <vector>

namespace irbench {

struct RestTrainingOptions {
  std::vector<std::string> avatars = {"p2", "p3", "p4", "p5"};  // p1 is the demo's person, kept out
  std::vector<std::string> motions = {"point_horizontal", "flap_both", "direct_traffic", "raise_overhead",
                                      "flap_one", "point_diagonal_both", "atom_tour", "story", "rest", "session_demo"};
  // Held out: motions played on avatars, none of them trained on, whose
  // samples the trained SVM is scored on (empty test_motions: none).
  std::vector<std::string> test_avatars = {"p1", "p6", "p7", "p8"};
  std::vector<std::string> test_motions;
  double sample_fps = 10.0;
  int folds = 5;
  uint64_t seed = 1;
  std::filesystem::path out;  // default: DefaultRestModelPath()
};

struct RestTrainingResult {
  std::filesystem::path model;
  int samples = 0;
  int at_rest = 0;
  double cv_accuracy = 0;
  int test_samples = 0;  // held-out arm samples (0: none asked for)
  int test_at_rest = 0;
  double test_accuracy = 0;  // the SVM's agreement with their truth labels
};

// Throws InputError on unknown avatars or motions, or a held-out avatar or
// motion that is also trained on.
RestTrainingResult RunRestTraining(const RestTrainingOptions& options);

}  // namespace irbench
