#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "common/error.h"
#include "tracker/posture/decompose.h"
#include "tracker/posture/posture_atoms.h"

namespace irbench {
namespace {

// Small descriptors (5 x 5 x 8 = 200 bins): a resting posture on bins
// 0..99, four arm atoms on disjoint blocks of 25 bins above it; postures are
// the rest plus arms, the additivity the thesis assumes (Eq. 4.9).
PostureAtoms SyntheticAtoms() {
  PostureAtoms a;
  a.descriptor.r_bins = 5;
  a.descriptor.theta_bins = 5;
  a.descriptor.phi_bins = 8;
  const int bins = a.descriptor.bin_count();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(0.2f, 1.0f);
  a.names = {"A0", "A1", "A2", "A3", "A4"};
  a.rest.assign(bins, 0.0f);
  for (int i = 0; i < 100; ++i) a.rest[i] = u(rng);
  double n = 0;
  for (float v : a.rest) n += v * v;
  for (float& v : a.rest) v /= std::sqrt(n);
  for (int k = 0; k < 4; ++k) {
    std::vector<float> arm(bins, 0.0f);
    for (int i = 100 + 25 * k; i < 125 + 25 * k; ++i) arm[i] = 0.05f * u(rng);
    a.arms.push_back(arm);
  }
  a.centroids = {{"A0+A0", {0, 0, 0, 0}}, {"A0+A1", {1, 0, 0, 0}}, {"A1+A1", {2, 0, 0, 0}}, {"A1+A3", {1, 0, 1, 0}}};
  return a;
}

std::vector<float> Compose(const PostureAtoms& a, double rest_scale, const std::vector<double>& w) {
  std::vector<float> f(a.rest.size());
  for (size_t i = 0; i < f.size(); ++i) {
    double v = rest_scale * a.rest[i];
    for (size_t k = 0; k < w.size(); ++k) v += w[k] * a.arms[k][i];
    f[i] = static_cast<float>(v);
  }
  return f;
}

double Norm(const std::vector<float>& v) {
  double s = 0;
  for (float x : v) s += double(x) * x;
  return std::sqrt(s);
}

TEST(Posture, RestResidualIsEquation56) {
  const PostureAtoms a = SyntheticAtoms();
  const std::vector<float> f = Compose(a, 3.0, {1, 0, 0.5, 0});
  double alpha0 = 0;
  const std::vector<float> r = RestResidual(f, a.rest, &alpha0);
  // The arms lie off the rest's bins: alpha0 = 3 / |f|, the residual the arms / |f|.
  EXPECT_NEAR(alpha0, 3.0 / Norm(f), 1e-6);
  for (size_t i = 0; i < r.size(); ++i) {
    EXPECT_NEAR(r[i], (a.arms[0][i] + 0.5 * a.arms[2][i]) / Norm(f), 1e-6) << i;
  }
}

TEST(Posture, BothWeightMethodsRecoverDisjointAtoms) {
  const PostureAtoms a = SyntheticAtoms();
  const std::vector<double> w = {1.0, 0.0, 0.7, 0.0};
  const std::vector<float> f = Compose(a, 2.0, w);
  double alpha0 = 0;
  const std::vector<float> r = RestResidual(f, a.rest, &alpha0);
  const std::vector<double> nn = NonNegativeWeights(r, a.arms);
  const std::vector<double> mp = MatchingPursuitWeights(r, a.arms, 3, 1e-4);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(nn[k], w[k] / Norm(f), 1e-5) << k;
    EXPECT_NEAR(mp[k], w[k] / Norm(f), 1e-5) << k;
  }
}

// Matching pursuit picks the atom of most overlapping bins first, and each
// atom once (Eqs. 5.7-5.8): with two atoms sharing bins it takes the one
// covering more of the residual, then the other from what is left.
TEST(Posture, MatchingPursuitPicksByOverlap) {
  std::vector<std::vector<float>> arms(2, std::vector<float>(10, 0.0f));
  for (int i = 0; i < 6; ++i) arms[0][i] = 1;   // bins 0-5
  for (int i = 4; i < 10; ++i) arms[1][i] = 1;  // bins 4-9
  std::vector<float> r(10, 0.0f);
  for (int i = 0; i < 7; ++i) r[i] = 2;  // overlaps atom 0 on 6 bins, atom 1 on 3
  const std::vector<double> w = MatchingPursuitWeights(r, arms, 3, 0.5);
  EXPECT_NEAR(w[0], 12.0 / 6.0, 1e-12);  // <r, a0> / <a0, a0>
  // Bins 0-5 removed: bin 6 remains, overlapping atom 1 once: <r, a1> = 2, / 6.
  EXPECT_NEAR(w[1], 2.0 / 6.0, 1e-12);
  EXPECT_EQ(MatchingPursuitWeights(std::vector<float>(10, -1.0f), arms, 3, 0.5), (std::vector<double>{0, 0}));
}

// Non-negative least squares against its optimality (KKT) conditions on
// random, overlapping atoms: the gradient vanishes on the atoms used and
// points outward (>= 0) on the others.
TEST(Posture, NonNegativeWeightsMeetTheKktConditions) {
  std::mt19937_64 rng(8);
  std::normal_distribution<float> z(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<std::vector<float>> arms(4, std::vector<float>(30));
    std::vector<float> r(30);
    for (auto& a : arms) {
      for (float& v : a) v = z(rng);
    }
    for (float& v : r) v = z(rng);
    const std::vector<double> w = NonNegativeWeights(r, arms);
    for (int k = 0; k < 4; ++k) {
      EXPECT_GE(w[k], 0);
      double grad = 0;  // d/dw_k of |A w - r|^2 / 2
      for (int i = 0; i < 30; ++i) {
        double fit = 0;
        for (int j = 0; j < 4; ++j) fit += w[j] * arms[j][i];
        grad += (fit - r[i]) * arms[k][i];
      }
      if (w[k] > 0) {
        EXPECT_NEAR(grad, 0, 1e-4) << trial << " " << k;
      } else {
        EXPECT_GE(grad, -1e-4) << trial << " " << k;
      }
    }
  }
}

TEST(Posture, PairRules) {
  PostureAtoms a = SyntheticAtoms();
  a.rule = PairRule::kThresholds;
  a.presence = 0.4;
  a.instance = 1.5;
  EXPECT_EQ(PairFromWeights({0.1, 0.2, 0.0, 0.3}, a), (std::array<int, 2>{0, 0}));
  EXPECT_EQ(PairFromWeights({0.1, 0.9, 0.0, 0.3}, a), (std::array<int, 2>{0, 2}));
  EXPECT_EQ(PairFromWeights({0.1, 0.9, 0.0, 1.1}, a), (std::array<int, 2>{2, 4}));
  EXPECT_EQ(PairFromWeights({0.1, 1.8, 0.0, 1.1}, a), (std::array<int, 2>{2, 2}));
  EXPECT_EQ(PairName({2, 4}, a), "A2+A4");
  a.rule = PairRule::kCentroids;
  EXPECT_EQ(PairFromWeights({0.1, 0.0, 0.0, 0.0}, a), (std::array<int, 2>{0, 0}));
  EXPECT_EQ(PairFromWeights({1.7, 0.1, 0.0, 0.0}, a), (std::array<int, 2>{1, 1}));
  EXPECT_EQ(PairFromWeights({0.8, 0.1, 0.9, 0.0}, a), (std::array<int, 2>{1, 3}));
  // Mahalanobis: a precision that discounts atom A2's weight moves the choice.
  a.centroids = {{"A0+A0", {0, 0, 0, 0}}, {"A1+A2", {1, 1, 0, 0}}};
  EXPECT_EQ(PairFromWeights({0.6, 0.0, 0.0, 0.0}, a), (std::array<int, 2>{0, 0}));
  a.centroid_precision = {1, 0, 0, 0, 0, 0.01, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  EXPECT_EQ(PairFromWeights({0.6, 0.0, 0.0, 0.0}, a), (std::array<int, 2>{1, 2}));
  a.centroid_precision = {1, 2};
  EXPECT_THROW(a.Check("x.json"), InputError);
}

// The pair agrees with the rest state's count of arms at rest: two arms in
// one atom that weigh less than two (the tracker's hulls: 1.3-1.8), and an
// arm whose weight is near rest's.
TEST(Posture, PairAgreesWithTheRestState) {
  PostureAtoms a = SyntheticAtoms();
  a.rule = PairRule::kCentroids;
  const std::vector<double> one_and_a_half = {1.4, 0.0, 0.0, 0.0};  // nearer A0+A1 ({1,0,0,0}) than A1+A1
  const std::vector<double> faint = {0.3, 0.0, 0.0, 0.0};           // nearer rest
  // Without pair_rest_state the count is ignored.
  EXPECT_EQ(PairFromWeights(one_and_a_half, a, 0), (std::array<int, 2>{0, 1}));
  a.pair_rest_state = true;
  EXPECT_EQ(PairFromWeights(one_and_a_half, a), (std::array<int, 2>{0, 1}));
  EXPECT_EQ(PairFromWeights(one_and_a_half, a, 0), (std::array<int, 2>{1, 1}));
  EXPECT_EQ(PairFromWeights(one_and_a_half, a, 2), (std::array<int, 2>{0, 0}));
  EXPECT_EQ(PairFromWeights(faint, a, 1), (std::array<int, 2>{0, 1}));
  EXPECT_EQ(PairFromWeights(faint, a, std::nullopt), (std::array<int, 2>{0, 0}));
  // Among the pairs with no A0, still the nearest: A1+A3 for one arm in each.
  EXPECT_EQ(PairFromWeights({0.8, 0.1, 0.9, 0.0}, a, 0), (std::array<int, 2>{1, 3}));
  // No centroid has the count: the weights alone decide.
  a.centroids = {{"A0+A0", {0, 0, 0, 0}}, {"A0+A1", {1, 0, 0, 0}}};
  EXPECT_EQ(PairFromWeights(one_and_a_half, a, 0), (std::array<int, 2>{0, 1}));
  // Thresholds: the 2 - n heaviest atoms, one twice when it weighs two
  // arms' worth or nothing else is present.
  a.rule = PairRule::kThresholds;
  a.presence = 0.4;
  a.instance = 1.5;
  EXPECT_EQ(PairFromWeights(one_and_a_half, a), (std::array<int, 2>{0, 1}));
  EXPECT_EQ(PairFromWeights(one_and_a_half, a, 0), (std::array<int, 2>{1, 1}));
  EXPECT_EQ(PairFromWeights({0.9, 0.0, 0.6, 0.0}, a, 0), (std::array<int, 2>{1, 3}));
  EXPECT_EQ(PairFromWeights({0.9, 0.0, 0.6, 0.0}, a, 1), (std::array<int, 2>{0, 1}));
  EXPECT_EQ(PairFromWeights({0.9, 0.0, 0.6, 0.0}, a, 2), (std::array<int, 2>{0, 0}));
  EXPECT_EQ(PairFromWeights(faint, a, 1), (std::array<int, 2>{0, 1}));
  // Through DecomposePosture: one arm in A3 with half its weight, the
  // rest state finding one arm raised.
  a.rule = PairRule::kCentroids;
  a.centroids = {{"A0+A0", {0, 0, 0, 0}}, {"A0+A3", {0, 0, 1, 0}}, {"A3+A3", {0, 0, 2, 0}}};
  const std::vector<float> f = Compose(a, 1.0, {0, 0, 0.3, 0});
  EXPECT_EQ(DecomposePosture(f, {}, a).pair, (std::array<int, 2>{0, 0}));
  EXPECT_EQ(DecomposePosture(f, {}, a, 1).pair, (std::array<int, 2>{0, 3}));
}

TEST(Posture, DecomposeUsesTheUsersRest) {
  PostureAtoms a = SyntheticAtoms();
  a.rule = PairRule::kThresholds;
  a.presence = 0.4;
  a.instance = 1.5;
  // A broader user: their resting posture also fills some of atom A1's bins.
  std::vector<float> own = a.rest;
  for (int i = 100; i < 110; ++i) own[i] = 0.08f;
  const double n = Norm(own);
  for (float& v : own) v = static_cast<float>(v / n);
  // The user raises one arm into atom A3.
  std::vector<float> f = own;
  for (size_t i = 0; i < f.size(); ++i) f[i] += a.arms[2][i];
  UserRest rest;
  EXPECT_TRUE(rest.Current().empty());
  rest.Update(own, false);
  EXPECT_TRUE(rest.Current().empty());
  rest.Update(own, true);
  rest.Update(own, true);
  ASSERT_EQ(rest.Current().size(), own.size());
  EXPECT_NEAR(Norm(rest.Current()), 1.0, 1e-6);
  const Posture with = DecomposePosture(f, rest.Current(), a);
  EXPECT_EQ(with.pair, (std::array<int, 2>{0, 3}));
  EXPECT_NEAR(with.weights[3] * Norm(f), 1.0, 1e-4);
  EXPECT_NEAR(with.weights[1], 0.0, 1e-4);
  // With the atoms' A0 the user's broader torso reads as arm A1.
  const Posture without = DecomposePosture(f, {}, a);
  EXPECT_GT(without.weights[1], a.presence);
  EXPECT_EQ(without.pair, (std::array<int, 2>{1, 3}));
  EXPECT_THROW(DecomposePosture(std::vector<float>(7, 1.0f), {}, a), std::invalid_argument);
}

TEST(Posture, ModelFileRoundTripAndErrors) {
  PostureAtoms a = SyntheticAtoms();
  a.provenance = {{"made_by", "posture_test"}};
  const auto dir = std::filesystem::temp_directory_path() / "irbench_posture_test";
  std::filesystem::create_directories(dir);
  a.Save(dir / "atoms.json");
  const PostureAtoms b = PostureAtoms::Load(dir / "atoms.json");
  EXPECT_EQ(b.names, a.names);
  EXPECT_EQ(b.centroids, a.centroids);
  EXPECT_EQ(b.provenance, a.provenance);
  EXPECT_FALSE(b.pair_rest_state);
  a.pair_rest_state = true;
  a.Save(dir / "atoms_rest.json");
  EXPECT_TRUE(PostureAtoms::Load(dir / "atoms_rest.json").pair_rest_state);
  for (size_t i = 0; i < a.rest.size(); ++i) EXPECT_NEAR(b.rest[i], a.rest[i], 1e-6 * std::abs(a.rest[i]) + 1e-12);
  EXPECT_NEAR(b.arms[3][190], a.arms[3][190], 1e-6 * a.arms[3][190]);

  auto expect_error = [&](const std::string& text, const std::string& field) {
    std::ofstream(dir / "bad.json") << text;
    try {
      PostureAtoms::Load(dir / "bad.json");
      ADD_FAILURE() << "no error for " << field;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos);
    }
  };
  std::ifstream in(dir / "atoms.json");
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    const size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  expect_error(replaced("irbench.posture-atoms/1", "irbench.posture-atoms/9"), "format");
  // A model made for another descriptor size.
  expect_error(replaced("\"phi_bins\":8", "\"phi_bins\":24"), "rest.bins");
  expect_error(replaced("\"rule\": \"centroids\"", "\"rule\": \"nearest\""), "rule");
  expect_error(replaced("\"iterations\": 3", "\"iterations\": 0"), "iterations");
  expect_error(replaced("\"pair_rest_state\": false", "\"pair_rest_state\": 1"), "pair_rest_state");
  // A file from before the key: the weights alone decide.
  std::ofstream(dir / "old.json") << replaced("\"pair_rest_state\": false,\n ", "");
  EXPECT_FALSE(PostureAtoms::Load(dir / "old.json").pair_rest_state);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace irbench
