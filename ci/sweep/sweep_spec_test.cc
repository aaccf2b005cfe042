// The sweep spec: its points against a brute-force enumeration and the
// analytic placements, the moved rig's camera where the point says, random
// points reproducible by index, and bad specs refused naming the field.

#include "ci/sweep/sweep_spec.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <tuple>

#include "common/error.h"
#include "sim/camera/rig.h"
#include "sim/sensor/sensor_model.h"
#include "sim/sequence/render_job.h"
#include "sim/motion/keyframes.h"
#include "sim/motion/motion_test_util.h"
#include "sim/motion/session.h"
#include "sim/scene/scene.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

fs::path Dir() {
  const fs::path dir = fs::temp_directory_path() / "irbench_sweep_spec_test";
  fs::create_directories(dir);
  return dir;
}

fs::path Write(const std::string& name, const std::string& text) {
  const fs::path file = Dir() / name;
  std::ofstream(file) << text;
  return file;
}

// A spec with the side camera on a 3 x 2 placement grid and two persons.
std::string GridSpec(const std::string& extra = "") {
  return R"({"format": "irbench.sweep/1", "name": "t", "base": {"rig": "theater4", "motion": "wave", "frames": 3},
    "axes": [{"camera": "side", "along": {"from": [-3.6, -1.0], "to": [-3.6, 2.0], "steps": 3},
              "height": {"from": 1.5, "to": 2.5, "steps": 2}, "look_at": [0, 0, 1.1]},
             {"key": "avatar", "values": ["p1", "p4"]}])" + extra + "}";
}

TEST(SweepSpecTest, GridVisitsEveryCombinationOnceAtTheAnalyticPlaces) {
  const SweepSpec spec = LoadSweepSpec(Write("grid.json", GridSpec()));
  ASSERT_EQ(PointCount(spec), 3 * 2 * 2);
  std::set<std::tuple<int, int, std::string>> seen;
  for (int i = 0; i < PointCount(spec); ++i) {
    const SweepPoint p = PointAt(spec, i);
    ASSERT_EQ(p.at.size(), 2u);
    const AxisValue& place = p.at[0];
    seen.insert({place.along_step, place.height_step, p.at[1].value.get<std::string>()});
    // from + t (to - from), t = step / 2; heights 1.5 and 2.5.
    EXPECT_NEAR(place.position.x(), -3.6, 1e-12);
    EXPECT_NEAR(place.position.y(), -1.0 + 3.0 * place.along_step / 2.0, 1e-12);
    EXPECT_NEAR(place.position.z(), place.height_step == 0 ? 1.5 : 2.5, 1e-12);
  }
  EXPECT_EQ(seen.size(), 12u);  // every combination, none twice
  // The last axis changes fastest.
  EXPECT_EQ(PointAt(spec, 0).at[1].value, "p1");
  EXPECT_EQ(PointAt(spec, 1).at[1].value, "p4");
  EXPECT_THROW(PointAt(spec, 12), InputError);
}

TEST(SweepSpecTest, PointRigHasTheCameraWhereThePointSays) {
  const SweepSpec spec = LoadSweepSpec(Write("rig.json", GridSpec()));
  const SweepPoint p = PointAt(spec, 7);
  const Scenario sc = PointScenario(spec, p, Dir());
  EXPECT_EQ(sc.render.avatar, p.at[1].value.get<std::string>());
  EXPECT_EQ(fs::path(sc.render.rig).filename(), "p0007.json");
  const Rig moved = LoadRig(sc.render.rig);
  const Rig base = LoadRig(fs::path(IRBENCH_SOURCE_DIR) / "rigs" / "theater4.json");
  ASSERT_EQ(moved.cameras.size(), base.cameras.size());
  for (size_t c = 0; c < moved.cameras.size(); ++c) {
    const Eigen::Vector3d centre = moved.cameras[c].cam_from_world.inverse().translation();
    const Eigen::Vector3d base_centre = base.cameras[c].cam_from_world.inverse().translation();
    if (moved.cameras[c].name == "side") {
      EXPECT_LT((centre - p.at[0].position).norm(), 1e-9);
      // Aimed at look_at: the optical axis (camera z) points at it.
      const Eigen::Vector3d axis = moved.cameras[c].cam_from_world.linear().row(2).transpose();
      EXPECT_GT(axis.dot((Eigen::Vector3d(0, 0, 1.1) - centre).normalized()), 1 - 1e-9);
    } else {
      EXPECT_LT((centre - base_centre).norm(), 1e-9) << moved.cameras[c].name;
    }
  }
}

