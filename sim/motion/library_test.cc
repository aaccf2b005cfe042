#include "sim/motion/library.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "common/error.h"
#include "sim/motion/labels.h"
#include "sim/motion/motion_test_util.h"
#include "sim/motion/posture_candidates.h"
#include "sim/motion/session.h"

namespace irbench {
namespace {
using irbench::testing::Person;
namespace fs = std::filesystem;

const Scene& Theater() {
  static const Scene scene = LoadScene(fs::path(IRBENCH_SOURCE_DIR) / "scenes" / "theater.json");
  return scene;
}

const std::vector<std::string> kPersons = {"p1", "p2", "p3", "p4", "p5"};

// Thesis 7.1 rule on synthetic velocities with known answers.
TEST(MotionLabelTest, RuleOnSyntheticTrajectories) {
  EXPECT_EQ(MotionLabel(true, {0, 0, 1}), "REST");
  EXPECT_EQ(MotionLabel(false, {0.05, 0.05, 0.05}), "PAUSE");
  EXPECT_EQ(MotionLabel(false, {-0.5, 0.1, 0}), "LEFT");
  EXPECT_EQ(MotionLabel(false, {0.5, 0, -0.1}), "RIGHT");
  EXPECT_EQ(MotionLabel(false, {0, 0.1, 0.4}), "UP");
  EXPECT_EQ(MotionLabel(false, {0.1, 0, -0.4}), "DOWN");
  EXPECT_EQ(MotionLabel(false, {0, 0.6, 0}), "FORWARD");
  EXPECT_EQ(MotionLabel(false, {0, -0.6, 0.2}), "BACKWARD");
  EXPECT_EQ(MotionLabel(false, {0.3, 0.3, 0.3}), "OTHER");
  // The share threshold: 80% of the speed on one axis.
  EXPECT_EQ(MotionLabel(false, {0.81, 0.5864, 0}), "RIGHT");
  EXPECT_EQ(MotionLabel(false, {0.79, 0.613, 0}), "OTHER");
}

TEST(MotionLabelTest, RestAndAtomRules) {
  EXPECT_TRUE(ArmAtRest({0.2, 0.1, -1}, {0.1, 0.4, -1}));
  EXPECT_FALSE(ArmAtRest({1, 0, -0.5}, {0, 0, -1}));  // upper arm 63° out
  EXPECT_FALSE(ArmAtRest({0, 0, -1}, {0, 1, -0.5}));  // forearm raised
  EXPECT_EQ(ArmAtom(true, {0, 0, 1}), "A0");
  EXPECT_EQ(ArmAtom(false, {1, 0, 0.1}), "A1");
  EXPECT_EQ(ArmAtom(false, {1, 0, 1}), "A3");
  EXPECT_EQ(ArmAtom(false, {0.1, 0, 1}), "A2");
  EXPECT_EQ(ArmAtom(false, {1, 0, -1}), "A4");
}

// Every pointing frame of the library, once settled, aims the head-centre-to-
// hand-tip ray at the named target within 1 cm on the screen.
TEST(LibraryTest, PointingHitsTargetsWithinOneCentimetre) {
  const Scene& scene = Theater();
  ASSERT_FALSE(scene.screens.empty());
  double worst = 0;
  int frames = 0;
  for (const std::string& person : kPersons) {
    const Avatar avatar = Person(person);
    for (const auto& [target, st] : scene.screens[0].targets) {
      for (const char* side : {"right", "left"}) {
        for (const char* name : {"point", "point_horizontal", "direct_traffic"}) {
          MotionContext ctx{&avatar, &scene, StyleFor(person, 1), {}};
          ctx.state.position = {0.3, -0.2};
          const MotionPtr m = BuildLibraryMotion(name, {{"target", target}, {"side", side}}, ctx);
          const Labeler labeler(avatar, &scene, *m);
          int seen = 0;
          for (const MotionEvent& e : m->Events()) {
            if (e.kind != "point") continue;
            EXPECT_EQ(e.value, target);
            for (double t = e.start; t <= e.end; t += 1.0 / 30) {
              const auto pointing = labeler.Pointing(t);
              ASSERT_FALSE(pointing[side].is_null()) << person << " " << target << " " << side << " t=" << t;
              const Eigen::Vector2d hit(pointing[side]["screen_hit"][0], pointing[side]["screen_hit"][1]);
              worst = std::max(worst, (hit - st).norm());
              EXPECT_EQ(pointing[side]["aimed_at"], target);
              ++seen;
              ++frames;
            }
          }
          EXPECT_GT(seen, 10) << name;
        }
      }
    }
  }
  EXPECT_LT(worst, 0.01) << "over " << frames << " frames";
  std::printf("pointing: %d settled frames, worst screen distance from the target %.2e m\n", frames, worst);
}

TEST(LibraryTest, StylesDifferBetweenPersonsAndAreSeeded) {
  const MotionStyle a = StyleFor("p1", 1), b = StyleFor("p2", 1), a2 = StyleFor("p1", 1);
  EXPECT_EQ(a.tempo, a2.tempo);
  EXPECT_EQ(a.tremor_deg, a2.tremor_deg);
  EXPECT_NE(a.tempo, b.tempo);
  EXPECT_NE(a.asynchrony_s, b.asynchrony_s);
  // Same gesture, two persons: the hands are in different places mid-gesture.
  const Avatar avatar = Person("p1");
  MotionContext ca{&avatar, &Theater(), a, {}}, cb{&avatar, &Theater(), b, {}};
  const MotionPtr ga = BuildLibraryMotion("flap_both", nullptr, ca);
  const MotionPtr gb = BuildLibraryMotion("flap_both", nullptr, cb);
  EXPECT_NE(ga->Duration(), gb->Duration());
  const auto ja = TruthJoints(avatar, ForwardKinematics(avatar.skeleton, ga->At(1.5)));
  const auto jb = TruthJoints(avatar, ForwardKinematics(avatar.skeleton, gb->At(1.5)));
  EXPECT_GT((ja[10] - jb[10]).norm(), 0.02);
}

// A composed session: each gesture's frames carry its label for at least 95%
// of its span; rest flags flip where the arms come down.
TEST(LibraryTest, SessionLabelsGesturesAndRest) {
  const fs::path file = fs::path(IRBENCH_SOURCE_DIR) / "motions" / "session_demo.json";
  const Avatar avatar = Person("p3");
  MotionContext ctx{&avatar, &Theater(), StyleFor("p3", 2), {}};
  const ResolvedMotion resolved = ResolveMotion(file.string(), ctx, "--motion");
  EXPECT_EQ(resolved.kind, "session");
  const MotionSource& m = *resolved.motion;
  const Labeler labeler(avatar, &Theater(), m);
  std::set<std::string> gestures_seen;
  const double fps = 30;
  for (const MotionEvent& e : m.Events()) {
    if (e.kind != "gesture") continue;
    gestures_seen.insert(e.value);
    int total = 0, labelled = 0;
    for (int f = static_cast<int>(std::ceil(e.start * fps)); f <= std::floor(e.end * fps); ++f) {
      ++total;
      labelled += labeler.Labels(f / fps)["gesture"] == e.value;
    }
    EXPECT_GE(labelled, 0.95 * total) << e.value;
    // At rest before the gesture's arm rises; not at rest at its middle, unless
    // the gesture is made with the arms low.
    const auto before = labeler.Labels(e.start + 0.02)["rest"];
    const auto middle = labeler.Labels(0.5 * (e.start + e.end))["rest"];
    EXPECT_TRUE(before["right"].get<bool>() && before["left"].get<bool>()) << e.value;
    EXPECT_FALSE(middle["right"].get<bool>() && middle["left"].get<bool>()) << e.value;
    const auto after = labeler.Labels(e.end - 0.02)["rest"];
    EXPECT_TRUE(after["right"].get<bool>() && after["left"].get<bool>()) << e.value;
  }
  EXPECT_EQ(gestures_seen.size(), 6u);
}

// The story motion covers all nine motion labels.
TEST(LibraryTest, StoryCoversTheNineMotionLabels) {
  for (const std::string& person : {std::string("p1"), std::string("p4")}) {
    const Avatar avatar = Person(person);
    MotionContext ctx{&avatar, &Theater(), StyleFor(person, 1), {}};
    const MotionPtr m = BuildLibraryMotion("story", nullptr, ctx);
    const Labeler labeler(avatar, &Theater(), *m);
    const std::string side = ctx.style.handedness > 0 ? "right" : "left";
    std::map<std::string, int> count;
    for (double t = 0; t <= m->Duration() + 0.5; t += 1.0 / 30) {
      ++count[labeler.Labels(t)["motion"][side].get<std::string>()];
    }
    for (const std::string& label : MotionLabelNames()) {
      EXPECT_GT(count[label], 0) << person << " never " << label;
    }
  }
}

TEST(LibraryTest, EveryMotionBuildsAndKeepsFeetOnTheFloor) {
  const Avatar avatar = Person("p2");
  for (const auto& [name, description] : LibraryMotions()) {
    MotionContext ctx{&avatar, &Theater(), StyleFor("p2", 5), {}};
    nlohmann::json params = nullptr;
    if (name == "point") params = {{"target", Theater().screens[0].targets.begin()->first}};
    if (name == "walk") params = {{"to", {1.0, 0.5}}};
    if (name == "turn") params = {{"heading_deg", 90}};
    const MotionPtr m = BuildLibraryMotion(name, params, ctx);
    EXPECT_GT(m->Duration(), 0.5) << name;
    for (double t = 0; t <= m->Duration(); t += 0.25) {
      const JointTransforms fk = ForwardKinematics(avatar.skeleton, m->At(t));
      const double low = std::min(fk[kRightAnkle].translation().z(), fk[kLeftAnkle].translation().z());
      EXPECT_NEAR(low, avatar.skeleton.bind_position[kRightAnkle].z(), 1e-6) << name << " t=" << t;
    }
  }
  MotionContext ctx{&avatar, &Theater(), StyleFor("p2", 5), {}};
  BuildLibraryMotion("walk", {{"to", {1.0, 0.5}}}, ctx);
  EXPECT_NEAR((ctx.state.position - Eigen::Vector2d(1.0, 0.5)).norm(), 0, 1e-12);
}

// The 30 candidate postures (thesis 5.1.2): one event per hold, each hold a
// still pose of the candidate arm alone, all 30 different, and the atoms'
// own postures among them where docs/motion.md says (the truth's rule names
// them: C03 A1, C19 A2, C05 A3, C01 A4).
TEST(LibraryTest, PostureCandidatesHoldThirtyDistinctOneArmPostures) {
  for (const char* side : {"right", "left"}) {
    const Avatar avatar = Person("p3");
    MotionContext ctx{&avatar, &Theater(), StyleFor("p3", 2), {}};
    const MotionPtr m = BuildLibraryMotion("posture_candidates", {{"side", side}}, ctx);
    const Labeler labeler(avatar, &Theater(), *m);
    const int arm = std::string(side) == "right" ? kRightShoulder : kLeftShoulder;
    std::vector<Eigen::Vector3d> wrists;
    int holds = 0;
    for (const MotionEvent& e : m->Events()) {
      if (e.kind != "posture_candidate") continue;
      ++holds;
      EXPECT_EQ(e.value, (holds < 10 ? "C0" : "C") + std::to_string(holds));
      EXPECT_EQ(e.side, side);
      const JointTransforms a = ForwardKinematics(avatar.skeleton, m->At(e.start + 0.05));
      const JointTransforms b = ForwardKinematics(avatar.skeleton, m->At(e.end - 0.05));
      const Eigen::Vector3d wrist = b[arm + 2].translation() - b[arm].translation();
      // Held: the wrist moves only by the tremor.
      EXPECT_LT((a[arm + 2].translation() - b[arm + 2].translation()).norm(), 0.02) << e.value;
      for (const Eigen::Vector3d& w : wrists) EXPECT_GT((w - wrist).norm(), 0.05) << e.value;
      wrists.push_back(wrist);
      const nlohmann::json labels = labeler.Labels(0.5 * (e.start + e.end));
      EXPECT_EQ(labels["rest"][std::string(side) == "right" ? "left" : "right"], true) << e.value;
      const std::map<std::string, std::string> atoms = {{"C03", "A1"}, {"C19", "A2"}, {"C05", "A3"}, {"C01", "A4"}};
      if (atoms.count(e.value)) {
        EXPECT_EQ(labels["posture"], nlohmann::json({atoms.at(e.value), "A0"})) << e.value;
      }
    }
    EXPECT_EQ(holds, 30);
    EXPECT_EQ(PostureCandidateDescriptions().size(), 30u);
  }
}

// `posture` with atoms' weights: one atom at weight 1 is that atom, no
// weight is the rest posture, A1 and A3 half each hold the upper arm halfway
// between their elevations (0 and 45 degrees: the slerp between two
// rotations about the same axis), weights over 1 are scaled to 1, and the
// hold lasts `hold_s` after `move_s`.
TEST(LibraryTest, PostureBlendsAtomsByWeight) {
  const Avatar avatar = Person("p3");
  const auto held = [&](const nlohmann::json& params) {
    MotionContext ctx{&avatar, &Theater(), StyleFor("p3", 2), {}};
    const MotionPtr m = BuildLibraryMotion("posture", params, ctx);
    return ForwardKinematics(avatar.skeleton, m->At(1.6));
  };
  // The right upper arm's elevation (degrees above level) and the wrist.
  const auto elevation = [](const JointTransforms& fk) {
    const Eigen::Vector3d d = fk[kRightElbow].translation() - fk[kRightShoulder].translation();
    return std::asin(d.normalized().z()) * 180 / M_PI;
  };
  const auto wrist = [](const JointTransforms& fk) { return fk[kRightWrist].translation(); };
  EXPECT_LT((wrist(held({{"right", {{"A3", 1.0}}}})) - wrist(held({{"right", "A3"}}))).norm(), 1e-9);
  EXPECT_LT((wrist(held({{"right", {{"A2", 0.0}}}})) - wrist(held({{"right", "A0"}}))).norm(), 1e-9);
  EXPECT_LT((wrist(held({{"right", {{"A1", 1.0}, {"A3", 1.0}}}})) -
             wrist(held({{"right", {{"A1", 0.5}, {"A3", 0.5}}}})))
                .norm(),
            1e-9);
  const double a1 = elevation(held({{"right", "A1"}})), a3 = elevation(held({{"right", "A3"}}));
  EXPECT_NEAR(a1, 0, 3);
  EXPECT_NEAR(a3, 45, 3);
  EXPECT_NEAR(elevation(held({{"right", {{"A1", 0.5}, {"A3", 0.5}}}})), 0.5 * (a1 + a3), 0.5);
  // A quarter of A2 (overhead) from the rest: the arm between the two, nearer the rest.
  const double rest = elevation(held({{"right", "A0"}})), a2 = elevation(held({{"right", "A2"}}));
  const double quarter = elevation(held({{"right", {{"A2", 0.25}}}}));
  EXPECT_GT(quarter, rest + 10);
  EXPECT_LT(quarter, 0.5 * (rest + a2));
  MotionContext ctx{&avatar, &Theater(), StyleFor("p3", 2), {}};
  const MotionPtr m = BuildLibraryMotion("posture", {{"right", {{"A1", 1.0}}}, {"move_s", 0.5}, {"hold_s", 3.0}}, ctx);
  const double tempo = ctx.style.tempo;
  EXPECT_NEAR(m->Duration(), BuildLibraryMotion("posture", {{"right", "A1"}}, ctx)->Duration() + 1.0 / tempo, 0.3);
  const JointTransforms a = ForwardKinematics(avatar.skeleton, m->At(0.55 / tempo));
  const JointTransforms b = ForwardKinematics(avatar.skeleton, m->At(3.45 / tempo));
  EXPECT_LT((wrist(a) - wrist(b)).norm(), 0.02);
  const std::vector<std::pair<nlohmann::json, std::string>> bad = {
      {{{"right", {{"A7", 0.5}}}}, "right.A7"}, {{{"right", {{"A1", -0.1}}}}, "right.A1"},
      {{{"right", {{"A1", 1.5}}}}, "right.A1"}, {{{"right", {{"A1", "x"}}}}, "right.A1"},
      {{{"left", nlohmann::json::object()}}, "left"}, {{{"left", 3}}, "left"}};
  for (const auto& [params, field] : bad) {
    try {
      BuildLibraryMotion("posture", params, ctx);
      ADD_FAILURE() << params.dump();
    } catch (const InputError& e) {
      const std::string f = e.field();
      EXPECT_EQ(f.substr(f.size() - std::min(f.size(), field.size())), field) << e.what();
      EXPECT_TRUE(f.size() == field.size() || f[f.size() - field.size() - 1] == '.') << f;
    }
  }
}

TEST(LibraryTest, StyleOverridesAreCheckedAndApplied) {
  const MotionStyle st = StyleFor("p1", 1, {{"tempo", 1.5}, {"handedness", "left"}}, "avatars/x.json");
  EXPECT_EQ(st.tempo, 1.5);
  EXPECT_EQ(st.handedness, -1);
  EXPECT_EQ(st.amplitude, StyleFor("p1", 1).amplitude);
  try {
    StyleFor("p1", 1, {{"tempo", 9.0}}, "avatars/x.json");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "avatars/x.json");
    EXPECT_EQ(e.field(), "style.tempo");
  }
  EXPECT_THROW(StyleFor("p1", 1, {{"speed", 1.0}}, "x"), InputError);
  EXPECT_THROW(StyleFor("p1", 1, {{"handedness", "both"}}, "x"), InputError);
}

TEST(LibraryTest, BadNamesAndParametersAreInputErrors) {
  const Avatar avatar = Person("p1");
  MotionContext ctx{&avatar, &Theater(), StyleFor("p1", 1), {}};
  EXPECT_THROW(BuildLibraryMotion("moonwalk", nullptr, ctx), InputError);
  EXPECT_THROW(BuildLibraryMotion("point", {{"target", "nowhere"}}, ctx), InputError);
  EXPECT_THROW(BuildLibraryMotion("flap_one", {{"cycles", 1000}}, ctx), InputError);
  EXPECT_THROW(BuildLibraryMotion("rest", {{"secs", 2}}, ctx), InputError);
  EXPECT_THROW(BuildLibraryMotion("posture", {{"right", "A9"}}, ctx), InputError);
}

}  // namespace
}  // namespace irbench
