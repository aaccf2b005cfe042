#pragma once
// Rest state (thesis 6.4): is an arm hanging at rest? An RBF support vector
// machine on the elbow and wrist positions in the upper-body frame, trained
// from simulated truth with 5-fold cross-validation (`irbench train rest`);
// the left arm is mirrored onto the right so one classifier serves both.
// The tracker forces an arm at rest down (thesis: "an arm at rest is forced
// down") and gives it no pointing ray.

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <memory>
#include <vector>

namespace irbench {

// The six features of one arm: elbow and wrist relative to the shoulder, in
// the upper-body frame (z from the waist to the neck, x towards the right
// shoulder, y forward), divided by the body height; for the left arm x is
// negated. All positions world metres.
std::array<float, 6> RestFeatures(const Eigen::Vector3d& waist, const Eigen::Vector3d& neck,
                                  const Eigen::Vector3d& right_shoulder, const Eigen::Vector3d& left_shoulder,
                                  const Eigen::Vector3d& elbow, const Eigen::Vector3d& wrist, double height_m,
                                  bool left_arm);

class RestClassifier {
 public:
  RestClassifier();
  ~RestClassifier();
  RestClassifier(RestClassifier&&) noexcept;
  RestClassifier& operator=(RestClassifier&&) noexcept;

  // Trains an RBF SVM, C and gamma chosen by `folds`-fold cross-validation
  // over OpenCV's grids (cv::ml::SVM::trainAuto). Returns the classifier;
  // `cv_accuracy` gets the accuracy of a separate k-fold pass with the chosen
  // parameters. Throws std::invalid_argument on empty or one-class data.
  static RestClassifier Train(const std::vector<std::array<float, 6>>& features, const std::vector<int>& at_rest,
                              int folds, double* cv_accuracy);
  // OpenCV FileStorage (YAML). Load throws InputError naming the file.
  static RestClassifier Load(const std::filesystem::path& path);
  void Save(const std::filesystem::path& path) const;  // atomic

  bool AtRest(const std::array<float, 6>& features) const;
  // The SVM's decision value: positive at rest, negative not, its size the
  // distance from the boundary in the kernel's units (thesis 7.1.3 uses it
  // as a motion-label feature); 0 when empty.
  double Margin(const std::array<float, 6>& features) const;
  bool empty() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Where the tracker finds the classifier by default: tracker/models/rest_svm.yml
// under the data root.
std::filesystem::path DefaultRestModelPath();

}  // namespace irbench