TEST(SweepSpecTest, RandomPointsAreInRangeAndDependOnlyOnSeedAndIndex) {
  const std::string text = R"({"format": "irbench.sweep/1", "name": "r", "mode": "random", "samples": 50, "seed": 9,
    "base": {"rig": "theater4", "motion": "wave", "frames": 3},
    "axes": [{"camera": "side", "along": {"from": [-3.6, -1.0], "to": [-3.6, 2.0]},
              "height": {"from": 1.5, "to": 2.5, "steps": 2}}, {"key": "seed", "values": [1, 2, 3]}]})";
  const SweepSpec a = LoadSweepSpec(Write("r1.json", text));
  ASSERT_EQ(PointCount(a), 50);
  std::set<int> seeds;
  double mean_along = 0;
  for (int i = 0; i < 50; ++i) {
    const SweepPoint p = PointAt(a, i);
    EXPECT_GE(p.at[0].along, 0.0);
    EXPECT_LT(p.at[0].along, 1.0);
    EXPECT_GE(p.at[0].height, 1.5);
    EXPECT_LE(p.at[0].height, 2.5);
    mean_along += p.at[0].along / 50;
    seeds.insert(p.at[1].value.get<int>());
    EXPECT_EQ(PointCoordinates(a, p), PointCoordinates(a, PointAt(a, i)));  // again: the same
  }
  EXPECT_EQ(seeds.size(), 3u);
  EXPECT_NEAR(mean_along, 0.5, 0.15);
  std::string other = text;
  other.replace(other.find("\"seed\": 9"), 9, "\"seed\": 8");
  const SweepSpec b = LoadSweepSpec(Write("r2.json", other));
  EXPECT_NE(PointAt(a, 0).at[0].along, PointAt(b, 0).at[0].along);
}

// A known bowl for a search: a point's metric is its first axis's camera's
// distance from `target`, each point drawn (through the earlier generations'
// metrics) once.
struct DistanceFrom {
  const SweepSpec& spec;
  Eigen::Vector3d target;
  std::map<int, double> memo;
  std::optional<double> operator()(int i) {
    if (!memo.count(i)) memo[i] = (PointAt(spec, i, [this](int j) { return (*this)(j); }).at[0].position - target).norm();
    return memo[i];
  }
};

// The cross-entropy search on a known bowl (the metric: the camera's distance
// from a target on its wall): it needs each generation's predecessors, and
// its generations close in on the target.
TEST(SweepSpecTest, SearchClosesInOnTheBestPlacement) {
  const SweepSpec spec = LoadSweepSpec(Write("search.json", R"({"format": "irbench.sweep/1", "name": "s",
    "base": {"rig": "theater4", "motion": "wave", "frames": 3}, "mode": "search", "seed": 3,
    "search": {"population": 6, "generations": 6, "elite": 2},
    "axes": [{"camera": "side", "along": {"from": [-3.6, -2.0], "to": [-3.6, 2.0]},
              "height": {"from": 1.0, "to": 3.0}}]})"));
  ASSERT_EQ(PointCount(spec), 36);
  EXPECT_EQ(GenerationOf(spec, 5), 0);
  EXPECT_EQ(GenerationOf(spec, 6), 1);
  EXPECT_THROW(PointAt(spec, 6), RuntimeError);  // generation 1 needs generation 0's metrics
  const Eigen::Vector3d target(-3.6, 1.1, 2.4);
  DistanceFrom bowl{spec, target, {}};
  const PointMetric metric_of = [&bowl](int i) { return bowl(i); };
  double first = 1e9, last = 1e9;
  for (int i = 0; i < 6; ++i) first = std::min(first, *metric_of(i));
  for (int i = 30; i < 36; ++i) last = std::min(last, *metric_of(i));
  EXPECT_LT(last, first);
  EXPECT_LT(last, 0.15);
  // The last generation's first point is its distribution's mean: near the target.
  EXPECT_LT(*metric_of(30), 0.3);
  // Every point inside the ranges.
  for (int i = 0; i < 36; ++i) {
    const SweepPoint point = PointAt(spec, i, metric_of);
    const AxisValue& at = point.at[0];
    EXPECT_GE(at.along, 0.0);
    EXPECT_LE(at.along, 1.0);
    EXPECT_GE(at.height, 1.0);
    EXPECT_LE(at.height, 3.0);
  }
}

