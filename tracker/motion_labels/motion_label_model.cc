#include "tracker/motion_labels/motion_label_model.h"

#include <cmath>
#include <string>

#include "common/atomic_file.h"
#include "common/json_reader.h"
#include "common/paths.h"

namespace irbench {
namespace {

constexpr const char* kFormat = "irbench.motion-labels/1";

Eigen::VectorXd PositiveVectorFrom(const JsonNode& node, int size) {
  const Eigen::VectorXd v = node.FiniteVector(size);
  if (!(v.array() > 0).all()) node.Fail("values must be > 0");
  return v;
}

nlohmann::json Rows(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json r = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) r.push_back(m(i, j));
    rows.push_back(r);
  }
  return rows;
}

}  // namespace

const char* MotionModelKindName(MotionModelKind kind) { return kind == MotionModelKind::kCrf ? "crf" : "ldcrf"; }

Eigen::MatrixXd MotionLabelModel::Standardize(const std::vector<MotionFeatures>& frames) const {
  Eigen::MatrixXd x(static_cast<Eigen::Index>(frames.size()), kMotionFeatureCount);
  for (size_t t = 0; t < frames.size(); ++t) {
    x.row(static_cast<Eigen::Index>(t)) = ((frames[t] - feature_mean).array() / feature_scale.array()).transpose();
  }
  return x;
}

int MotionLabelModel::Decide(const Eigen::Ref<const Eigen::RowVectorXd>& marginals) const {
  int best = 0;
  if (decision == MotionDecision::kBalanced) {
    (marginals.array() / label_prior.transpose().array().pow(prior_power)).maxCoeff(&best);
  } else {
    marginals.maxCoeff(&best);
  }
  return best;
}

MotionLabelModel MotionLabelModel::Load(const std::filesystem::path& path) {
  const JsonNode root = ParseJsonFile(path.string());
  root.CheckKeys({"format", "kind", "labels", "features", "states_per_label", "window", "feature_mean",
                  "feature_scale", "decision", "label_prior", "prior_power", "state_weights", "transition", "provenance"});
  if (root.GetString("format") != kFormat) {
    root["format"].Fail("must be " + std::string(kFormat) + " (got " + root.GetString("format") + ")");
  }
  MotionLabelModel m;
  const std::string kind = root.GetString("kind");
  if (kind == "crf") {
    m.kind = MotionModelKind::kCrf;
  } else if (kind == "ldcrf") {
    m.kind = MotionModelKind::kLdcrf;
  } else {
    root["kind"].Fail("must be crf or ldcrf (got " + kind + ")");
  }
  for (size_t i = 0; i < root["labels"].Size(); ++i) m.labels.push_back(root["labels"][i].String());
  if (m.labels.size() < 2) root["labels"].Fail("needs at least two labels");
  const JsonNode features = root["features"];
  if (features.Size() != MotionFeatureNames().size()) {
    features.Fail("must name the " + std::to_string(kMotionFeatureCount) + " features of this tracker");
  }
  for (size_t i = 0; i < features.Size(); ++i) {
    if (features[i].String() != MotionFeatureNames()[i]) features[i].Fail("must be " + MotionFeatureNames()[i]);
  }
  const int k = root.GetInt("states_per_label"), window = root.GetInt("window");
  if (k < 1 || k > 16) root["states_per_label"].Fail("must be 1 to 16");
  if (m.kind == MotionModelKind::kCrf && k != 1) root["states_per_label"].Fail("must be 1 for a crf");
  if (window < 0 || window > 100) root["window"].Fail("must be 0 to 100");
  m.crf = LatentCrf(static_cast<int>(m.labels.size()), k, kMotionFeatureCount, window);
  m.feature_mean = root["feature_mean"].FiniteVector(kMotionFeatureCount);
  m.feature_scale = PositiveVectorFrom(root["feature_scale"], kMotionFeatureCount);
  const std::string decision = root.GetString("decision");
  if (decision == "balanced") {
    m.decision = MotionDecision::kBalanced;
  } else if (decision == "max_marginal") {
    m.decision = MotionDecision::kMaxMarginal;
  } else {
    root["decision"].Fail("must be balanced or max_marginal (got " + decision + ")");
  }
  m.label_prior = PositiveVectorFrom(root["label_prior"], static_cast<int>(m.labels.size()));
  m.prior_power = root.GetDouble("prior_power");
  if (!(m.prior_power >= 0 && m.prior_power <= 1)) root["prior_power"].Fail("must be in 0..1");
  m.crf.state_weights() = root["state_weights"].FiniteMatrix(m.crf.states(), m.crf.window_dims());
  m.crf.transition() = root["transition"].FiniteMatrix(m.crf.states(), m.crf.states());
  if (!root["provenance"].raw().is_object()) root["provenance"].Fail("must be an object");
  m.provenance = root["provenance"].raw();
  return m;
}

void MotionLabelModel::Save(const std::filesystem::path& path) const {
  nlohmann::json j;
  j["format"] = kFormat;
  j["kind"] = MotionModelKindName(kind);
  j["labels"] = labels;
  j["features"] = MotionFeatureNames();
  j["states_per_label"] = crf.states_per_label();
  j["window"] = crf.window();
  j["feature_mean"] = std::vector<double>(feature_mean.data(), feature_mean.data() + feature_mean.size());
  j["feature_scale"] = std::vector<double>(feature_scale.data(), feature_scale.data() + feature_scale.size());
  j["decision"] = decision == MotionDecision::kBalanced ? "balanced" : "max_marginal";
  j["label_prior"] = std::vector<double>(label_prior.data(), label_prior.data() + label_prior.size());
  j["prior_power"] = prior_power;
  j["state_weights"] = Rows(crf.state_weights());
  j["transition"] = Rows(crf.transition());
  j["provenance"] = provenance;
  // One key per line, the matrices one row per line: diffable, not huge.
  std::string text = "{";
  for (auto it = j.begin(); it != j.end(); ++it) {
    text += (it == j.begin() ? "\n " : ",\n ") + nlohmann::json(it.key()).dump() + ": ";
    if ((it.key() == "state_weights" || it.key() == "transition") && !it.value().empty()) {
      std::string rows = "[";
      for (size_t r = 0; r < it.value().size(); ++r) rows += (r ? ",\n  " : "\n  ") + it.value()[r].dump();
      text += rows + "\n ]";
    } else {
      text += it.value().dump();
    }
  }
  AtomicWriteFile(path, text + "\n}\n");
}

std::filesystem::path DefaultMotionLabelModelPath(MotionModelKind kind) {
  return DataRoot() / "tracker" / "models" / (std::string("motion_") + MotionModelKindName(kind) + ".json");
}

}  // namespace irbench
