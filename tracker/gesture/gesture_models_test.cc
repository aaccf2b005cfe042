#include "tracker/gesture/gesture_models.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "common/error.h"
#include "tracker/gesture/gesture_recognizer.h"

namespace irbench {
namespace {

const std::vector<std::string> kAtoms = {"A0", "A1", "A2", "A3", "A4"};

// A gesture as a script of two arms' atoms over time (each held a while),
// observed as weight vectors (one arm in atom k weighs 1 on k) with noise and
// as the recognised pair with some errors: what the posture stage gives.
std::vector<GestureObservation> Perform(const std::vector<std::pair<int, int>>& script, std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0, 0.12);
  std::uniform_int_distribution<int> hold(6, 14);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<GestureObservation> out;
  for (auto [a, b] : script) {
    const int frames = hold(rng);
    for (int t = 0; t < frames; ++t) {
      GestureObservation o;
      o.weights = Eigen::VectorXd::Zero(5);
      o.weights(0) = 0.95 + 0.01 * noise(rng);
      if (a) o.weights(a) += 1;
      if (b) o.weights(b) += 1;
      for (int k = 1; k < 5; ++k) o.weights(k) += noise(rng);
      int p = std::max(a, b), s = std::min(a, b);
      if (u(rng) < 0.1) p = std::uniform_int_distribution<int>(0, 4)(rng);
      o.primary = std::max(p, s);
      o.secondary = std::min(p, s);
      out.push_back(o);
    }
  }
  return out;
}

// Three gestures that use the same atoms in different orders and pairings.
const std::vector<std::vector<std::pair<int, int>>> kScripts = {
    {{0, 0}, {1, 0}, {3, 0}, {1, 0}, {0, 0}},  // one arm up and down
    {{0, 0}, {1, 1}, {4, 4}, {1, 1}, {4, 4}, {0, 0}},  // both arms flap
    {{0, 0}, {3, 4}, {3, 4}, {0, 0}},  // one up, one down
};

GestureModels TrainOnScripts(std::mt19937_64& rng) {
  std::vector<std::vector<std::vector<GestureObservation>>> segments(kScripts.size());
  for (size_t g = 0; g < kScripts.size(); ++g) {
    for (int r = 0; r < 5; ++r) segments[g].push_back(Perform(kScripts[g], rng));
  }
  GestureTrainingOptions options;
  options.max_iterations = 25;
  options.restarts = 2;
  return GestureModels::Train({"up", "flap", "diagonal"}, kAtoms, segments, options);
}

TEST(GestureModels, EveryKindRecognisesHeldOutPerformances) {
  std::mt19937_64 rng(12);
  const GestureModels models = TrainOnScripts(rng);
  for (GestureModelKind kind : {GestureModelKind::kHmm, GestureModelKind::kParallelHmm, GestureModelKind::kFactorialHmm}) {
    int right = 0, total = 0;
    for (size_t g = 0; g < kScripts.size(); ++g) {
      for (int r = 0; r < 6; ++r) {
        std::vector<double> ll;
        right += models.Classify(kind, Perform(kScripts[g], rng), &ll) == static_cast<int>(g);
        ++total;
        for (double v : ll) EXPECT_TRUE(std::isfinite(v));
      }
    }
    EXPECT_GE(right, total - 1) << GestureModelKindName(kind);
  }
}

TEST(GestureModels, FileRoundTripKeepsTheLikelihoodsAndBadFilesAreNamed) {
  std::mt19937_64 rng(4);
  GestureModels models = TrainOnScripts(rng);
  models.provenance = {{"made_by", "gesture_models_test"}};
  const auto dir = std::filesystem::temp_directory_path() / "irbench_gesture_models_test";
  std::filesystem::create_directories(dir);
  models.Save(dir / "m.json");
  const GestureModels back = GestureModels::Load(dir / "m.json");
  EXPECT_EQ(back.gestures, models.gestures);
  EXPECT_EQ(back.provenance, models.provenance);
  EXPECT_EQ(back.observation, GestureObservationKind::kPair);  // the default
  EXPECT_EQ(back.pair_scale, models.pair_scale);
  const std::vector<GestureObservation> segment = Perform(kScripts[1], rng);
  for (GestureModelKind kind : {GestureModelKind::kHmm, GestureModelKind::kParallelHmm, GestureModelKind::kFactorialHmm}) {
    for (int g = 0; g < 3; ++g) {
      const double a = models.LogLikelihood(kind, g, segment), b = back.LogLikelihood(kind, g, segment);
      EXPECT_NEAR(a, b, 1e-6 * std::abs(a)) << GestureModelKindName(kind) << " " << g;
    }
  }
  std::ifstream in(dir / "m.json");
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto expect_error = [&](const std::string& from, const std::string& to, const std::string& field) {
    std::string text = good;
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(dir / "bad.json") << text;
    try {
      GestureModels::Load(dir / "bad.json");
      ADD_FAILURE() << "no error for " << field;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), field) << e.what();
    }
  };
  expect_error("irbench.gesture-models/1", "irbench.gesture-models/2", "format");
  // Models trained for four atoms read as five: every matrix disagrees; the
  // first one read names itself.
  expect_error("\"atoms\": [\"A0\",\"A1\",\"A2\",\"A3\",\"A4\"]", "\"atoms\": [\"A0\",\"A1\",\"A2\",\"A3\"]",
               "models[0].hmm.means[0]");
  expect_error("\"gestures\": [\"up\",\"flap\",\"diagonal\"]", "\"gestures\": [\"up\",\"flap\"]", "models");
  expect_error("\"pair_scale\": 0.1", "\"pair_scale\": -1", "pair_scale");
  expect_error("\"observation\": \"pair\"", "\"observation\": \"poses\"", "observation");
  // A file from before the keys observes the weights.
  std::string old = good;
  for (const std::string key : {"\"observation\": \"pair\",\n ", "\"pair_scale\": 0.1,\n "}) {
    ASSERT_NE(old.find(key), std::string::npos) << key;
    old.erase(old.find(key), key.size());
  }
  std::ofstream(dir / "old.json") << old;
  EXPECT_EQ(GestureModels::Load(dir / "old.json").observation, GestureObservationKind::kWeights);
  std::filesystem::remove_all(dir);
}