// Adversarial: the same search seeking the worst moves away from the target.
TEST(SweepSpecTest, AdversarialSearchSeeksTheWorst) {
  const SweepSpec spec = LoadSweepSpec(Write("adversarial.json", R"({"format": "irbench.sweep/1", "name": "a",
    "base": {"rig": "theater4", "motion": "wave", "frames": 3}, "mode": "adversarial", "seed": 3,
    "search": {"population": 6, "generations": 4, "elite": 2},
    "axes": [{"camera": "side", "along": {"from": [-3.6, -2.0], "to": [-3.6, 2.0]},
              "height": {"from": 1.0, "to": 3.0}}]})"));
  EXPECT_FALSE(SeeksHigh(LoadSweepSpec(Write("s2.json", R"({"format": "irbench.sweep/1", "name": "s",
    "base": {}, "mode": "search", "search": {"population": 2, "generations": 1},
    "axes": [{"camera": "side", "along": {"from": [-3.6, -2.0], "to": [-3.6, 2.0]}, "height": 2}]})"))));
  EXPECT_TRUE(SeeksHigh(spec));  // the worst arms error: the highest
  const Eigen::Vector3d target(-3.6, 0.0, 2.0);  // the middle: the worst points are at the corners
  DistanceFrom bowl{spec, target, {}};
  const PointMetric metric_of = [&bowl](int i) { return bowl(i); };
  double first = 0, last = 0;
  for (int i = 0; i < 6; ++i) first = std::max(first, *metric_of(i));
  for (int i = 18; i < 24; ++i) last = std::max(last, *metric_of(i));
  EXPECT_GT(last, first);
  EXPECT_GT(last, 0.9 * std::hypot(2.0, 1.0));  // near a corner: 2 m along, 1 m up or down
}

// A pose point's motion: a keyframe file the motion reader takes, standing
// at 0 and holding the point's angles from move_s to move_s + hold_s.
TEST(SweepSpecTest, PosePointIsAKeyframeMotionHoldingItsAngles) {
  const SweepSpec spec = LoadSweepSpec(Write("pose.json", R"({"format": "irbench.sweep/1", "name": "p",
    "base": {"rig": "theater4"}, "mode": "random", "samples": 3, "seed": 5,
    "axes": [{"pose": "arms", "move_s": 0.5, "hold_s": 1.5,
              "joints": {"right_shoulder": [0, {"from": -40, "to": 60}, {"from": 20, "to": 150}],
                         "left_elbow": [0, 0, {"from": -130, "to": 0}]}}]})"));
  const SweepPoint p = PointAt(spec, 2);
  const auto& dims = std::get<PoseAxis>(spec.axes[0].axis).dims;
  ASSERT_EQ(p.at[0].pose.size(), 3u);
  std::map<std::string, double> angle;  // "right_shoulder.z" -> degrees
  for (size_t d = 0; d < dims.size(); ++d) angle[dims[d].Label()] = p.at[0].pose[d];
  ASSERT_EQ(angle.size(), 3u);
  EXPECT_GE(angle["right_shoulder.z"], 20.0);
  EXPECT_LE(angle["right_shoulder.z"], 150.0);
  EXPECT_GE(angle["left_elbow.z"], -130.0);
  EXPECT_LE(angle["left_elbow.z"], 0.0);
  const Scenario sc = PointScenario(spec, p, Dir() / "pose_out");
  EXPECT_EQ(fs::path(sc.render.motion), fs::absolute(Dir() / "pose_out" / "motions" / "p0002.json"));
  const KeyframeMotion motion = LoadKeyframes(sc.render.motion);
  EXPECT_DOUBLE_EQ(motion.Duration(), 2.0);
  const nlohmann::json file = nlohmann::json::parse(std::ifstream(sc.render.motion));
  const nlohmann::json& held = file["keys"][1]["joints"];
  EXPECT_DOUBLE_EQ(held["right_shoulder"][1].get<double>(), angle["right_shoulder.y"]);
  EXPECT_DOUBLE_EQ(held["right_shoulder"][2].get<double>(), angle["right_shoulder.z"]);
  EXPECT_DOUBLE_EQ(held["left_elbow"][2].get<double>(), angle["left_elbow.z"]);
  EXPECT_EQ(file["keys"][2]["joints"], held);
  EXPECT_EQ(file["keys"][0]["joints"]["right_shoulder"], nlohmann::json({0.0, 80.0, 0.0}));  // standing
  // Unknown joints and out-of-range angles are refused naming the field.
  try {
    LoadSweepSpec(Write("pose_bad.json", R"({"format": "irbench.sweep/1", "name": "p", "base": {},
      "axes": [{"pose": "arms", "joints": {"right_knuckle": [0, 0, {"from": 0, "to": 10, "steps": 2}]}}]})"));
    ADD_FAILURE() << "accepted an unknown joint";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "axes[0].joints.right_knuckle");
  }
}

// A pose in the atoms' space: a grid over the listed weights, each point's
// motion a session of the library's `posture` with the point's weights (an
// arm whose weights are all 0 rests), which the motion reader plays as the
// library plays `posture` with those weights.
TEST(SweepSpecTest, AtomPosePointIsAPostureSessionWithItsWeights) {
  const SweepSpec spec = LoadSweepSpec(Write("atoms.json", R"({"format": "irbench.sweep/1", "name": "a",
    "base": {"rig": "theater4", "avatar": "p3"},
    "axes": [{"pose": "arms", "move_s": 0.5, "hold_s": 1.5,
              "atoms": {"right": {"A1": {"from": 0, "to": 1, "steps": 3}, "A3": 0.5},
                        "left": {"A2": {"from": 0, "to": 0.6, "steps": 2}}}}]})"));
  ASSERT_EQ(PointCount(spec), 6);
  const auto& pose = std::get<PoseAxis>(spec.axes[0].axis);
  ASSERT_TRUE(pose.atoms);
  ASSERT_EQ(pose.dims.size(), 2u);
  std::set<std::pair<double, double>> seen;
  for (int i = 0; i < 6; ++i) {
    const SweepPoint p = PointAt(spec, i);
    std::map<std::string, double> w;
    for (size_t d = 0; d < pose.dims.size(); ++d) w[pose.dims[d].Label()] = p.at[0].pose[d];
    seen.insert({w["right.A1"], w["left.A2"]});
    const Scenario sc = PointScenario(spec, p, Dir() / "atoms_out");
    const nlohmann::json file = nlohmann::json::parse(std::ifstream(sc.render.motion));
    EXPECT_EQ(file["format"], "irbench.session/1");
    ASSERT_EQ(file["items"].size(), 1u);
    const nlohmann::json& item = file["items"][0];
    EXPECT_EQ(item["motion"], "posture");
    EXPECT_EQ(item["right"]["A3"], 0.5);
    if (w["right.A1"] > 0) {
      EXPECT_DOUBLE_EQ(item["right"]["A1"].get<double>(), w["right.A1"]);
    } else {
      EXPECT_FALSE(item["right"].contains("A1"));
    }
    if (w["left.A2"] > 0) {
      EXPECT_DOUBLE_EQ(item["left"]["A2"].get<double>(), w["left.A2"]);
    } else {
      EXPECT_EQ(item["left"], "A0");
    }
    // Played by the motion reader as the library plays `posture`.
    const Avatar avatar = irbench::testing::Person("p3");
    const Scene scene = LoadScene(fs::path(IRBENCH_SOURCE_DIR) / "scenes" / "theater.json");
    MotionContext a{&avatar, &scene, StyleFor("p3", 1), {}}, b = a;
    const MotionPtr played = ResolveMotion(sc.render.motion, a, "--motion").motion;
    nlohmann::json params = {{"move_s", 0.5}, {"hold_s", 1.5}, {"right", {{"A1", w["right.A1"]}, {"A3", 0.5}}},
                             {"left", {{"A2", w["left.A2"]}}}};
    const MotionPtr library = BuildLibraryMotion("posture", params, b);
    EXPECT_NEAR(played->Duration(), library->Duration(), 1e-9);
    const double t = 1.2 / a.style.tempo;
    const JointTransforms x = ForwardKinematics(avatar.skeleton, played->At(t));
    const JointTransforms y = ForwardKinematics(avatar.skeleton, library->At(t));
    for (const int j : {kRightWrist, kLeftWrist}) {
      EXPECT_LT((x[j].translation() - y[j].translation()).norm(), 1e-9) << i;
    }
  }
  EXPECT_EQ(seen.size(), 6u);
  // Weights out of 0..1, unknown atoms and arms, and both spaces at once are refused naming the field.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"({"right": {"A1": {"from": 0, "to": 1.5, "steps": 2}}})", "axes[0].atoms.right.A1"},
      {R"({"right": {"A5": {"from": 0, "to": 1, "steps": 2}}})", "axes[0].atoms.right.A5"},
      {R"({"middle": {"A1": {"from": 0, "to": 1, "steps": 2}}})", "axes[0].atoms.middle"},
      {R"({"right": {"A1": 0.5}})", "axes[0].atoms"},
      {R"({"right": {"A1": {"from": 0, "to": 1, "steps": 2}}}, "hold_s": 120)", "axes[0].hold_s"}};
  for (const auto& [atoms, field] : bad) {
    try {
      LoadSweepSpec(Write("atoms_bad.json", R"({"format": "irbench.sweep/1", "name": "a", "base": {},
        "axes": [{"pose": "arms", "atoms": )" + atoms + "}]}"));
      ADD_FAILURE() << atoms;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), field) << atoms;
    }
  }
  try {
    LoadSweepSpec(Write("atoms_bad.json", R"({"format": "irbench.sweep/1", "name": "a", "base": {},
      "axes": [{"pose": "arms", "atoms": {"right": {"A1": 1}}, "joints": {"right_elbow": [0, 0, 0]}}]})"));
    ADD_FAILURE() << "accepted both spaces";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "axes[0]");
  }
}

