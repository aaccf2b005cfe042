#include "tracker/motion_labels/motion_labeler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "common/error.h"

namespace irbench {
namespace {

namespace fs = std::filesystem;

std::shared_ptr<MotionLabelModel> RandomLabelModel(int window, bool transitions, uint64_t seed) {
  auto m = std::make_shared<MotionLabelModel>();
  m->kind = MotionModelKind::kLdcrf;
  m->labels = {"REST", "UP", "LEFT", "RIGHT"};
  m->crf = LatentCrf(4, 2, kMotionFeatureCount, window);
  m->feature_mean = Eigen::VectorXd::Constant(kMotionFeatureCount, 0.1);
  m->feature_scale = Eigen::VectorXd::Constant(kMotionFeatureCount, 0.5);
  m->label_prior = Eigen::Vector4d(0.4, 0.3, 0.2, 0.1);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0, 0.5);
  for (Eigen::Index i = 0; i < m->crf.state_weights().size(); ++i) m->crf.state_weights().data()[i] = n(rng);
  if (transitions) {
    for (Eigen::Index i = 0; i < m->crf.transition().size(); ++i) m->crf.transition().data()[i] = 2 * n(rng);
  }
  return m;
}

// A person whose wrists wander (seeded).
std::vector<MotionObservation> Wander(int count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> step(0, 0.02);
  std::vector<MotionObservation> out;
  Eigen::Vector3d w[2] = {{0.1, 0.2, -0.4}, {-0.1, 0.25, -0.3}};
  for (int i = 0; i < count; ++i) {
    MotionObservation o;
    o.t = i / 30.0;
    o.height_m = 1.75;
    o.waist = {0, 0, 1.0};
    o.neck = {0, 0, 1.45};
    for (int a = 0; a < 2; ++a) {
      for (int d = 0; d < 3; ++d) w[a](d) += step(rng);
      o.shoulder[a] = {a == 0 ? 0.2 : -0.2, 0, 1.4};
      o.elbow[a] = o.shoulder[a] + Eigen::Vector3d(0, 0.05, -0.3);
      o.wrist[a] = o.shoulder[a] + w[a];
      o.rest_margin[a] = w[a].z() + 0.45;
    }
    out.push_back(o);
  }
  return out;
}

// What the whole chain's forward-backward gives each arm (left mirrored back).
std::vector<std::array<std::string, 2>> Offline(const MotionLabelModel& m, const std::vector<MotionObservation>& obs) {
  MotionFeatureExtractor extractor;
  std::array<std::vector<MotionFeatures>, 2> arms;
  for (const auto& o : obs) {
    const auto f = extractor.Update(o);
    for (int a = 0; a < 2; ++a) arms[a].push_back((*f)[a]);
  }
  std::vector<std::array<std::string, 2>> out(obs.size());
  for (int a = 0; a < 2; ++a) {
    const Eigen::MatrixXd marginals = m.crf.LabelMarginals(m.Standardize(arms[a]));
    for (Eigen::Index t = 0; t < marginals.rows(); ++t) {
      const std::string& label = m.labels[m.Decide(marginals.row(t))];
      out[t][a] = a == 0 ? label : MirrorMotionLabel(label);
    }
  }
  return out;
}

// Without transitions a frame's marginal depends on its window alone, so the
// online labels, `window` frames late, are the whole chain's.
TEST(MotionLabelerTest, OnlineLabelsAreTheWindowLateWholeChainLabels) {
  const auto model = RandomLabelModel(3, false, 1);
  const std::vector<MotionObservation> obs = Wander(60, 2);
  const auto expected = Offline(*model, obs);
  MotionLabeler labeler(model, 5);
  EXPECT_EQ(labeler.latency_frames(), 3);
  std::vector<MotionLabeler::Labels> got;
  for (int f = 0; f < 60; ++f) {
    const auto out = labeler.Update(f, obs[f]);
    for (const auto& l : out) EXPECT_EQ(l.frame, f - 3);
    got.insert(got.end(), out.begin(), out.end());
  }
  const auto rest = labeler.Finish();
  EXPECT_EQ(rest.size(), 3u);
  got.insert(got.end(), rest.begin(), rest.end());
  ASSERT_EQ(got.size(), 60u);
  std::set<std::string> seen;
  for (int f = 0; f < 60; ++f) {
    EXPECT_EQ(got[f].frame, f);
    ASSERT_TRUE(got[f].arms);
    EXPECT_EQ(*got[f].arms, expected[f]) << "frame " << f;
    seen.insert((*got[f].arms)[0]);
  }
  EXPECT_GT(seen.size(), 1u);  // the test labels more than one thing
}

// With transitions, frames labelled when the segment ends (a lost frame)
// saw the whole segment: they equal the offline labels; the lost frame has
// none.
TEST(MotionLabelerTest, SegmentEndFlushesWithTheWholeSegment) {
  const auto model = RandomLabelModel(4, true, 3);
  const std::vector<MotionObservation> obs = Wander(25, 4);
  const auto expected = Offline(*model, obs);
  MotionLabeler labeler(model, 100);
  std::vector<MotionLabeler::Labels> got;
  for (int f = 0; f < 25; ++f) {
    const auto out = labeler.Update(f, obs[f]);
    got.insert(got.end(), out.begin(), out.end());
  }
  const auto flushed = labeler.Update(25, std::nullopt);
  ASSERT_EQ(flushed.size(), 5u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(flushed[i].frame, 21 + i);
    EXPECT_EQ(*flushed[i].arms, expected[21 + i]);
  }
  EXPECT_EQ(flushed[4].frame, 25);
  EXPECT_FALSE(flushed[4].arms);
  EXPECT_THROW(labeler.Update(25, obs[0]), std::invalid_argument);
}

// The balanced rule divides by the training shares; the other takes the
// largest marginal.
TEST(MotionLabelModelTest, DecisionRules) {
  MotionLabelModel m;
  m.labels = {"REST", "UP", "LEFT"};
  m.label_prior = Eigen::Vector3d(0.7, 0.2, 0.1);
  const Eigen::RowVector3d marginals(0.5, 0.3, 0.2);
  m.decision = MotionDecision::kMaxMarginal;
  EXPECT_EQ(m.Decide(marginals), 0);
  m.decision = MotionDecision::kBalanced;
  EXPECT_EQ(m.Decide(marginals), 2);  // 0.71, 1.5, 2.0
  m.prior_power = 0.25;
  EXPECT_EQ(m.Decide(marginals), 0);  // 0.55, 0.45, 0.36
}

TEST(MotionLabelModelTest, SavesLoadsAndRejectsBadFiles) {
  const fs::path dir = fs::temp_directory_path() / ("irbench_motion_model_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto model = RandomLabelModel(2, true, 5);
  model->provenance = {{"made_by", "test"}};
  model->Save(dir / "m.json");
  const MotionLabelModel back = MotionLabelModel::Load(dir / "m.json");
  EXPECT_EQ(back.labels, model->labels);
  EXPECT_EQ(back.crf.states_per_label(), 2);
  EXPECT_EQ(back.crf.window(), 2);
  EXPECT_LT((back.crf.Parameters() - model->crf.Parameters()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(back.feature_scale, model->feature_scale);
  std::ifstream in(dir / "m.json");
  const nlohmann::json good = nlohmann::json::parse(in);
  auto expect_error = [&](const std::function<void(nlohmann::json&)>& spoil, const std::string& field) {
    nlohmann::json j = good;
    spoil(j);
    std::ofstream(dir / "bad.json") << j.dump();
    try {
      MotionLabelModel::Load(dir / "bad.json");
      ADD_FAILURE() << "no error for " << field;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), (dir / "bad.json").string());
      EXPECT_EQ(e.field(), field);
    }
  };
  expect_error([](nlohmann::json& j) { j["format"] = "irbench.motion-labels/9"; }, "format");
  expect_error([](nlohmann::json& j) { j["kind"] = "svm"; }, "kind");
  expect_error([](nlohmann::json& j) { j["kind"] = "crf"; }, "states_per_label");
  expect_error([](nlohmann::json& j) { j["features"][3] = "knee"; }, "features[3]");
  expect_error([](nlohmann::json& j) { j["feature_scale"][0] = 0; }, "feature_scale");
  expect_error([](nlohmann::json& j) { j["state_weights"][1].erase(0); }, "state_weights[1]");
  expect_error([](nlohmann::json& j) { j["transition"].erase(0); }, "transition");
  expect_error([](nlohmann::json& j) { j["extra"] = 1; }, "extra");
  expect_error([](nlohmann::json& j) { j["decision"] = "vote"; }, "decision");
  expect_error([](nlohmann::json& j) { j["prior_power"] = 2; }, "prior_power");
  expect_error([](nlohmann::json& j) { j["label_prior"][2] = -0.1; }, "label_prior");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace irbench
