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
};

// Throws InputError on unknown avatars or motions.
RestTrainingResult RunRestTraining(const RestTrainingOptions& options);

}  // namespace irbench