// Each bad spec: InputError naming the spec file and the field.
// The rig axes: each point's rig keeps the cameras its `rig.cameras` value
// names, in the rig's order; at twice the resolution a world point lands
// where the base camera's pixel centre lands, scaled ((u + 0.5) 2 - 0.5);
// a zoom of 0.8 brings it towards the principal point by 0.8; the lens
// distortion is the value's.
TEST(SweepSpecTest, RigAxesMakeEachPointsRig) {
  const SweepSpec spec = LoadSweepSpec(Write("rig_axes.json", R"({"format": "irbench.sweep/1", "name": "r",
    "base": {"rig": "theater4", "motion": "wave", "frames": 3},
    "axes": [{"key": "rig.cameras", "values": [["side", "front_left"], 3]},
             {"key": "rig.resolution", "values": [[320, 240], [640, 480]]},
             {"key": "rig.focal_scale", "values": [1, 0.8]},
             {"key": "rig.dist", "values": [[0, 0, 0, 0, 0]]}]})"));
  ASSERT_EQ(PointCount(spec), 8);
  const Rig base = LoadRig(fs::path(IRBENCH_SOURCE_DIR) / "rigs" / "theater4.json");
  Rig undistorted = base;
  for (Camera& c : undistorted.cameras) c.dist = {0, 0, 0, 0, 0};
  const Eigen::Vector3d chest(0.1, -0.2, 1.2);
  for (int i = 0; i < PointCount(spec); ++i) {
    const SweepPoint p = PointAt(spec, i);
    const Rig rig = LoadRig(PointScenario(spec, p, Dir()).render.rig);
    const bool named = p.at[0].value.is_array();
    ASSERT_EQ(rig.cameras.size(), named ? 2u : 3u) << i;
    if (named) {
      EXPECT_EQ(rig.cameras[0].name, "front_left");  // the rig's order
      EXPECT_EQ(rig.cameras[1].name, "side");
    }
    const double scale = p.at[1].value[0].get<int>() / 320.0, zoom = p.at[2].value.get<double>();
    for (const Camera& c : rig.cameras) {
      const Camera* b = nullptr;
      for (const Camera& u : undistorted.cameras) {
        if (u.name == c.name) b = &u;
      }
      ASSERT_NE(b, nullptr) << c.name;
      EXPECT_EQ(c.width, static_cast<int>(320 * scale));
      EXPECT_EQ(c.height, static_cast<int>(240 * scale));
      for (const double k : c.dist) EXPECT_EQ(k, 0.0);
      const Eigen::Vector2d principal((b->cx + 0.5) * scale - 0.5, (b->cy + 0.5) * scale - 0.5);
      const Eigen::Vector2d expected = principal + zoom * ((b->Project(chest).array() + 0.5) * scale - 0.5 -
                                                           principal.array()).matrix();
      EXPECT_LT((c.Project(chest) - expected).norm(), 1e-6) << i << " " << c.name;
    }
  }
}