// Two gestures whose weights agree: one arm raised into A1, and both arms
// into A1 where two arms weigh what one does (the tracker's hulls: 1.3-1.8
// rather than 2). Only the recognised pair, whose count of arms at rest the
// pose tracker's rest state fixes, tells them apart.
std::vector<GestureObservation> RaiseInto(int arms, std::mt19937_64& rng) {
  std::vector<GestureObservation> out = Perform({{0, 0}, {1, 0}, {1, 0}, {0, 0}}, rng);
  for (GestureObservation& o : out) {
    if (o.primary != 0) o.secondary = arms == 2 ? o.primary : 0;
  }
  return out;
}

TEST(GestureModels, ThePairObservationTellsOneArmFromTwo) {
  std::mt19937_64 rng(8);
  std::vector<std::vector<std::vector<GestureObservation>>> segments(2);
  for (int r = 0; r < 6; ++r) {
    segments[0].push_back(RaiseInto(1, rng));
    segments[1].push_back(RaiseInto(2, rng));
  }
  GestureTrainingOptions options;
  options.max_iterations = 25;
  options.restarts = 2;
  options.observation = GestureObservationKind::kWeights;
  const GestureModels weights = GestureModels::Train({"one", "two"}, kAtoms, segments, options);
  options.observation = GestureObservationKind::kPair;
  options.pair_scale = 0.2;
  const GestureModels pair = GestureModels::Train({"one", "two"}, kAtoms, segments, options);
  // The observation: pair_scale per arm on the pair's atoms.
  const GestureObservation& raised = segments[1][0][segments[1][0].size() / 2];
  ASSERT_NE(raised.primary, 0);
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(5);
  expected(raised.primary) += 0.2;
  expected(raised.secondary) += 0.2;
  EXPECT_EQ(pair.ObservationVector(raised), expected);
  EXPECT_EQ(weights.ObservationVector(raised), raised.weights);
  for (GestureModelKind kind : {GestureModelKind::kHmm, GestureModelKind::kFactorialHmm}) {
    int right_weights = 0, right_pair = 0, total = 0;
    for (int r = 0; r < 10; ++r) {
      for (int arms = 1; arms <= 2; ++arms) {
        const std::vector<GestureObservation> seg = RaiseInto(arms, rng);
        right_weights += weights.Classify(kind, seg) == arms - 1;
        right_pair += pair.Classify(kind, seg) == arms - 1;
        ++total;
      }
    }
    EXPECT_EQ(right_pair, total) << GestureModelKindName(kind);
    EXPECT_LE(right_weights, total * 3 / 4) << GestureModelKindName(kind);
  }
  // The kind and scale survive the file, and the online recogniser reads them.
  const auto dir = std::filesystem::temp_directory_path() / "irbench_gesture_models_pair";
  std::filesystem::create_directories(dir);
  pair.Save(dir / "m.json");
  auto back = std::make_shared<GestureModels>(GestureModels::Load(dir / "m.json"));
  EXPECT_EQ(back->observation, GestureObservationKind::kPair);
  EXPECT_DOUBLE_EQ(back->pair_scale, 0.2);
  const std::vector<GestureObservation> seg = RaiseInto(2, rng);
  GestureRecognizer online(back, GestureModelKind::kFactorialHmm, {1});
  std::optional<GestureDecision> d;
  for (size_t t = 0; t < seg.size(); ++t) d = online.Update(static_cast<int>(t), seg[t], false);
  ASSERT_TRUE(d);
  std::vector<double> batch;
  EXPECT_EQ(d->gesture, back->Classify(GestureModelKind::kFactorialHmm, seg, &batch));
  EXPECT_EQ(d->gesture, 1);
  for (int g = 0; g < 2; ++g) EXPECT_NEAR(online.log_likelihoods()[g], batch[g], 1e-6 * std::abs(batch[g]));
  std::filesystem::remove_all(dir);
}

