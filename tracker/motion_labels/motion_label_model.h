#pragma once
// A trained motion-label model (thesis 7.1): the CRF or LDCRF, the labels it
// gives, the feature standardisation, and how it was made. File format
// `irbench.motion-labels/1` (JSON, docs/recognition.md); Load rejects a bad
// file with an InputError naming the file and field.

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tracker/motion_labels/latent_crf.h"
#include "tracker/motion_labels/motion_features.h"

namespace irbench {

enum class MotionModelKind { kCrf, kLdcrf };
const char* MotionModelKindName(MotionModelKind kind);  // "crf", "ldcrf"

// How a frame's label follows from its label marginals p(l | x): the most
// probable (kMaxMarginal), or the largest p(l | x) / p(l) with p(l) the
// training frames' label shares raised to `prior_power` (kBalanced; power
// 1 is the Bayes rule for the mean per-label recall, which the thesis's
// tables report: rare labels such as BACKWARD are not swamped by REST;
// lower powers trust the marginals more).
enum class MotionDecision { kMaxMarginal, kBalanced };

struct MotionLabelModel {
  MotionModelKind kind = MotionModelKind::kLdcrf;
  std::vector<std::string> labels;  // the label of each CRF label index (right arm's sense)
  Eigen::VectorXd feature_mean, feature_scale;  // kMotionFeatureCount each; scale > 0
  LatentCrf crf;
  MotionDecision decision = MotionDecision::kBalanced;
  Eigen::VectorXd label_prior;  // labels.size(): training shares, each > 0
  double prior_power = 1.0;     // 0..1
  nlohmann::json provenance = nlohmann::json::object();

  // T x kMotionFeatureCount standardised rows: (f - mean) / scale.
  Eigen::MatrixXd Standardize(const std::vector<MotionFeatures>& frames) const;

  // The label index a frame's label marginals (labels.size()) decide.
  int Decide(const Eigen::Ref<const Eigen::RowVectorXd>& marginals) const;

  static MotionLabelModel Load(const std::filesystem::path& path);
  void Save(const std::filesystem::path& path) const;  // atomic
};

// The shipped models: tracker/models/motion_crf.json, motion_ldcrf.json
// under the data root.
std::filesystem::path DefaultMotionLabelModelPath(MotionModelKind kind);

}  // namespace irbench