// Pan and tilt as a tripod head turns them: the view's azimuth about +z
// (the side camera's up) grows by the pan, its elevation by the tilt, and the
// horizon stays level; against spherical coordinates, through the rig file.
TEST(SweepSpecTest, AimRangesPanAndTiltTheCameraLikeATripodHead) {
  const SweepSpec spec = LoadSweepSpec(Write("aim.json", R"({"format": "irbench.sweep/1", "name": "a",
    "base": {"rig": "theater4", "motion": "wave", "frames": 3},
    "axes": [{"camera": "side", "along": {"from": [-3.6, -1.0], "to": [-3.6, 1.0], "steps": 2}, "height": 2.2,
              "look_at": [0, 0, 1.1], "pan": {"from": -20, "to": 30, "steps": 3}, "tilt": {"from": -10, "to": 5, "steps": 2}},
             {"key": "rig.dist", "values": [[0, 0, 0, 0, 0]]}]})"));
  ASSERT_EQ(PointCount(spec), 2 * 3 * 2);
  std::set<std::tuple<double, double, double>> seen;
  for (int i = 0; i < PointCount(spec); ++i) {
    const SweepPoint p = PointAt(spec, i);
    const AxisValue& at = p.at[0];
    seen.insert({at.along, at.pan, at.tilt});
    const nlohmann::json c = PointCoordinates(spec, p);
    EXPECT_EQ(c["side.pan"].get<double>(), at.pan);
    EXPECT_EQ(c["side.tilt"].get<double>(), at.tilt);
    const Rig rig = LoadRig(PointScenario(spec, p, Dir()).render.rig);
    const Camera* side = nullptr;
    for (const Camera& cam : rig.cameras) {
      if (cam.name == "side") side = &cam;
    }
    ASSERT_NE(side, nullptr);
    const Eigen::Vector3d to = Eigen::Vector3d(0, 0, 1.1) - at.position;
    const double azimuth = std::atan2(to.y(), to.x()) + at.pan * M_PI / 180;
    const double elevation = std::asin(to.z() / to.norm()) + at.tilt * M_PI / 180;
    const Eigen::Vector3d view(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                               std::sin(elevation));
    // The view's ray lands on the principal point ...
    EXPECT_LT((side->Project(at.position + 2 * view) - Eigen::Vector2d(side->cx, side->cy)).norm(), 1e-6) << i;
    // ... and a point beside it, level with it, on the principal row.
    const Eigen::Vector3d left(-std::sin(azimuth), std::cos(azimuth), 0);
    const Eigen::Vector2d beside = side->Project(at.position + 2 * view + 0.3 * left);
    EXPECT_NEAR(beside.y(), side->cy, 1e-6) << i;
    EXPECT_LT(beside.x(), side->cx) << i;  // left is left in the image
  }
  EXPECT_EQ(seen.size(), 12u);  // every along x pan x tilt once
}