// Online, frame by frame, the recogniser's log-likelihoods equal the batch
// ones of the segment seen so far (the last frame at rest first), and its
// decision is the batch classification.
TEST(GestureRecognizer, OnlineEqualsBatchOnTheSegmentSoFar) {
  std::mt19937_64 rng(6);
  auto models = std::make_shared<GestureModels>(TrainOnScripts(rng));
  for (GestureModelKind kind : {GestureModelKind::kHmm, GestureModelKind::kParallelHmm, GestureModelKind::kFactorialHmm}) {
    GestureRecognizer online(models, kind, {10});
    const std::vector<GestureObservation> rest = Perform({{0, 0}}, rng);
    int frame = 0;
    for (const auto& o : rest) EXPECT_FALSE(online.Update(frame++, o, true));
    const std::vector<GestureObservation> gesture = Perform(kScripts[2], rng);
    std::vector<GestureObservation> seen = {rest.back()};
    const int start = frame;
    for (size_t t = 0; t < gesture.size(); ++t) {
      seen.push_back(gesture[t]);
      const std::optional<GestureDecision> d = online.Update(frame++, gesture[t], false);
      ASSERT_EQ(d.has_value(), seen.size() >= 10) << t;
      std::vector<double> batch;
      const int best = models->Classify(kind, seen, &batch);
      for (int g = 0; g < 3; ++g) EXPECT_NEAR(online.log_likelihoods()[g], batch[g], 1e-6 * std::abs(batch[g]));
      if (d) {
        EXPECT_EQ(d->gesture, best);
        EXPECT_EQ(d->start_frame, start);
        EXPECT_GE(d->score, 0);
      }
    }
    EXPECT_FALSE(online.Update(frame++, rest[0], true));
    EXPECT_FALSE(online.Update(frame++, std::nullopt, false));
  }
}

}  // namespace
}  // namespace irbench