TEST(SweepSpecTest, SensorKnobAxesSetEveryCamerasKnobOnThePointsPreset) {
  const SweepSpec spec = LoadSweepSpec(Write("knob_axes.json", R"({"format": "irbench.sweep/1", "name": "k",
    "base": {"rig": "theater4", "motion": "wave", "frames": 3},
    "axes": [{"key": "sensor", "values": ["thesis", "clean"]},
             {"key": "sensor.flicker.mains_depth", "values": [0.0, 0.3]},
             {"key": "sensor.sensor.bit_depth", "values": [10]},
             {"key": "rig.cameras", "values": [3]}]})"));
  ASSERT_EQ(PointCount(spec), 4);
  for (int i = 0; i < PointCount(spec); ++i) {
    const SweepPoint p = PointAt(spec, i);
    const RenderInputs in = LoadRenderInputs(PointScenario(spec, p, Dir()).render);
    const std::string preset = p.at[0].value.get<std::string>();
    const SensorSetup expected = *SensorPreset(preset);
    ASSERT_EQ(in.sensors.size(), 3u) << i;  // the knobs reach the cameras rig.cameras keeps
    for (size_t c = 0; c < in.sensors.size(); ++c) {
      EXPECT_EQ(in.sensors[c].preset, preset) << i;
      EXPECT_EQ(in.sensors[c].flicker.mains_depth, p.at[1].value.get<double>()) << i << " " << c;
      EXPECT_EQ(in.sensors[c].sensor.bit_depth, 10) << i << " " << c;
      // Knobs no axis names stay the preset's.
      EXPECT_EQ(in.sensors[c].sensor.full_well_e, expected.sensor.full_well_e) << i;
      EXPECT_EQ(in.sensors[c].flicker.mains_hz, expected.flicker.mains_hz) << i;
      EXPECT_EQ(in.sensors[c].optics.f_number, expected.optics.f_number) << i;
      EXPECT_TRUE(in.sensor_active[c]) << i << " " << c;  // a knob on `clean` models a sensor
    }
  }
}

// The specs shipped in ci/sweeps/ load (their avatars, motions, rigs and
// values still exist and pass the checks), and each has points.
TEST(SweepSpecTest, ShippedSpecsLoad) {
  int specs = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(IRBENCH_SOURCE_DIR) / "ci" / "sweeps")) {
    if (entry.path().extension() != ".json") continue;
    ++specs;
    try {
      const SweepSpec spec = LoadSweepSpec(entry.path());
      EXPECT_EQ(spec.name, entry.path().stem().string());
      EXPECT_GT(PointCount(spec), 0) << entry.path();
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_GE(specs, 5);
}

TEST(SweepSpecTest, BadSpecsNameTheFileAndField) {
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"unknown_axis", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "lens", "values": [1]}]})", "axes[0].key"},
      {"empty_values", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "avatar", "values": []}]})", "axes[0].values"},
      {"bad_value", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "avatar", "values": ["p1", "nobody"]}]})", "axes[0].values[1]"},
      {"empty_range", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"camera": "side", "along": {"from": [-3, 0], "to": [-3, 1], "steps": 2},
                   "height": {"from": 2, "to": 2, "steps": 3}}]})", "axes[0].height"},
      {"outside", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"camera": "side", "along": {"from": [-3, 0], "to": [-9, 0], "steps": 2}, "height": 2}]})",
       "axes[0].along"},
      {"no_camera", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"camera": "back", "along": {"from": [-3, 0], "to": [-3, 1], "steps": 2}, "height": 2}]})",
       "axes[0].camera"},
      {"metric", R"({"format": "irbench.sweep/1", "name": "b", "base": {}, "metric": "speed",
         "axes": [{"key": "seed", "values": [1]}]})", "metric"},
      {"no_axes", R"({"format": "irbench.sweep/1", "name": "b", "base": {}, "axes": []})", "axes"},
      {"samples", R"({"format": "irbench.sweep/1", "name": "b", "base": {}, "mode": "random", "samples": 0,
         "axes": [{"key": "seed", "values": [1]}]})", "samples"},
      {"search_values", R"({"format": "irbench.sweep/1", "name": "b", "base": {}, "mode": "search",
         "search": {"population": 4, "generations": 2}, "axes": [{"key": "seed", "values": [1]}]})", "axes[0]"},
      {"base_key", R"({"format": "irbench.sweep/1", "name": "b", "base": {"lens": 2},
         "axes": [{"key": "seed", "values": [1]}]})", "base.lens"},
      {"one_camera", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "rig.cameras", "values": [3, ["front_left"]]}]})", "axes[0].values[1]"},
      {"unknown_camera", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "rig.cameras", "values": [["front_left", "back"]]}]})", "axes[0].values[0]"},
      {"too_many_cameras", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "rig.cameras", "values": [5]}]})", "axes[0].values[0]"},
      {"pan_too_far", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"camera": "side", "along": {"from": [-3, 0], "to": [-3, 1], "steps": 2}, "height": 2,
                   "pan": {"from": -200, "to": 0, "steps": 2}}]})", "axes[0].pan"},
      {"tilt_to_the_ceiling", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"camera": "side", "along": {"from": [-3, 0], "to": [-3, 1], "steps": 2}, "height": 2,
                   "look_at": [0, 0, 3], "tilt": {"from": 0, "to": 80, "steps": 2}}]})", "axes[0].tilt"},
      {"tilt_past_straight_down_mid_line", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"camera": "side", "along": {"from": [-2, -1.5], "to": [2, -1.5], "steps": 4}, "height": 3,
                   "look_at": [0, 0, 1], "tilt": {"from": -40, "to": 0, "steps": 2}}]})", "axes[0].tilt"},
      {"knobs_bound_together", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "sensor.sensor.tone_lift", "values": [0.1, 0.5]},
                  {"key": "sensor.sensor.tone_ceiling_drop", "values": [0.3, 0.5]}]})", "axes[1].values[1]"},
      {"knob_without_group", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "sensor.mains_depth", "values": [0.1]}]})", "axes[0].key"},
      {"unknown_knob", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "sensor.flicker.depth", "values": [0.1]}]})", "axes[0].values[0]"},
      {"unknown_group", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "sensor.lens.f_number", "values": [2]}]})", "axes[0].values[0]"},
      {"knob_out_of_range", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "sensor.flicker.mains_depth", "values": [0.1, 1.5]}]})", "axes[0].values[1]"},
      {"knob_wrong_type", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "sensor.sensor.bit_depth", "values": [10, 10.5]}]})", "axes[0].values[1]"},
      {"knob_text", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "sensor.sensor.noise", "values": ["off"]}]})", "axes[0].values[0]"},
      {"resolution", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "rig.resolution", "values": [[640, 480], [4, 3]]}]})", "axes[0].values[1]"},
      {"zoom", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "rig.focal_scale", "values": [0]}]})", "axes[0].values[0]"},
      {"dist", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "rig.dist", "values": [[0.1, 0.0, 0.0]]}]})", "axes[0].values[0]"},
      {"dist_folds", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"key": "rig.dist", "values": [[0, 0, 0, 0, 0], [-90, 0, 0, 0, 0]]}]})", "axes[0].values[1]"},
      {"placed_left_out", R"({"format": "irbench.sweep/1", "name": "b", "base": {},
         "axes": [{"camera": "side", "along": {"from": [-3, 0], "to": [-3, 1], "steps": 2}, "height": 2},
                  {"key": "rig.cameras", "values": [["front_left", "front_right"]]}]})", "axes[0].camera"},
  };
  for (const auto& [name, text, field] : cases) {
    const fs::path file = Write(name + ".json", text);
    try {
      LoadSweepSpec(file);
      ADD_FAILURE() << name << ": accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), file.string()) << name << ": " << e.what();
      EXPECT_EQ(e.field(), field) << name << ": " << e.what();
    }
  }
}

}  // namespace
}  // namespace irbench
