// Unit tests of the pose stage's parts on silhouettes rasterised from the
// ellipsoid model itself (the closed loop on rendered skinned avatars is
// tests/pose_closed_loop_test.cc).

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>
#include <opencv2/imgproc.hpp>
#include <unistd.h>

#include "common/cancel.h"
#include "common/error.h"
#include "sim/camera/rig.h"
#include "tracker/pose/body_calibration.h"
#include "tracker/pose/hull_legs.h"
#include "tracker/pose/icp.h"
#include "tracker/pose/particle_filter.h"
#include "tracker/pose/observation.h"
#include "tracker/pose/pointing.h"
#include "tracker/pose/pose_tracker.h"

namespace irbench {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

std::vector<Camera> PinholeRig() {
  std::vector<Camera> cams = LoadRig(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json").cameras;
  for (Camera& c : cams) c.dist = {};  // model silhouettes are drawn in ideal pixels
  return cams;
}

double Iou(const cv::Mat& a, const cv::Mat& b) {
  const int inter = cv::countNonZero(a & b), uni = cv::countNonZero(a | b);
  return uni ? static_cast<double>(inter) / uni : 0.0;
}

TEST(Observation, OverlapRatioEqualsTheRasterisedIou) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    BodyPose truth = ScarecrowPose(shape, Vector2d(0.3 * u(rng), 0.3 * u(rng)), u(rng));
    BodyPose guess = truth;
    guess.dof[kDofX] += 0.1 * u(rng);
    guess.dof[kDofRightShoulderZenith] += 0.8 * u(rng);
    const Camera& cam = cams[trial % cams.size()];
    const auto P = ProjectionMatrix(cam);
    const cv::Size size(cam.width, cam.height);
    const cv::Mat silhouette = RasteriseEllipses(ProjectBody(cam, P, PoseBody(shape, truth)), size);
    const std::vector<ImageEllipse> model = ProjectBody(cam, P, PoseBody(shape, guess));
    cv::Mat map1, map2;
    MakeUndistortMaps(cam, &map1, &map2);
    const SilhouetteView full(cam, silhouette, map1, map2, 1.0);
    EXPECT_NEAR(full.OverlapRatio(model), Iou(silhouette, RasteriseEllipses(model, size)), 1e-12);
    // Half resolution: the ellipses scaled about the pixel grid against the
    // area-downsampled silhouette.
    const SilhouetteView half(cam, silhouette, map1, map2, 0.5);
    std::vector<ImageEllipse> model_half;
    for (const ImageEllipse& e : model) model_half.push_back(e.Scaled(0.5));
    EXPECT_NEAR(half.OverlapRatio(model), Iou(half.level(), RasteriseEllipses(model_half, half.level().size())),
                1e-12);
  }
}

TEST(Icp, QuaternionAverageAlignsSignsFirst) {
  const Eigen::Quaterniond a(Eigen::AngleAxisd(0.2, Vector3d::UnitZ()));
  const Eigen::Quaterniond b(Eigen::AngleAxisd(0.6, Vector3d::UnitZ()));
  Eigen::Quaterniond minus_b = b;
  minus_b.coeffs() = -b.coeffs();
  const Eigen::AngleAxisd mean(AverageQuaternions({a, minus_b}));
  EXPECT_NEAR(mean.angle(), 0.4, 1e-12);
  EXPECT_GT(mean.axis().dot(Vector3d::UnitZ()), 1 - 1e-12);
}

std::vector<IcpView> ModelViews(const std::vector<Camera>& cams, const BodyShape& shape, const BodyPose& truth) {
  std::vector<IcpView> views;
  for (const Camera& cam : cams) {
    const auto P = ProjectionMatrix(cam);
    const cv::Mat s = RasteriseEllipses(ProjectBody(cam, P, PoseBody(shape, truth)), cv::Size(cam.width, cam.height));
    views.push_back({cam, P, OutlinePolygons(s)});
  }
  return views;
}

double ArmAngleDeg(const BodyShape& shape, const BodyPose& a, const BodyPose& b, int from, int to) {
  const PosedBody pa = PoseBody(shape, a), pb = PoseBody(shape, b);
  const Vector3d da = (pa.joints[to] - pa.joints[from]).normalized();
  const Vector3d db = (pb.joints[to] - pb.joints[from]).normalized();
  return std::acos(std::clamp(da.dot(db), -1.0, 1.0)) * 180 / M_PI;
}

TEST(Icp, PullsAPerturbedArmAndBodyBackTowardsTheOutlines) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  BodyPose truth = ScarecrowPose(shape, Vector2d(0.1, -0.2), 0.3);
  truth.dof[kDofRightShoulderAzimuth] = 0.6;  // forward and out
  truth.dof[kDofRightElbowZenith] = 0.5;
  const std::vector<IcpView> views = ModelViews(cams, shape, truth);
  BodyPose start = truth;
  start.dof[kDofRightShoulderZenith] -= 0.30;  // 17 deg lower
  start.dof[kDofLeftShoulderZenith] += 0.25;
  start.dof[kDofX] += 0.05;
  IcpOptions options;
  options.iterations = 3;
  const BodyPose refined = RefineIcp(shape, start, views, options);
  const double before = ArmAngleDeg(shape, start, truth, kModelRightShoulder, kModelRightElbow);
  const double after = ArmAngleDeg(shape, refined, truth, kModelRightShoulder, kModelRightElbow);
  EXPECT_LT(after, 0.35 * before) << before << " -> " << after;
  const double left_before = ArmAngleDeg(shape, start, truth, kModelLeftShoulder, kModelLeftElbow);
  const double left_after = ArmAngleDeg(shape, refined, truth, kModelLeftShoulder, kModelLeftElbow);
  EXPECT_LT(left_after, 0.35 * left_before) << left_before << " -> " << left_after;
  EXPECT_LT(std::abs(refined.dof[kDofX] - truth.dof[kDofX]), 0.02);
}

// Synthetic frame features from the model itself: silhouettes, the hull's
// placement and 3D arm axis points along the true arms.
// `arms`: which arms' 3D axis points the front end reports (right, left); a
// real front end misses an arm held against the torso.
FrameFeatures ModelFeatures(const std::vector<Camera>& cams, const BodyShape& shape, const BodyPose& truth, int frame,
                            std::array<bool, 2> arms = {true, true}) {
  FrameFeatures f;
  f.frame = frame;
  const PosedBody body = PoseBody(shape, truth);
  for (const Camera& cam : cams) {
    CameraFeatures cf;
    cf.silhouette = RasteriseEllipses(ProjectBody(cam, ProjectionMatrix(cam), body), cv::Size(cam.width, cam.height));
    f.cameras.push_back(cf);
  }
  BodyPlacement place;
  place.root = body.joints[kModelRoot];
  place.top_m = shape.height_m;
  place.volume_m3 = 0.07;
  f.placement = place;
  for (int tip : {kModelRightHandTip, kModelLeftHandTip}) {
    if (!arms[tip == kModelRightHandTip ? 0 : 1]) continue;
    const Vector3d shoulder = body.joints[tip - 3], elbow = body.joints[tip - 2], hand = body.joints[tip];
    for (double t = 0.2; t <= 1.0; t += 0.2) {
      AxisPoint3d a;
      a.part = BodyPart::kArm;
      a.p_in_world = shoulder + t * (elbow - shoulder);
      f.axis3d.push_back(a);
      a.p_in_world = elbow + t * (hand - elbow);
      f.axis3d.push_back(a);
    }
  }
  return f;
}

// An empty voxel grid over the stage: 2 x 2 x 2.2 m from (-1, -1, 0), 2 cm voxels.
VoxelHull EmptyStageHull() {
  VoxelHull hull;
  hull.origin_m = Vector3d(-1, -1, 0);
  hull.voxel_size_m = 0.02;
  hull.nx = hull.ny = 100;
  hull.nz = 110;
  hull.occupied.assign(size_t(hull.nx) * hull.ny * hull.nz, 0);
  return hull;
}

// Marks occupied the voxels whose centres `inside` holds.
void FillHull(VoxelHull* hull, const std::function<bool(const Vector3d&)>& inside) {
  for (int z = 0; z < hull->nz; ++z) {
    for (int y = 0; y < hull->ny; ++y) {
      for (int x = 0; x < hull->nx; ++x) {
        if (inside(hull->VoxelCenter(x, y, z))) hull->occupied[hull->Index(x, y, z)] = 1;
      }
    }
  }
}

double WorstJointError(const PosedBody& a, const PosedBody& b) {
  double worst = 0;
  for (int j = 0; j < kModelJointCount; ++j) worst = std::max(worst, (a.joints[j] - b.joints[j]).norm());
  return worst;
}

// The head joint (the pointing rays' origin) is the voxel hull's head where
// every camera sees the model's head, and the model's own where a camera has
// lost it: such a view has carved the head from the hull too.
TEST(PoseTracker, TakesTheHeadFromTheHullOnlyWhereEveryViewSeesIt) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  PoseTrackerOptions options;
  options.seed = 5;
  PoseTracker tracker(cams, {}, options);
  const BodyPose truth = StandingPose(shape, Vector2d(0.1, 0.2), 0.0);
  const PosedBody body = PoseBody(shape, truth);
  for (int f = 0; f < 10; ++f) ASSERT_TRUE(tracker.Step(ModelFeatures(cams, shape, truth, f), 1.0 / 30).tracking);
  // A hull whose head is a ball 3 cm to the side of the model's.
  VoxelHull hull = EmptyStageHull();
  const Vector3d ball = body.joints[kModelHead] + Vector3d(0.03, 0, 0);
  FillHull(&hull, [&](const Vector3d& c) { return (c - ball).norm() < 0.1; });
  FrameFeatures seen = ModelFeatures(cams, shape, truth, 10);
  seen.voxels = hull;
  PoseEstimate e = tracker.Step(seen, 1.0 / 30);
  ASSERT_TRUE(e.tracking);
  const Vector3d model_head = PoseBody(e.shape, e.pose).joints[kModelHead];
  EXPECT_NEAR(e.body.joints[kModelHead].x(), ball.x(), 0.011);  // the ball's centroid, within half a voxel
  EXPECT_GT((e.body.joints[kModelHead] - model_head).norm(), 0.015);
  ASSERT_TRUE(e.pointing[0]);
  EXPECT_NEAR((e.pointing[0]->origin - e.body.joints[kModelHead]).norm(), 0.0, 1e-12);

  // One camera loses the head.
  FrameFeatures lost = ModelFeatures(cams, shape, truth, 11);
  lost.voxels = hull;
  const Eigen::Vector3d p = ProjectionMatrix(cams[0]) * body.joints[kModelHead].homogeneous();
  cv::circle(lost.cameras[0].silhouette, cv::Point2d(p.x() / p.z(), p.y() / p.z()), 25, cv::Scalar(0), cv::FILLED);
  e = tracker.Step(lost, 1.0 / 30);
  ASSERT_TRUE(e.tracking);
  EXPECT_NEAR((e.body.joints[kModelHead] - PoseBody(e.shape, e.pose).joints[kModelHead]).norm(), 0.0, 1e-12);
}

// The model's arms take the thickness the 3D arm axis points measure (a
// jacket's sleeves): their median diameter over arm_reference_diameter
// times the height, never thinner than bare arms nor past
// max_arm_thickness, fixed once arm_thickness_frames frames have given arm
// points, and measured afresh for the next user.
TEST(PoseTracker, ThickensTheArmsToTheAxisPointsDiameters) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  const BodyPose truth = StandingPose(shape, Vector2d(0.1, 0.2), 0.0);
  PoseTrackerOptions options;
  options.seed = 3;
  options.arm_thickness_min_points = 40;
  const double reference = options.arm_reference_diameter * shape.height_m;
  // Tracks 12 frames whose arm points (20 a frame; ModelFeatures) are
  // diameter(frame, point) across.
  auto track = [&](PoseTracker& tracker, const std::function<double(int, int)>& diameter) {
    PoseEstimate e;
    for (int f = 0; f < 12; ++f) {
      FrameFeatures features = ModelFeatures(cams, shape, truth, f);
      for (size_t i = 0; i < features.axis3d.size(); ++i) features.axis3d[i].diameter_m = diameter(f, int(i));
      e = tracker.Step(features, 1.0 / 30);
      EXPECT_TRUE(e.tracking) << f;
      EXPECT_NEAR(e.shape.height_m, shape.height_m, 1e-9) << f;
    }
    return e;
  };
  auto thickness = [&](const std::function<double(int, int)>& diameter, const PoseTrackerOptions& o) {
    PoseTracker tracker(cams, {}, o);
    return track(tracker, diameter).shape.arm_thickness;
  };
  {
    PoseTracker tracker(cams, {}, options);
    PoseEstimate e = tracker.Step(ModelFeatures(cams, shape, truth, 0), 1.0 / 30);
    EXPECT_EQ(e.shape.arm_thickness, 1.0) << "no diameters yet";
    e = track(tracker, [&](int, int) { return 1.2 * reference; });
    EXPECT_NEAR(e.shape.arm_thickness, 1.2, 1e-9);
    const BodyShape expected = BodyShape::FromHeight(e.shape.height_m, e.shape.girth, 1.2);
    for (int seg = 0; seg < kSegmentCount; ++seg) {
      EXPECT_NEAR((e.shape.radii[seg] - expected.radii[seg]).norm(), 0, 1e-9) << BodySegmentName(seg);
    }
  }
  EXPECT_EQ(thickness([&](int, int) { return 0.5 * reference; }, options), 1.0);
  EXPECT_EQ(thickness([&](int, int) { return 3.0 * reference; }, options), options.max_arm_thickness);
  // Points without a diameter measure nothing: two in three here, which
  // would make the median 0 (and the thickness 1) if they counted.
  EXPECT_NEAR(thickness([&](int, int i) { return i % 3 == 0 ? 1.2 * reference : 0.0; }, options), 1.2, 1e-9);
  // Three frames of thick arms, then thin ones: the thin ones come too late.
  // Then the user leaves, and the next one's arms are measured afresh.
  PoseTrackerOptions three = options;
  three.arm_thickness_frames = 3;
  PoseTracker tracker(cams, {}, three);
  EXPECT_NEAR(track(tracker, [&](int f, int) { return f < 3 ? 1.2 * reference : 0.9 * reference; }).shape.arm_thickness,
              1.2, 1e-9);
  FrameFeatures empty = ModelFeatures(cams, shape, truth, 12);
  empty.placement.reset();
  EXPECT_FALSE(tracker.Step(empty, 1.0 / 30).tracking);
  EXPECT_NEAR(track(tracker, [&](int, int) { return 1.1 * reference; }).shape.arm_thickness, 1.1, 1e-9);
}

// Thesis 6.1.1's per-user proportion: the shoulder width is measured where
// the arms held straight forward cross the line through the model's
// shoulders. A narrow-shouldered and a broad-shouldered user of the same
// height are each configured within 1 cm of their own after standing at rest
// (the arms' axis points lost against the body) and then pointing forward;
// arms held out sideways (no crossing) measure nothing, and the fixed
// proportion stays. The model's arm points lie on its bones, so the girth's
// bias is off (shoulder_girth_bias_m 0) but in the last case, which takes
// it off the crossings.
TEST(PoseTracker, ConfiguresTheShoulderWidthFromStraightArms) {
  const std::vector<Camera> cams = PinholeRig();
  for (const double width : {0.9, 1.14, 1.0}) {
    const bool biased = width == 1.0;
    for (const bool sideways : {false, true}) {
      if (biased && sideways) continue;
      const BodyShape shape = BodyShape::FromHeight(1.75, 1.0, 1.0, width);
      const double yaw = 0.3;
      const BodyPose rest = StandingPose(shape, Vector2d(0.1, 0.2), yaw);
      BodyPose held = sideways ? ScarecrowPose(shape, Vector2d(0.1, 0.2), yaw) : rest;
      if (!sideways) {
        const Vector2d f = FacingDirection(yaw);
        const Vector3d forward = Vector3d(f.x(), f.y(), -0.2).normalized();
        SetArmDirections(shape, &held, kRightUpperArm, forward, forward);
        SetArmDirections(shape, &held, kLeftUpperArm, forward, forward);
      }
      PoseTrackerOptions options;
      options.seed = 4;
      options.shoulder_girth_bias_m = biased ? 0.05 : 0.0;
      options.shoulder_bias_girth = 0.9;
      PoseTracker tracker(cams, {}, options);
      PoseEstimate e;
      for (int f = 0; f < 50; ++f) {
        // At rest the arms' axis points are lost against the body, as a
        // real front end loses them.
        const bool at_rest = f < 20;
        e = tracker.Step(ModelFeatures(cams, shape, at_rest ? rest : held, f, {!at_rest, !at_rest}), 1.0 / 30);
        ASSERT_TRUE(e.tracking) << f;
        if (at_rest) {
          EXPECT_EQ(e.shape.shoulder_width, 1.0) << "no arm points, no measurement";
        }
      }
      const double bias = biased ? 0.05 * (std::clamp(e.shape.girth, 1.2, 1.8) - 0.9) : 0.0;
      const double expected = sideways ? 0.105 * e.shape.height_m : shape.shoulder_offset_m - bias;
      if (biased) EXPECT_GE(bias, 0.014);
      EXPECT_NEAR(2 * e.shape.shoulder_offset_m, 2 * expected, 0.01) << width << (sideways ? " sideways" : "");
      if (!sideways && !biased) {
        const PosedBody body = PoseBody(shape, held);
        EXPECT_LT((e.body.joints[kModelRightShoulder] - body.joints[kModelRightShoulder]).norm(), 0.03) << width;
        EXPECT_LT((e.body.joints[kModelLeftShoulder] - body.joints[kModelLeftShoulder]).norm(), 0.03) << width;
      }
    }
  }
}

// One arm's crossing with the shoulders' line, against the geometry: a
// straight arm from a shoulder 0.2 m right of the centre gives 0.2; a bent
// one, one held sideways, one too short or one passing far from the
// shoulders' line gives nothing.
TEST(PoseTracker, ShoulderOffsetFromArmIsWhereAStraightArmCrossesTheShoulders) {
  const Vector3d centre(0.1, 0.2, 1.4), lateral = Vector3d(1, 1, 0).normalized();
  const Vector3d forward = Vector3d(-1, 1, 0).normalized(), up(0, 0, 1);
  const Vector3d shoulder = centre + 0.2 * lateral;
  auto arm = [](const Vector3d& from, const Vector3d& dir, double length) {
    std::vector<Vector3d> points;
    for (double t = 0.02; t <= length; t += 0.04) points.push_back(from + t * dir);
    return points;
  };
  const Vector3d model_shoulder = centre + 0.18 * lateral;  // the model's, 2 cm off
  auto offset = [&](const std::vector<Vector3d>& points, bool left = false) {
    return ShoulderOffsetFromArm(points, model_shoulder, centre, lateral, left);
  };
  ASSERT_TRUE(offset(arm(shoulder, forward, 0.7)));
  EXPECT_NEAR(*offset(arm(shoulder, forward, 0.7)), 0.2, 1e-9);
  EXPECT_NEAR(*offset(arm(shoulder, (forward + up).normalized(), 0.7)), 0.2, 1e-9);
  EXPECT_NEAR(*offset(arm(shoulder, forward, 0.7), true), -0.2, 1e-9);
  EXPECT_FALSE(offset(arm(shoulder, lateral, 0.7)));                           // held sideways
  EXPECT_FALSE(offset(arm(shoulder, forward, 0.4)));                           // too short
  EXPECT_FALSE(offset(arm(shoulder + Vector3d(0, 0, 0.1), forward, 0.7)));     // 10 cm above the line
  std::vector<Vector3d> bent = arm(shoulder, forward, 0.3);
  for (const Vector3d& p : arm(shoulder + 0.3 * forward, up, 0.4)) bent.push_back(p);
  EXPECT_FALSE(offset(bent));
}

TEST(PoseTracker, ArmThicknessAndShoulderOptionsAreChecked) {
  PoseTrackerOptions options;
  EXPECT_NO_THROW(options.Check());
  options.arm_thickness_frames = 0;  // off
  options.max_arm_thickness = 1.0;   // never thicker
  options.arm_thickness_min_points = 1;
  EXPECT_NO_THROW(options.Check());
  for (auto bad : std::vector<std::function<void(PoseTrackerOptions&)>>{
           [](PoseTrackerOptions& o) { o.arm_thickness_frames = -1; },
           [](PoseTrackerOptions& o) { o.arm_thickness_min_points = 0; },
           [](PoseTrackerOptions& o) { o.arm_reference_diameter = 0; },
           [](PoseTrackerOptions& o) { o.max_arm_thickness = 0.9; },
           [](PoseTrackerOptions& o) { o.shoulder_girth_bias_m = -0.01; },
           [](PoseTrackerOptions& o) { o.shoulder_girth_bias_m = std::nan(""); },
           [](PoseTrackerOptions& o) { o.shoulder_bias_girth = 0.1; }}) {
    PoseTrackerOptions o;
    bad(o);
    EXPECT_THROW(o.Check(), InputError);
  }
}

// The tracker (seed `seed`) follows a model raising its arm, then its
// particles are scattered: the frames it takes to find the root again.
int FramesToRecoverAfterRaisingAnArm(uint64_t seed) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  PoseTrackerOptions options;
  options.seed = seed;
  PoseTracker tracker(cams, {}, options);
  std::vector<double> errors;
  BodyPose truth = StandingPose(shape, Vector2d(0.2, 0.1), 0.0);
  PoseEstimate e;
  for (int f = 0; f < 30; ++f) {
    truth.dof[kDofRightShoulderAzimuth] = M_PI / 2;                        // forward
    truth.dof[kDofRightShoulderZenith] = 0.15 + (M_PI / 2 - 0.15) * f / 20.0;  // raising to horizontal
    if (f > 20) truth.dof[kDofRightShoulderZenith] = M_PI / 2;
    truth.dof[kDofX] = 0.2 + 0.005 * f;
    e = tracker.Step(ModelFeatures(cams, shape, truth, f), 1.0 / 30);
    EXPECT_TRUE(e.tracking) << f;
    if (!e.tracking) return -1;
    if (f >= 5) errors.push_back(WorstJointError(e.body, PoseBody(shape, truth)));
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.05) << "median worst-joint error";

  // Scattered particles (thesis 6.6: recovery in 2-3 frames).
  tracker.Scatter();
  int recovered_after = -1;
  for (int f = 0; f < 6 && recovered_after < 0; ++f) {
    e = tracker.Step(ModelFeatures(cams, shape, truth, 30 + f), 1.0 / 30);
    if (e.tracking && (e.body.joints[kModelRoot] - PoseBody(shape, truth).joints[kModelRoot]).norm() < 0.05) {
      recovered_after = f + 1;
    }
  }
  // An empty stage: no placement, no tracking.
  FrameFeatures empty = ModelFeatures(cams, shape, truth, 40);
  empty.placement.reset();
  EXPECT_FALSE(tracker.Step(empty, 1.0 / 30).tracking);
  return recovered_after;
}

TEST(PoseTracker, FollowsAModelRaisingItsArmAndRecoversFromScattering) {
  // Thesis 6.6: recovery in 2-3 frames. Over tracker seeds 1-6 every run
  // recovers, within 3 frames in 5 of them (seed 4 took 3 frames before
  // the elbows' backward cap and takes 5 with it; seeds 1-10: 1 frame in
  // 8, 3 in one, 5 in one).
  int within_three = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const int frames = FramesToRecoverAfterRaisingAnArm(seed);
    EXPECT_GE(frames, 1) << "seed " << seed;
    if (frames >= 1 && frames <= 3) ++within_three;
  }
  EXPECT_GE(within_three, 5);
}

// A camera aimed so high that its image cuts off the feet of a person at the
// stage's centre (found by sweeping the side camera's tilt: 12 degrees up
// kept every frame "partial", nothing tracked) is left out of the in-view
// test; the others still decide it, and the tracker tracks.
TEST(PoseTracker, ACameraThatCutsOffThePersonAtTheCentreIsLeftOutOfTheInViewTest) {
  std::vector<Camera> cams = PinholeRig();
  Camera* side = nullptr;
  for (Camera& c : cams) {
    if (c.name == "side") side = &c;
  }
  ASSERT_NE(side, nullptr);
  EXPECT_TRUE(HoldsBox(*side, Vector3d::Zero(), 2.0, 0.35));
  // Tilted 12 degrees up about its own x axis (OpenCV frame: y down): the
  // floor below the box, 27.8 degrees below the horizontal from 1.9 m up and
  // 3.6 m away, leaves its 25.6-degree lower half field of view.
  const double depression = std::atan2(side->CenterInWorld().z() - 1.0, side->CenterInWorld().head<2>().norm());
  const double floor_angle = std::atan2(side->CenterInWorld().z(), side->CenterInWorld().head<2>().norm() - 0.35);
  const double half_fov = std::atan2(side->height - 1 - side->cy, side->fy);
  const double tilt = 12 * M_PI / 180;
  ASSERT_GT(floor_angle - (depression - tilt), half_fov);  // the analytic expectation
  side->cam_from_world = Eigen::Isometry3d(Eigen::AngleAxisd(-tilt, Vector3d::UnitX())) * side->cam_from_world;
  EXPECT_FALSE(HoldsBox(*side, Vector3d::Zero(), 2.0, 0.35));
  Camera turned = *side;
  turned.cam_from_world = Eigen::Isometry3d(Eigen::AngleAxisd(M_PI, Vector3d::UnitY())) * side->cam_from_world;
  EXPECT_FALSE(HoldsBox(turned, Vector3d::Zero(), 2.0, 0.35));  // facing away

  const BodyShape shape = BodyShape::FromHeight(1.75);
  PoseTrackerOptions options;
  options.seed = 2;
  PoseTracker tracker(cams, {}, options);
  const BodyPose truth = StandingPose(shape, Vector2d(0.1, 0.0), 0.0);
  PoseEstimate e;
  for (int f = 0; f < 8; ++f) e = tracker.Step(ModelFeatures(cams, shape, truth, f), 1.0 / 30);
  EXPECT_TRUE(e.in_view);
  EXPECT_TRUE(e.tracking);
  EXPECT_LT((e.body.joints[kModelRoot] - PoseBody(shape, truth).joints[kModelRoot]).norm(), 0.05);
}

// Ctrl-C is honoured within a frame's particles (issue 27): a cancel that
// arrives while the particles are scored stops the scoring and throws
// Cancelled in the caller, instead of finishing the whole frame.
TEST(ParticleFilter, ACancelStopsTheScoringWithinTheFrame) {
  ResetCancel();
  const std::vector<BodyPose> particles(2000);
  std::atomic<int> scored{0};
  const PoseScore score = [&](const BodyPose&) {
    if (++scored == 10) RequestCancel();
    return 0.0;
  };
  EXPECT_THROW(WeighParticles(particles, score), Cancelled);
  // Each worker stops at its next particle: far fewer than all were scored.
  EXPECT_LT(scored.load(), 200);
  ResetCancel();
  scored = 0;
  EXPECT_EQ(WeighParticles(particles, [&](const BodyPose&) { return 1.0 * ++scored; }).size(), particles.size());
  EXPECT_EQ(scored.load(), 2000);
}

TEST(Pointing, RayFromHeadThroughHandTipHitsTheNearestScreen) {
  ScreenSurface near_screen, far_screen;
  near_screen.name = "near";
  near_screen.origin = Vector3d(-2, 3, 0);  // the plane y = 3
  near_screen.right = Vector3d(1, 0, 0);
  near_screen.up = Vector3d(0, 0, 1);
  near_screen.width = 4;
  near_screen.height = 3;
  near_screen.targets["door"] = Vector2d(2.5, 1.6);
  far_screen = near_screen;
  far_screen.name = "far";
  far_screen.origin = Vector3d(-2, 5, 0);
  const Vector3d head(0, 0, 1.6);
  const Vector3d hand(0.1, 0.6, 1.6);
  auto ray = Pointing(head, hand, {far_screen, near_screen});
  ASSERT_TRUE(ray);
  EXPECT_NEAR(ray->dir.dot((hand - head).normalized()), 1.0, 1e-12);
  // The planes' fronts (right x up = -y) face the viewer; the hit is on the
  // nearer one, at the analytic point.
  ASSERT_TRUE(ray->screen);
  EXPECT_EQ(*ray->screen, "near");
  const Vector3d hit = head + (3.0 / ray->dir.y()) * ray->dir;
  EXPECT_NEAR(ray->screen_hit->x(), hit.x() + 2, 1e-9);
  EXPECT_NEAR(ray->screen_hit->y(), hit.z(), 1e-9);
  EXPECT_EQ(ray->target.value_or(""), "door");
  EXPECT_FALSE(Pointing(head, head, {near_screen}));
}

// The head centre is read off the voxel hull, not the model: a ball of a
// head on a trunk with an arm held out at shoulder height, and a model head
// a couple of centimetres off. The ball sits on voxel centres, so its
// voxels' centroid is its centre exactly.
TEST(Pointing, HullHeadCentreIsWhereTheVoxelsShowTheHead) {
  VoxelHull hull = EmptyStageHull();
  const Vector3d ball(0.13, -0.07, 1.61);  // a voxel centre's x and y
  const double radius = 0.09;              // the crown at 1.70, a voxel layer's upper face
  FillHull(&hull, [&](const Vector3d& c) { return (c - ball).norm() < radius; });
  FillHull(&hull, [&](const Vector3d& c) {  // trunk, and the right arm held out sideways at shoulder height
    const Vector3d d = c - ball;
    const bool trunk = std::abs(d.x()) < 0.2 && std::abs(d.y()) < 0.1 && c.z() > 0.9 && c.z() < 1.45;
    const bool arm = d.x() > 0.2 && d.x() < 0.8 && std::abs(d.y()) < 0.04 && c.z() > 1.38 && c.z() < 1.46;
    return trunk || arm;
  });
  const double height = 1.7;
  const Vector3d model_head = ball + Vector3d(0.02, -0.01, -0.03);
  const Vector3d forward(0, 2, 0);  // facing +y, not unit
  HullHeadOptions options;
  const auto head = HullHeadCentre(hull, model_head, forward, height, options);
  ASSERT_TRUE(head);
  EXPECT_NEAR(head->x(), ball.x(), 1e-9);
  EXPECT_NEAR(head->y(), ball.y() - options.back_m, 1e-9);  // moved back against the facing
  EXPECT_NEAR(head->z(), 1.70 - options.below_top * height, 1e-9);

  // A hand over the head puts the top too far above the model's crown: the
  // model's head is kept.
  FillHull(&hull, [&](const Vector3d& c) { return (c - (ball + Vector3d(0, 0, 0.24))).norm() < 0.05; });
  EXPECT_FALSE(HullHeadCentre(hull, model_head, forward, height, options));
  // No voxels near the head either.
  EXPECT_FALSE(HullHeadCentre(hull, model_head + Vector3d(0.5, 0, 0), forward, height, options));
  EXPECT_FALSE(HullHeadCentre(VoxelHull(), model_head, forward, height, options));

  options.slab = 0;
  EXPECT_THROW(options.Check(), InputError);
  PoseTrackerOptions tracker_options;
  tracker_options.hull_head.radius_m = -1;
  EXPECT_THROW(tracker_options.Check(), InputError);
}


// Between the legs' measures the root is the model's moved by the measures'
// average offset, which turns with the body and fades.
TEST(HullLegs, WithoutTheLegsTheAveragedOffsetTurnsWithTheBodyAndFades) {
  RootOffsetMemory memory(0.2, 2.0);
  // Facing +x: the legs' root 5 cm ahead of the model's and 2 cm to its
  // left (+y). The first measure is the average.
  const Vector3d model_root(0.4, -0.3, 0);
  HullLegs legs;
  legs.root = model_root + Vector3d(0.05, 0.02, 0);
  EXPECT_NEAR((memory.Root(model_root, Vector3d(2, 0, 0.5), legs, 1.0 / 30) - legs.root).norm(), 0.0, 1e-12);
  EXPECT_NEAR((memory.offset() - Eigen::Vector2d(0.05, 0.02)).norm(), 0.0, 1e-12);
  // A frame later facing -x, 3 cm ahead (-x) and none to the side: the
  // average moves that share of the way (exp(-dt / 0.2 s) kept).
  legs.root = model_root + Vector3d(-0.03, 0, 0);
  EXPECT_EQ(memory.Root(model_root, Vector3d(-1, 0, 0), legs, 1.0 / 30), legs.root);
  const double keep = std::exp(-1.0 / 30 / 0.2);
  const Eigen::Vector2d average = keep * Eigen::Vector2d(0.05, 0.02) + (1 - keep) * Eigen::Vector2d(0.03, 0.0);
  EXPECT_NEAR((memory.offset() - average).norm(), 0.0, 1e-12);
  // Half a second later, no legs, turned to face +y (left is -x), moved:
  // the average faded by exp(-0.5 s / 2 s); a second in, by exp(-1 / 2).
  const Vector3d moved(-0.2, 0.6, 0);
  const Vector3d up(0, 1, 0);
  const auto turned = [](const Eigen::Vector2d& o) { return Vector3d(-o.y(), o.x(), 0); };  // facing +y
  EXPECT_NEAR((memory.Root(moved, up, std::nullopt, 0.5) - (moved + std::exp(-0.25) * turned(average))).norm(), 0.0,
              1e-12);
  EXPECT_NEAR((memory.Root(moved, up, std::nullopt, 0.5) - (moved + std::exp(-0.5) * turned(average))).norm(), 0.0,
              1e-12);
  // A measure after the gap is averaged with the faded average; the next
  // gap fades from there (the clock restarts at the measure).
  legs.root = moved + Vector3d(0, 0.04, 0);  // 4 cm ahead
  EXPECT_EQ(memory.Root(moved, up, legs, 1.0 / 30), legs.root);
  const Eigen::Vector2d after = keep * std::exp(-0.5) * average + (1 - keep) * Eigen::Vector2d(0.04, 0.0);
  EXPECT_NEAR((memory.offset() - after).norm(), 0.0, 1e-12);
  EXPECT_NEAR((memory.Root(moved, up, std::nullopt, 0.1) - (moved + std::exp(-0.05) * turned(after))).norm(), 0.0,
              1e-12);
  // A body facing straight up (no direction on the floor) gets the legs'
  // root, or the model's, and leaves the average alone.
  legs.root = moved + Vector3d(0.3, 0, 0);
  EXPECT_EQ(memory.Root(moved, Vector3d(0, 0, 1), legs, 0.1), legs.root);
  EXPECT_EQ(memory.Root(moved, Vector3d(0, 0, 1), std::nullopt, 0.1), moved);
  EXPECT_NEAR((memory.offset() - after).norm(), 0.0, 1e-12);
  // Reset (tracking lost): the model's root, and the next measure is the
  // whole average.
  memory.Reset();
  EXPECT_EQ(memory.Root(moved, up, std::nullopt, 0.5), moved);
  legs.root = moved + Vector3d(0.01, 0.02, 0);  // 2 cm ahead, 1 cm to the right
  EXPECT_EQ(memory.Root(moved, up, legs, 1.0 / 30), legs.root);
  EXPECT_NEAR((memory.offset() - Eigen::Vector2d(0.02, -0.01)).norm(), 0.0, 1e-12);
}

// The root is read off the hull's lower legs: two shins leaning forward (the
// knees 12 cm ahead of the ankles, as people stand), feet reaching forward
// of the ankles, a person facing 30 deg from +y. The layers' line
// extrapolated to the ankles' height is the ankles' midpoint, not the point
// under the knees or the waist; the feet give the facing direction.
TEST(HullLegs, TheRootIsTheAnklesMidpointWhateverTheShinsLean) {
  VoxelHull hull = EmptyStageHull();
  const double height = 1.75;
  HullLegsOptions options;
  const double ankle_z = options.ankle * height;
  const Eigen::Vector2d forward(std::sin(M_PI / 6), std::cos(M_PI / 6));
  const Eigen::Vector2d side(forward.y(), -forward.x());
  const Eigen::Vector2d mid(0.13, -0.21);
  const auto on_leg = [&](const Vector3d& c, const Eigen::Vector2d& ankle, double lean) {
    if (c.z() < ankle_z || c.z() > 0.5) return false;
    const Eigen::Vector2d axis = ankle + lean * (c.z() - ankle_z) * forward;  // the shin's centre at c's height
    return (c.head<2>() - axis).norm() < 0.055;
  };
  const auto on_foot = [&](const Vector3d& c, const Eigen::Vector2d& ankle) {
    const Eigen::Vector2d d = c.head<2>() - ankle;
    return c.z() < ankle_z && d.dot(forward) > -0.05 && d.dot(forward) < 0.19 && std::abs(d.dot(side)) < 0.045;
  };
  const Eigen::Vector2d right = mid + 0.11 * side + 0.06 * forward, left = mid - 0.11 * side - 0.06 * forward;
  const double lean = 0.12 / (0.5 - ankle_z);
  FillHull(&hull, [&](const Vector3d& c) {
    return on_leg(c, right, lean) || on_leg(c, left, lean) || on_foot(c, right) || on_foot(c, left);
  });
  const Vector3d model_root(mid.x() + 0.1 * forward.x(), mid.y() + 0.1 * forward.y(), 0);  // under the waist
  const Vector3d facing(forward.x(), forward.y(), 0.3);  // need not be unit or level
  options.calf = 0;
  options.weight = 1;
  const auto legs = MeasureHullLegs(hull, model_root, facing, height, options);
  ASSERT_TRUE(legs);
  EXPECT_NEAR((legs->root.head<2>() - mid).norm(), 0.0, 0.01);  // half a 2 cm voxel
  EXPECT_GE(legs->layers, options.min_layers);
  ASSERT_TRUE(legs->toes);
  EXPECT_GT(legs->toes->dot(forward), 0.05);
  EXPECT_LT(std::abs(legs->toes->dot(side)), 0.01);
  // The calf correction moves the root forward by that share of the height.
  options.calf = 0.0085;
  const auto corrected = MeasureHullLegs(hull, model_root, facing, height, options);
  ASSERT_TRUE(corrected);
  EXPECT_NEAR((corrected->root.head<2>() - legs->root.head<2>() - 0.0085 * height * forward).norm(), 0.0, 1e-9);
  // Blended with the model's root: that share of the way from it.
  options.weight = 0.8;
  const auto blended = MeasureHullLegs(hull, model_root, facing, height, options);
  ASSERT_TRUE(blended);
  EXPECT_NEAR((blended->root - (model_root + 0.8 * (corrected->root - model_root))).norm(), 0.0, 1e-9);
  // A lean steeper than max_lean is carried down only that far: the shins'
  // 0.29 capped at 0.1 leaves the root ahead of the ankles (towards the
  // knees) by 0.19 times the anchor layers' height above the ankles.
  options.weight = 1;
  options.calf = 0;
  options.max_lean = 0.1;
  const auto capped = MeasureHullLegs(hull, model_root, facing, height, options);
  ASSERT_TRUE(capped);
  EXPECT_GT((capped->root.head<2>() - mid).dot(forward), 0.01);
  options.max_lean = 0.3;

  // Legs leaning more than max_slope: the same root, not the feet's direction.
  options.max_lean = 0.2;
  const auto gentle = MeasureHullLegs(hull, model_root, facing, height, options);
  ASSERT_TRUE(gentle && gentle->toes);
  options.max_slope = 0.2;
  const auto steep = MeasureHullLegs(hull, model_root, facing, height, options);
  ASSERT_TRUE(steep);
  EXPECT_EQ(steep->root, gentle->root);
  EXPECT_FALSE(steep->toes);
  // No legs near the model's root, an empty hull, legs leaning more than
  // root_max_slope: the model's root stands.
  EXPECT_FALSE(MeasureHullLegs(hull, model_root + Vector3d(0.8, 0, 0), facing, height, options));
  EXPECT_FALSE(MeasureHullLegs(EmptyStageHull(), model_root, facing, height, options));
  options.root_max_slope = 0.2;
  EXPECT_FALSE(MeasureHullLegs(hull, model_root, facing, height, options));
  EXPECT_NO_THROW(options.Check());
  options.root_max_slope = 0.1;  // below max_slope
  EXPECT_THROW(options.Check(), InputError);
  options.root_max_slope = 0.2;
  options.low = 0.3;  // above `high`
  EXPECT_THROW(options.Check(), InputError);
  options = HullLegsOptions();
  PoseTrackerOptions tracker_options;
  tracker_options.root_offset_smoothing_s = 0;
  EXPECT_THROW(tracker_options.Check(), InputError);
  tracker_options = PoseTrackerOptions();
  tracker_options.root_offset_memory_s = -1;
  EXPECT_THROW(tracker_options.Check(), InputError);

  // The feet are on the floor where the floor layer holds them; lifted
  // 20 cm (a jump), or far from the root, they are not.
  EXPECT_TRUE(FeetOnFloor(hull, model_root, height, options));
  VoxelHull jump = hull;
  jump.origin_m.z() += 0.2;
  EXPECT_FALSE(FeetOnFloor(jump, model_root, height, options));
  EXPECT_FALSE(FeetOnFloor(hull, model_root + Vector3d(0.8, 0, 0), height, options));
  // How far the lowest part lies above the floor: under a voxel standing,
  // 20 cm more in the jump, nothing where no leg is near the root.
  const double standing_gap = FloorGap(hull, model_root, height, options);
  EXPECT_LT(standing_gap, hull.voxel_size_m);
  EXPECT_NEAR(FloorGap(jump, model_root, height, options), standing_gap + 0.2, 1e-9);
  EXPECT_EQ(FloorGap(hull, model_root + Vector3d(0.8, 0, 0), height, options), 0.0);
  EXPECT_EQ(FloorGap(EmptyStageHull(), model_root, height, options), 0.0);
}

// The top of the hull's column over the head: a head (a cylinder of 9 cm
// radius up to 1.80 m) tops out at the upper face of its highest layer; a
// hand 10 cm over it, apart, does not count, one laid on it does; nothing
// where the layer it starts from is empty, or outside the grid.
TEST(HullLegs, TheColumnOverTheHeadEndsAtTheFirstGap) {
  VoxelHull hull = EmptyStageHull();
  const Vector2d head(0.1, 0.2);
  auto in_head = [&](const Vector3d& c) { return (c.head<2>() - head).norm() < 0.09 && c.z() > 1.5 && c.z() < 1.80; };
  FillHull(&hull, in_head);
  // Voxel centres below 1.80 m: the highest at 1.79, its upper face 1.80.
  ASSERT_TRUE(HullColumnTop(hull, head, 1.65, 0.08));
  EXPECT_NEAR(*HullColumnTop(hull, head, 1.65, 0.08), 1.80, 1e-9);
  // Beside the head but within the radius of its edge: the same column.
  EXPECT_NEAR(*HullColumnTop(hull, head + Vector2d(0.12, 0), 1.65, 0.08), 1.80, 1e-9);
  VoxelHull hand = hull;
  FillHull(&hand, [&](const Vector3d& c) { return (c.head<2>() - head).norm() < 0.05 && c.z() > 1.90 && c.z() < 2.0; });
  EXPECT_NEAR(*HullColumnTop(hand, head, 1.65, 0.08), 1.80, 1e-9);
  FillHull(&hand, [&](const Vector3d& c) { return (c.head<2>() - head).norm() < 0.05 && c.z() > 1.5 && c.z() < 2.0; });
  EXPECT_NEAR(*HullColumnTop(hand, head, 1.65, 0.08), 2.0, 1e-9);
  EXPECT_FALSE(HullColumnTop(hull, head + Vector2d(0.3, 0), 1.65, 0.08));
  EXPECT_FALSE(HullColumnTop(hull, head, 1.2, 0.08));
  EXPECT_FALSE(HullColumnTop(hull, head, -0.1, 0.08));
  EXPECT_FALSE(HullColumnTop(hull, head, 2.5, 0.08));
  EXPECT_FALSE(HullColumnTop(VoxelHull(), head, 1.65, 0.08));
}

// Two legs apart, one of them seen fatter (a calf seen by fewer views, a
// ghost beside it): the layers' centres are the midpoints of the two legs,
// as the truth's root is the midpoint of the ankles, not the voxels'
// centroid, which leans to the leg with more voxels. Legs together (one
// blob): the two halves straddle its centre.
TEST(HullLegs, TwoLegsApartCountAlikeWhateverVoxelsEachHolds) {
  const double height = 1.75;
  HullLegsOptions options;
  options.calf = 0;
  options.weight = 1;  // the root reported is the one measured
  const double ankle_z = options.ankle * height;
  const Eigen::Vector2d forward(0, 1), side(1, 0);
  const Eigen::Vector2d mid(0.07, -0.12);
  const auto leg = [&](const Vector3d& c, const Eigen::Vector2d& ankle, double radius) {
    return c.z() >= ankle_z && c.z() <= 0.5 && (c.head<2>() - ankle).norm() < radius;
  };
  const Vector3d model_root(mid.x(), mid.y(), 0);
  VoxelHull apart = EmptyStageHull();
  const Eigen::Vector2d right = mid + 0.2 * side, left = mid - 0.2 * side;
  FillHull(&apart, [&](const Vector3d& c) { return leg(c, right, 0.05) || leg(c, left, 0.085); });
  const auto split = MeasureHullLegs(apart, model_root, Vector3d(0, 1, 0), height, options);
  ASSERT_TRUE(split);
  EXPECT_NEAR((split->root.head<2>() - mid).norm(), 0.0, 0.01);  // half a 2 cm voxel
  options.split_legs = false;
  const auto centroid = MeasureHullLegs(apart, model_root, Vector3d(0, 1, 0), height, options);
  ASSERT_TRUE(centroid);
  // The left leg holds (8.5 / 5)^2 = 2.9 times the right's voxels: the
  // centroid lies about 0.2 * (2.9 - 1) / (2.9 + 1) = 10 cm towards it.
  EXPECT_GT((centroid->root.head<2>() - mid).dot(-side), 0.07);
  options.split_legs = true;

  VoxelHull together = EmptyStageHull();
  FillHull(&together, [&](const Vector3d& c) { return leg(c, mid + 0.03 * forward, 0.1); });
  const auto blob = MeasureHullLegs(together, model_root, Vector3d(0, 1, 0), height, options);
  ASSERT_TRUE(blob);
  EXPECT_NEAR((blob->root.head<2>() - (mid + 0.03 * forward)).norm(), 0.0, 0.01);
}

// The top of the model: the highest point of its ellipsoids.
double ModelTop(const PosedBody& body) {
  double top = 0;
  for (const Ellipsoid& e : body.segments) {
    const Eigen::Vector3d row = e.world_from_segment.row(2).transpose().cwiseProduct(e.radii);
    top = std::max(top, e.center.z() + row.norm());
  }
  return top;
}

// The height (thesis 6.1.2: the hull's top when the user enters) is taken
// only while the user stands up straight with the feet on the floor. Real
// people bend, crouch and jump in their first half second: CMU 13_14
// laughs bent 15-25 deg forward, 02_04 crouches to jump; measured then,
// p1 (1.75 m) was 1.62 and 1.50 m tall for the rest of the take. Here a
// user bends 29 deg forward a tenth of a second after entering, stays bent
// for a second, then stands up.
TEST(PoseTracker, TheHeightIsMeasuredStandingUpStraight) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  const BodyPose upright = StandingPose(shape, Vector2d(0.1, 0.2), 0.0);
  BodyPose bent = upright;
  bent.dof[kDofWaistX] = 0.5;
  const double bent_top = ModelTop(PoseBody(shape, bent));
  ASSERT_LT(bent_top, 1.70);
  const double upright_top = ModelTop(PoseBody(shape, upright));
  ASSERT_NEAR(upright_top, shape.height_m, 0.01);
  auto measured = [&](const PoseTrackerOptions& options) {
    PoseTracker tracker(cams, {}, options);
    PoseEstimate e;
    for (int f = 0; f < 70; ++f) {
      BodyPose pose = upright;
      pose.dof[kDofWaistX] = f < 2 ? 0.0 : f < 5 ? bent.dof[kDofWaistX] * (f - 2) / 3 : f < 40 ? bent.dof[kDofWaistX] : 0.0;
      FrameFeatures features = ModelFeatures(cams, shape, pose, f);
      features.placement->top_m = ModelTop(PoseBody(shape, pose));
      e = tracker.Step(features, 1.0 / 30);
      EXPECT_TRUE(e.tracking) << f;
    }
    return e.shape.height_m;
  };
  PoseTrackerOptions options;
  options.seed = 4;
  EXPECT_NEAR(measured(options), upright_top, 0.01);
  // Taken whatever the lean and the waist's height: the bent user's top.
  PoseTrackerOptions any = options;
  any.height_max_lean_deg = 90;
  any.height_min_waist = 0;
  EXPECT_NEAR(measured(any), bent_top, 0.01);

  // A jump: the feet off the floor measure nothing.
  BodyCalibration calibration(options);
  BodyShape model = calibration.Start(shape.height_m);
  const BodyCalibration::ShapeScore score = [](const BodyShape&, const BodyPose&) { return 0.0; };
  EXPECT_FALSE(calibration.MeasureHeightAndGirth(true, upright, 2.05, false, true, score, &model));
  EXPECT_FALSE(calibration.height_measured());
  EXPECT_TRUE(calibration.MeasureHeightAndGirth(true, upright, 1.77, true, true, score, &model));
  EXPECT_NEAR(model.height_m, 1.77, 1e-9);

  // A model started short (the user first seen half in view: 1.63 m for a
  // 1.75 m user's top) stands with its waist too low for that top, which
  // reads as a crouch and is not measured; the rise cap keeps the filter
  // from lifting the waist there. Until measured, the model takes the top's
  // height once it is more than height_top_match off (7 % here; at 10 %, as
  // before 2026-12-07, p2 walking in stayed 1.48 m for 1.60 m for 80 frames).
  BodyCalibration short_start(options);
  BodyShape short_model = short_start.Start(1.63);
  BodyPose short_standing = upright;
  short_standing.dof[kDofZ] = short_model.waist_height_m;
  ASSERT_GT(1.75 * short_model.waist_height_m / short_model.height_m * options.height_min_waist,
            short_model.waist_height_m + options.max_rise_m);
  EXPECT_FALSE(short_start.MeasureHeightAndGirth(true, short_standing, 1.75, true, true, score, &short_model));
  const std::optional<double> ratio = short_start.MatchHullTop(1.75, &short_model);
  ASSERT_TRUE(ratio);
  EXPECT_NEAR(*ratio, 1.75 / 1.63, 1e-12);
  EXPECT_NEAR(short_model.height_m, 1.75, 1e-9);
  EXPECT_FALSE(short_start.MatchHullTop(1.70, &short_model));  // within 5 %: kept
  EXPECT_TRUE(short_start.MatchHullTop(1.65, &short_model));

  // With a camera left out, the taller hull's tops stand in until the first
  // frame seen by all views, and are then forgotten (tops within 3 % of the
  // 1.75 m estimate's: its waist is high enough for them).
  BodyCalibration partial(options);
  model = partial.Start(shape.height_m);
  for (double top : {1.77, 1.79, 1.79}) {
    EXPECT_TRUE(partial.takes_height_sample(false));
    EXPECT_TRUE(partial.MeasureHeightAndGirth(true, upright, top, true, false, score, &model));
  }
  EXPECT_NEAR(model.height_m, 1.79, 1e-9);
  EXPECT_TRUE(partial.measuring_height());
  EXPECT_TRUE(partial.takes_height_sample(true));
  EXPECT_TRUE(partial.MeasureHeightAndGirth(true, upright, 1.74, true, true, score, &model));
  EXPECT_NEAR(model.height_m, 1.74, 1e-9);
  EXPECT_TRUE(partial.MeasureHeightAndGirth(true, upright, 1.76, true, true, score, &model));
  EXPECT_NEAR(model.height_m, 1.76, 1e-9);  // the upper median
  // Once all views measured, a view left out measures nothing.
  EXPECT_FALSE(partial.takes_height_sample(false));
  EXPECT_FALSE(partial.MeasureHeightAndGirth(true, upright, 1.70, true, false, score, &model));
  EXPECT_NEAR(model.height_m, 1.76, 1e-9);
  for (int f = 2; f < options.height_frames; ++f) {
    EXPECT_TRUE(partial.measuring_height());
    EXPECT_TRUE(partial.takes_height_sample(true));
    partial.MeasureHeightAndGirth(true, upright, 1.75, true, true, score, &model);
  }
  EXPECT_FALSE(partial.measuring_height());
  for (bool all_views : {true, false}) {
    EXPECT_FALSE(partial.takes_height_sample(all_views));
    EXPECT_FALSE(partial.MeasureHeightAndGirth(true, upright, 1.75, true, all_views, score, &model));
  }

  // A camera dead all take: its frames fill height_frames, then measure
  // nothing more (the feet need no looking at) while the height is still
  // provisional, until all views are back.
  BodyCalibration dead(options);
  model = dead.Start(shape.height_m);
  for (int f = 0; f < options.height_frames; ++f) {
    EXPECT_TRUE(dead.takes_height_sample(false));
    EXPECT_TRUE(dead.MeasureHeightAndGirth(true, upright, 1.78, true, false, score, &model));
  }
  EXPECT_TRUE(dead.measuring_height());
  EXPECT_FALSE(dead.takes_height_sample(false));
  EXPECT_FALSE(dead.MeasureHeightAndGirth(true, upright, 1.78, true, false, score, &model));
  EXPECT_TRUE(dead.takes_height_sample(true));
  EXPECT_TRUE(dead.MeasureHeightAndGirth(true, upright, 1.74, true, true, score, &model));
  EXPECT_NEAR(model.height_m, 1.74, 1e-9);

  for (auto set : {+[](PoseTrackerOptions* o) { o->height_max_lean_deg = 0; },
                   +[](PoseTrackerOptions* o) { o->height_min_waist = 1.5; }}) {
    PoseTrackerOptions bad;
    set(&bad);
    EXPECT_THROW(bad.Check(), InputError);
  }
}

}  // namespace
}  // namespace irbench

namespace irbench {
namespace {

// Features of a right arm from its upper-arm and forearm directions in the
// upper-body frame (x right, y forward, z up), for a body of height 1.
std::array<float, 6> ArmFeatures(const Eigen::Vector3d& upper, const Eigen::Vector3d& fore) {
  const Eigen::Vector3d shoulder(0.1, 0, 0.81), elbow = shoulder + 0.186 * upper, wrist = elbow + 0.146 * fore;
  return RestFeatures(Eigen::Vector3d(0, 0, 0.6), Eigen::Vector3d(0, 0, 0.818), shoulder,
                      Eigen::Vector3d(-0.1, 0, 0.81), elbow, wrist, 1.0, false);
}

// The SVM learns the truth's rest rule (sim/motion/labels.h: upper arm within
// 30 deg of down, forearm within 45 deg) from samples of it.
TEST(RestState, LearnsTheRestRuleFromSamples) {
  std::mt19937 rng(8);
  std::normal_distribution<double> n(0, 1);
  auto random_dir = [&](double spread) {
    return Eigen::Vector3d(spread * n(rng), spread * n(rng), -1.0).normalized();
  };
  auto rule = [](const Eigen::Vector3d& u, const Eigen::Vector3d& f) {
    return std::acos(-u.z()) < 30 * M_PI / 180 && std::acos(-f.z()) < 45 * M_PI / 180;
  };
  std::vector<std::array<float, 6>> x, test_x;
  std::vector<int> y, test_y;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d u = random_dir(i % 2 ? 0.4 : 1.5), f = random_dir(i % 3 ? 0.6 : 2.0);
    (i < 2400 ? x : test_x).push_back(ArmFeatures(u, f));
    (i < 2400 ? y : test_y).push_back(rule(u, f));
  }
  double cv_accuracy = 0;
  const RestClassifier svm = RestClassifier::Train(x, y, 5, &cv_accuracy);
  EXPECT_GT(cv_accuracy, 0.92);  // many samples lie near the boundary on purpose
  int correct = 0;
  for (size_t i = 0; i < test_x.size(); ++i) correct += svm.AtRest(test_x[i]) == (test_y[i] == 1);
  EXPECT_GT(correct / double(test_x.size()), 0.92);
  // Saved and loaded, it decides the same.
  const auto file = std::filesystem::temp_directory_path() / ("rest_svm_test_" + std::to_string(getpid()) + ".yml");
  svm.Save(file);
  const RestClassifier loaded = RestClassifier::Load(file);
  for (const auto& f : test_x) EXPECT_EQ(loaded.AtRest(f), svm.AtRest(f));
  std::filesystem::remove(file);
}

// An SVM trained on a rule no arm in these tests meets (upper arm within 30
// deg of straight up), so that only the tracker's other rest tests can find
// an arm at rest.
std::shared_ptr<RestClassifier> NeverRestSvm() {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 1);
  std::vector<std::array<float, 6>> x;
  std::vector<int> y;
  for (int i = 0; i < 600; ++i) {
    const Eigen::Vector3d u = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    const Eigen::Vector3d f = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    x.push_back(ArmFeatures(u, f));
    y.push_back(u.z() > std::cos(30 * M_PI / 180));
  }
  return std::make_shared<RestClassifier>(RestClassifier::Train(x, y, 3, nullptr));
}

// Rest decisions (right, left) over frames 5-19 of a tracker following
// `truth`, the front end reporting the arms `arms` shows.
std::vector<std::array<bool, 2>> RestDecisions(const PoseTrackerOptions& options, const BodyPose& truth,
                                               std::array<bool, 2> arms) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  PoseTracker tracker(cams, {}, options);
  tracker.set_rest_classifier(NeverRestSvm());
  std::vector<std::array<bool, 2>> decisions;
  for (int f = 0; f < 20; ++f) {
    const PoseEstimate e = tracker.Step(ModelFeatures(cams, shape, truth, f, arms), 1.0 / 30);
    EXPECT_TRUE(e.tracking) << f;
    if (!e.rest[0] || !e.rest[1]) {
      ADD_FAILURE() << "no rest decision at frame " << f;
      continue;
    }
    if (f >= 5) decisions.push_back({*e.rest[0], *e.rest[1]});
  }
  return decisions;
}

// Expects each of `decisions` ({right, left} at rest) to be {right, left};
// `right_why` and `left_why` name the arms in a failure.
void ExpectEveryDecision(const std::vector<std::array<bool, 2>>& decisions, bool right, bool left,
                         const char* right_why = "", const char* left_why = "") {
  for (const auto& [r, l] : decisions) {
    EXPECT_EQ(r, right) << right_why;
    EXPECT_EQ(l, left) << left_why;
  }
}

// Thesis 6.4: silhouettes cannot tell an arm wrapped near the body from a
// hanging one. Besides the SVM, an arm the axis points do not show is at rest
// when forcing it down costs the estimate next to nothing
// (PoseTrackerOptions::rest_max_log_overlap_loss).
TEST(RestState, AnArmTheSilhouettesCannotTellFromHangingIsAtRest) {
  const BodyShape shape = BodyShape::FromHeight(1.75);
  BodyPose truth = StandingPose(shape, Vector2d(0.1, 0.2), 0.0);
  truth.dof[kDofRightShoulderAzimuth] = M_PI / 2;  // right arm forward, horizontal
  truth.dof[kDofRightShoulderZenith] = M_PI / 2;
  PoseTrackerOptions options;
  options.seed = 6;
  // The front end sees the raised right arm, not the hanging left one.
  const auto with_test = RestDecisions(options, truth, {true, false});
  ASSERT_EQ(with_test.size(), 15u);
  ExpectEveryDecision(with_test, false, true, "the raised right arm is not at rest",
                      "the hanging left arm is at rest");
  // Without the test the SVM alone decides, and it finds neither arm at rest.
  options.rest_max_log_overlap_loss = 0;
  ExpectEveryDecision(RestDecisions(options, truth, {true, false}), false, false);
}

// An arm the 3D axis points show apart from the body is at rest when they
// hang within rest_seen_max_angle_deg of straight down, whatever the SVM
// says; and for a seen arm the likelihood-ratio test is not run.
TEST(RestState, AnArmSeenHangingIsAtRestAndOneSeenLiftedIsNot) {
  const BodyShape shape = BodyShape::FromHeight(1.75);
  BodyPose truth = StandingPose(shape, Vector2d(0.1, 0.2), 0.0);
  // Both arms out to the side, straight: the right 20 deg from straight
  // down, the left 38 deg (below rest_lifted_angle_deg, so only the seen
  // arm's exemption keeps the likelihood-ratio test away from it).
  for (int sh : {kDofRightShoulderAzimuth, kDofLeftShoulderAzimuth}) {
    truth.dof[sh] = 0.0;
    truth.dof[sh + 2] = 0.0;
  }
  truth.dof[kDofRightShoulderZenith] = 20 * M_PI / 180;
  truth.dof[kDofLeftShoulderZenith] = 38 * M_PI / 180;
  for (int el : {kDofRightElbowAzimuth, kDofLeftElbowAzimuth}) truth.dof[el] = truth.dof[el + 1] = 0.0;
  PoseTrackerOptions options;
  options.seed = 7;
  options.rest_max_log_overlap_loss = 1e9;  // passes any arm it is run on
  const auto decisions = RestDecisions(options, truth, {true, true});
  ASSERT_EQ(decisions.size(), 15u);
  ExpectEveryDecision(decisions, true, false, "the right arm hangs 20 deg from straight down",
                      "the left arm is lifted 38 deg");
  // At a limit of 15 deg neither is at rest.
  options.rest_seen_max_angle_deg = 15;
  ExpectEveryDecision(RestDecisions(options, truth, {true, true}), false, false);
}

// The truth's rule calls an arm lifted once its forearm is 45 deg or more
// from straight down. Under a hanging upper arm the farthest axis point then
// lies about half the elbow's bend from down (a little more: forearm and
// hand outreach the upper arm): an arm bent 50 deg forward reads about 28
// deg, inside the old limit of 34 deg, and was taken for hanging (issue 28:
// a third of the CMU arm-frames wrongly at rest). The limit is half the
// truth's forearm limit, 22.5 deg: such an arm is left to the SVM and the
// filter, and a straight arm swung 20 deg is still at rest.
// A standing pose whose upper arms hang `shoulder_zenith` (radians) out to
// the sides, the right forearm bent `right_elbow_zenith` forward, the left
// arm straight.
BodyPose RightForearmBentForward(const BodyShape& shape, double shoulder_zenith, double right_elbow_zenith) {
  BodyPose truth = StandingPose(shape, Vector2d(0.1, 0.2), 0.0);
  for (int sh : {kDofRightShoulderAzimuth, kDofLeftShoulderAzimuth}) {
    truth.dof[sh] = 0.0;
    truth.dof[sh + 1] = shoulder_zenith;
    truth.dof[sh + 2] = 0.0;
  }
  truth.dof[kDofRightElbowAzimuth] = M_PI / 2;  // forward
  truth.dof[kDofRightElbowZenith] = right_elbow_zenith;
  truth.dof[kDofLeftElbowAzimuth] = truth.dof[kDofLeftElbowZenith] = 0.0;
  return truth;
}

TEST(RestState, AForearmBentForwardUnderAHangingUpperArmIsNotForcedToRest) {
  const BodyShape shape = BodyShape::FromHeight(1.75);
  BodyPose truth = RightForearmBentForward(shape, 0.05, 50 * M_PI / 180);
  truth.dof[kDofLeftShoulderZenith] = 20 * M_PI / 180;  // the left arm straight, 20 deg out
  PoseTrackerOptions options;
  options.seed = 7;
  EXPECT_DOUBLE_EQ(options.rest_seen_max_angle_deg, 22.5);
  const auto decisions = RestDecisions(options, truth, {true, true});
  ASSERT_EQ(decisions.size(), 15u);
  ExpectEveryDecision(decisions, false, true, "the right forearm is bent 50 deg forward",
                      "the left arm hangs straight, 20 deg out");
  // At the old limit the bent arm was at rest.
  options.rest_seen_max_angle_deg = 34;
  ExpectEveryDecision(RestDecisions(options, truth, {true, true}), true, true);
}

// The mean distance (metres) over frames 5-19 between the tracked right
// wrist and the truth's, for a tracker following a user whose right upper arm
// hangs with the forearm held 95 deg forward (the hand before the belly, as
// real motion holds it), the left arm hanging straight; the front end shows
// neither arm, and the likelihood-ratio test passes any arm, so both are
// forced down.
double HeldForearmWristError(bool held_forearms, uint64_t seed) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  const BodyPose truth = RightForearmBentForward(shape, 0.1, 95 * M_PI / 180);
  const Vector3d wrist = PoseBody(shape, truth).joints[kModelRightWrist];
  PoseTrackerOptions options;
  options.seed = seed;
  options.rest_max_log_overlap_loss = 1e9;
  options.rest_held_forearms = held_forearms;
  PoseTracker tracker(cams, {}, options);
  tracker.set_rest_classifier(NeverRestSvm());
  double sum = 0;
  int n = 0;
  for (int f = 0; f < 20; ++f) {
    const PoseEstimate e = tracker.Step(ModelFeatures(cams, shape, truth, f, {false, false}), 1.0 / 30);
    EXPECT_TRUE(e.tracking) << f;
    if (f < 5) continue;
    EXPECT_EQ(e.rest[0], std::optional<bool>(true)) << f;
    sum += (e.body.joints[kModelRightWrist] - wrist).norm();
    ++n;
  }
  return n > 0 ? sum / n : 1e9;
}

// An arm found at rest is forced to the best hanging pose; with the held
// forearms among them (PoseTrackerOptions::rest_held_forearms) a forearm held
// 95 deg forward keeps its wrist (2-3 cm off), where the rest test's poses
// (forearms bent 63 deg at most) put it 10 cm off.
TEST(RestState, AForcedDownArmKeepsAForearmHeldBeforeTheBody) {
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    const double error = HeldForearmWristError(true, seed);
    EXPECT_LT(error, 0.05) << "seed " << seed;
    std::printf("held forearm, seed %d: the wrist %.1f cm off\n", int(seed), 100 * error);
  }
  const double without = HeldForearmWristError(false, 1);
  EXPECT_GT(without, 0.08);
  std::printf("held forearm forced to the rest test's poses: the wrist %.1f cm off\n", 100 * without);
}

TEST(RestState, OptionsAreChecked) {
  PoseTrackerOptions options;
  EXPECT_NO_THROW(options.Check());
  options.rest_seen_max_angle_deg = 200;
  EXPECT_THROW(options.Check(), InputError);
  options = PoseTrackerOptions();
  options.rest_lifted_memory_s = -1;
  EXPECT_THROW(options.Check(), InputError);
  options = PoseTrackerOptions();
  options.rest_held_min_gain = std::nan("");
  EXPECT_THROW(options.Check(), InputError);
  options = PoseTrackerOptions();
  options.rest_lifted_angle_deg = options.rest_seen_max_angle_deg - 1;  // an arm seen at rest would count as lifted
  EXPECT_THROW(options.Check(), InputError);
}

// An arm the axis points showed lifted and then lose is not taken for
// hanging by the likelihood-ratio test for rest_lifted_memory_s (on the
// harsh preset such an arm has left the noisy silhouettes too). Here the
// silhouettes show it hanging once it is lost, so the test would pass it at
// once: the decisions show the memory's timing, and its reset when the user
// is lost from view.
TEST(RestState, AnArmJustSeenLiftedIsNotTakenForHangingWhenItVanishes) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  const BodyPose hanging = StandingPose(shape, Vector2d(0.1, 0.2), 0.0);
  BodyPose lifted = hanging;
  lifted.dof[kDofRightShoulderAzimuth] = 0.0;  // out to the side, horizontal
  lifted.dof[kDofRightShoulderZenith] = M_PI / 2;
  // Seen lifted for 10 frames; then gone from the axis points, the
  // silhouettes showing it hanging; `gap`: frame 10 has no person.
  auto right_arm_decisions = [&](double memory_s, bool gap) {
    PoseTrackerOptions options;
    options.seed = 8;
    options.rest_lifted_memory_s = memory_s;
    PoseTracker tracker(cams, {}, options);
    tracker.set_rest_classifier(NeverRestSvm());
    std::vector<bool> right;
    for (int f = 0; f < 30; ++f) {
      FrameFeatures features = f < 10 ? ModelFeatures(cams, shape, lifted, f)
                                      : ModelFeatures(cams, shape, hanging, f, {false, true});
      if (gap && f == 10) features.placement.reset();
      const PoseEstimate e = tracker.Step(features, 1.0 / 30);
      if (!(gap && f == 10)) {
        EXPECT_TRUE(e.tracking && e.rest[0]) << f;
      }
      right.push_back(e.rest[0].value_or(false));
    }
    return right;
  };
  const std::vector<bool> with_memory = right_arm_decisions(0.5, false);
  for (int f = 5; f < 23; ++f) EXPECT_FALSE(with_memory[f]) << "frame " << f << ": within 0.5 s of seen lifted";
  for (int f = 27; f < 30; ++f) EXPECT_TRUE(with_memory[f]) << "frame " << f << ": 0.5 s after, hanging";
  const std::vector<bool> without = right_arm_decisions(0.0, false);
  for (int f = 5; f < 10; ++f) EXPECT_FALSE(without[f]) << f;
  for (int f = 12; f < 30; ++f) EXPECT_TRUE(without[f]) << "frame " << f << ": no memory, hanging";
  // A frame without the user forgets what was seen before it.
  const std::vector<bool> after_gap = right_arm_decisions(0.5, true);
  for (int f = 13; f < 30; ++f) EXPECT_TRUE(after_gap[f]) << "frame " << f << ": memory reset by the empty frame";
}

TEST(RestState, TheShippedModelLoadsAndKnowsHangingFromPointing) {
  const RestClassifier svm = RestClassifier::Load(DefaultRestModelPath());
  EXPECT_TRUE(svm.AtRest(ArmFeatures(Eigen::Vector3d(0.1, 0, -1).normalized(), Eigen::Vector3d(0, 0.1, -1).normalized())));
  EXPECT_FALSE(svm.AtRest(ArmFeatures(Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 1, 0))));
  EXPECT_FALSE(svm.AtRest(ArmFeatures(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1))));
  EXPECT_THROW(RestClassifier::Load("/nonexistent/rest.yml"), InputError);
}

}  // namespace
}  // namespace irbench

namespace irbench {
namespace {

// FlippedPose is the front/back twin: turned half way round about the spine,
// each arm is where the other side's arm was (same world positions), so only
// the ellipsoid torso's orientation differs — which silhouettes barely show —
// and what sits off the spine line is mirrored through it: the head centre
// (spine_depth_m ahead of it) and the root (ankle_setback_m behind it).
TEST(PoseTracker, FlippedPoseKeepsTheArmsWhereTheyWere) {
  const BodyShape shape = BodyShape::FromHeight(1.8);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> az(-M_PI, M_PI), zen(0.0, 2.4), yaw(-M_PI, M_PI);
  for (int trial = 0; trial < 50; ++trial) {
    BodyPose pose = StandingPose(shape, Eigen::Vector2d(0.2, -0.1), yaw(rng));
    // Upper arms out to the sides (within the shoulder cap both ways round:
    // a flipped arm that would point behind the back is clamped, on purpose).
    std::uniform_real_distribution<double> side(-0.5, 0.5);
    for (int d : {kDofRightShoulderAzimuth, kDofLeftShoulderAzimuth}) {
      pose.dof[d] = side(rng);
      pose.dof[d + 1] = zen(rng);
    }
    // Forearms bent no more than 0.1 of their length forward or back: the
    // twin bends them the other way, and the elbows' cap allows 0.1 back.
    for (int d : {kDofRightElbowAzimuth, kDofLeftElbowAzimuth}) {
      do {
        pose.dof[d] = az(rng);
        pose.dof[d + 1] = zen(rng);
      } while (std::abs(std::sin(pose.dof[d + 1]) * std::sin(pose.dof[d])) > 0.1);
    }
    ASSERT_TRUE(ClampToJointLimits(&pose));
    const BodyPose flipped = FlippedPose(pose);
    const PosedBody a = PoseBody(shape, pose), b = PoseBody(shape, flipped);
    for (auto [from, to] : {std::pair{kModelRightShoulder, kModelLeftShoulder}, {kModelRightElbow, kModelLeftElbow},
                            {kModelRightWrist, kModelLeftWrist}, {kModelLeftHandTip, kModelRightHandTip},
                            {kModelNeck, kModelNeck}, {kModelWaist, kModelWaist}}) {
      EXPECT_LT((b.joints[to] - a.joints[from]).norm(), 1e-9) << ModelJointName(from) << " trial " << trial;
    }
    const Eigen::Vector3d forward(-std::sin(pose.dof[kDofYaw]), std::cos(pose.dof[kDofYaw]), 0);
    EXPECT_LT((b.joints[kModelHead] - (a.joints[kModelHead] - 2 * shape.spine_depth_m * forward)).norm(), 1e-9);
    EXPECT_LT((b.joints[kModelRoot] - (a.joints[kModelRoot] + 2 * shape.ankle_setback_m * forward)).norm(), 1e-9);
  }
}

// The hand's elevation seen from the shoulder, degrees above the horizontal
// (the bodies here stand upright, so the world's z is the upper body's).
double HandElevationDeg(const PosedBody& body, bool left) {
  const Vector3d d = body.joints[left ? kModelLeftHandTip : kModelRightHandTip] -
                     body.joints[left ? kModelLeftShoulder : kModelRightShoulder];
  return std::asin(d.z() / d.norm()) * 180 / M_PI;
}

// Thesis 6.3.2's posture proposal: the arm that is not in the recognised
// posture is moved into it (its elevation band, or hanging), the arm that is
// keeps every angle, and the pair goes to the arms the nearer way.
TEST(PoseTracker, ThePostureProposalMovesTheArmsIntoTheRecognisedPosture) {
  const BodyShape shape = BodyShape::FromHeight(1.75);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
  const ArmPostureBand rest{.rest = true}, up{.min_deg = 62.5, .max_deg = 90},
      diagonal{.min_deg = 22.5, .max_deg = 62.5};
  const double slack = 12;  // the proposal's jitter, 0.05 per direction component
  int raised_left = 0;
  for (int trial = 0; trial < 40; ++trial) {
    // Both arms hanging, one arm recognised up: either arm may take it.
    const BodyPose standing = StandingPose(shape, Vector2d(0.1, 0.2), yaw(rng));
    const std::optional<BodyPose> one_up = PostureProposal(standing, shape, {up, rest}, rng);
    ASSERT_TRUE(one_up);
    const PosedBody b = PoseBody(shape, *one_up);
    const bool left = HandElevationDeg(b, true) > HandElevationDeg(b, false);
    raised_left += left;
    EXPECT_GT(HandElevationDeg(b, left), 62.5 - slack) << trial;
    const int kept_shoulder = left ? kDofRightShoulderAzimuth : kDofLeftShoulderAzimuth;
    const int kept_elbow = left ? kDofRightElbowAzimuth : kDofLeftElbowAzimuth;
    for (int d : {kept_shoulder, kept_shoulder + 1, kept_elbow, kept_elbow + 1}) {
      EXPECT_EQ(one_up->dof[d], standing.dof[d]) << trial;
    }

    // The right arm held out level (not at rest) and the left hanging,
    // recognised as rest + diagonal: the right arm is nearer the diagonal
    // and rises into it, keeping its horizontal direction; the left stays.
    BodyPose level = standing;
    SetArmDirections(shape, &level, kRightUpperArm,
                     Vector3d(std::cos(level.dof[kDofYaw]), std::sin(level.dof[kDofYaw]), 0),
                     Vector3d(std::cos(level.dof[kDofYaw]), std::sin(level.dof[kDofYaw]), 0));
    const std::optional<BodyPose> raised = PostureProposal(level, shape, {rest, diagonal}, rng);
    ASSERT_TRUE(raised);
    const PosedBody r = PoseBody(shape, *raised), l = PoseBody(shape, level);
    EXPECT_GT(HandElevationDeg(r, false), 22.5 - slack) << trial;
    EXPECT_LT(HandElevationDeg(r, false), 62.5 + slack) << trial;
    const Vector3d before = l.joints[kModelRightHandTip] - l.joints[kModelRightShoulder];
    const Vector3d after = r.joints[kModelRightHandTip] - r.joints[kModelRightShoulder];
    const double turned = std::acos(std::clamp(before.head<2>().normalized().dot(after.head<2>().normalized()), -1.0, 1.0));
    EXPECT_LT(turned * 180 / M_PI, 15) << trial;
    for (int d : {kDofLeftShoulderAzimuth, kDofLeftShoulderZenith, kDofLeftElbowAzimuth, kDofLeftElbowZenith}) {
      EXPECT_EQ(raised->dof[d], level.dof[d]) << trial;
    }
    // A pose already in the posture is left to the other proposals.
    EXPECT_FALSE(PostureProposal(standing, shape, {rest, rest}, rng)) << trial;
  }
  // Both hanging arms are equally near: the pair goes either way.
  EXPECT_GT(raised_left, 5);
  EXPECT_LT(raised_left, 35);
}

}  // namespace
}  // namespace irbench

namespace irbench {
namespace {

// Tracks a 1.75 m model posed by `truth(frame, shape)` for `frames` frame-sets
// at 30 fps on the pinhole rig, with no screens (the screen is towards +y),
// from the model's features and, where `legs` is given, the hull it returns
// for the truth's pose. Returns the frames from `first` on whose tracked
// heading lies more than 90 deg from the truth's.
int TurnedRoundFrames(const PoseTrackerOptions& options, int frames, int first,
                      const std::function<BodyPose(int, const BodyShape&)>& truth,
                      const std::function<VoxelHull(const BodyPose&, const BodyShape&)>& legs = {}) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  PoseTracker tracker(cams, {}, options);
  int turned = 0;
  for (int f = 0; f < frames; ++f) {
    const BodyPose pose = truth(f, shape);
    FrameFeatures seen = ModelFeatures(cams, shape, pose, f);
    if (legs) seen.voxels = legs(pose, shape);
    const PoseEstimate e = tracker.Step(seen, 1.0 / 30);
    if (f >= first && std::cos(e.pose.dof[kDofYaw] - pose.dof[kDofYaw]) < 0) ++turned;
  }
  return turned;
}

// Front and back look alike: a model that walks along +x and then stands
// side-on to the screen before turning to it must keep facing where it
// walked (the walk's heading memory), never flip half way round. Without the
// memory (walk_memory_s ~ 0) this case flipped for 38 of its 96 frames.
int FlippedFramesAfterAWalk(double walk_memory_s, uint64_t seed = 7) {
  PoseTrackerOptions options;
  options.seed = seed;
  options.walk_memory_s = walk_memory_s;
  const double walk_yaw = YawFacing(Vector2d::UnitX()), screen_yaw = YawFacing(Vector2d::UnitY());
  return TurnedRoundFrames(options, 120, 24, [&](int f, const BodyShape& shape) {
    const double x = -0.8 + std::min(f, 36) / 30.0;  // 1 m/s for 1.2 s, then standing
    double yaw = walk_yaw;
    if (f >= 75) yaw = walk_yaw + WrapAngle(screen_yaw - walk_yaw) * std::min(1.0, (f - 75) / 30.0);
    return StandingPose(shape, Vector2d(x, 0.3), yaw);
  });
}

// Over filter seeds 1-12, at most one frame in 96 flips (seeds 2 and 12);
// a single seed is one sample, so the test takes six.
TEST(PoseTracker, KeepsFacingWhereItWalkedUntilItTurns) {
  int total = 0;
  for (uint64_t seed = 5; seed <= 10; ++seed) {
    const int flipped = FlippedFramesAfterAWalk(PoseTrackerOptions().walk_memory_s, seed);
    EXPECT_LE(flipped, 2) << "seed " << seed;
    total += flipped;
  }
  EXPECT_LE(total, 3);
}

// A hull of two legs standing at `mid` (the ankles' midpoint), `forward`
// and `side` unit and horizontal, lifted by `lift`: vertical shins (5.5 cm
// radius) from the ankles' height `ankle_z` to 0.5 m above each ankle, 11 cm
// to each side, and feet from 5 cm behind to 19 cm ahead of each ankle.
// `nz` layers of the stage's grid (the legs' estimate reads nothing higher).
VoxelHull LegsHull(const Vector2d& mid, const Vector2d& side, const Vector2d& forward, double ankle_z, double lift,
                   int nz) {
  VoxelHull hull = EmptyStageHull();
  hull.nz = nz;
  hull.occupied.assign(size_t(hull.nx) * hull.ny * hull.nz, 0);
  FillHull(&hull, [&](const Vector3d& c) {
    const double z = c.z() - lift;
    for (double s : {-1.0, 1.0}) {
      const Vector2d d = c.head<2>() - (mid + s * 0.11 * side);
      if (z >= ankle_z && z < 0.5 && d.norm() < 0.055) return true;
      if (z >= 0 && z < ankle_z && d.dot(forward) > -0.05 && d.dot(forward) < 0.19 && std::abs(d.dot(side)) < 0.045)
        return true;
    }
    return false;
  });
  return hull;
}

// A step back is not a walk: a model standing side-on to the screen (it is
// towards +y) and facing +x, its hull's feet reaching forward of its
// ankles, steps back 0.6 m at 0.6 m/s and stands again. The feet keep the
// heading; taken for a walk (step_max_speed_mps 0, as before the rule) the
// move turned the model to face where it moved, front to back, for most of
// the frames from the step on. Returns the frames whose tracked heading
// lies more than 90 deg from the truth's.
int FlippedFramesOverAStepBack(double step_max_speed_mps, uint64_t seed) {
  PoseTrackerOptions options;
  options.seed = seed;
  options.step_max_speed_mps = step_max_speed_mps;
  const Vector2d forward = Vector2d::UnitX(), side(0, -1);
  const double yaw = YawFacing(forward);
  return TurnedRoundFrames(
      options, 100, 15,
      [&](int f, const BodyShape& shape) {
        const double x = 0.3 - 0.6 * std::clamp((f - 20) / 30.0, 0.0, 1.0);  // 0.6 m/s back over frames 20-50
        return StandingPose(shape, Vector2d(x, 0.2), yaw);
      },
      [&](const BodyPose& pose, const BodyShape& shape) {
        // Vertical shins above each ankle, and feet reaching 19 cm ahead of it.
        const Vector2d mid = PoseBody(shape, pose).joints[kModelRoot].head<2>();
        return LegsHull(mid, side, forward, options.hull_legs.ankle * shape.height_m, 0.0, 26);
      });
}

// A model jumping 30 cm in place (frames 30-50, a parabola), its hull's
// legs lifted with it: the tracked waist's largest error while the feet are
// at least 15 cm up (lower hops are below min_floor_gap_m).
double WaistErrorOverAJump(double min_floor_gap_m, uint64_t seed) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  PoseTrackerOptions options;
  options.seed = seed;
  options.min_floor_gap_m = min_floor_gap_m;
  PoseTracker tracker(cams, {}, options);
  const Vector2d forward = Vector2d::UnitX(), side(0, -1);
  const double ankle_z = options.hull_legs.ankle * shape.height_m;
  double worst = 0;
  for (int f = 0; f < 70; ++f) {
    const double t = std::clamp((f - 30) / 20.0, 0.0, 1.0);
    const double lift = 1.2 * t * (1 - t);  // 0.3 m at the apex
    BodyPose truth = StandingPose(shape, Vector2d(0.1, 0.2), YawFacing(forward));
    truth.dof[kDofZ] += lift;
    FrameFeatures seen = ModelFeatures(cams, shape, truth, f);
    const Vector2d mid = PoseBody(shape, truth).joints[kModelRoot].head<2>();
    seen.voxels = LegsHull(mid, side, forward, ankle_z, lift, 40);
    const PoseEstimate e = tracker.Step(seen, 1.0 / 30);
    if (lift >= 0.15) worst = std::max(worst, std::abs(e.pose.dof[kDofZ] - truth.dof[kDofZ]));
  }
  return worst;
}

TEST(PoseTracker, FollowsAJumpWhereTheHullLeavesTheFloor) {
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    const double worst = WaistErrorOverAJump(PoseTrackerOptions().min_floor_gap_m, seed);
    EXPECT_LT(worst, 0.05) << "seed " << seed;
    std::printf("jump, seed %d: the waist at most %.1f cm off\n", int(seed), 100 * worst);
  }
  // Held to its standing height (the rule off), the waist stays low.
  const double capped = WaistErrorOverAJump(10.0, 1);
  EXPECT_GT(capped, 0.2);
  std::printf("jump with the waist held down: %.1f cm off\n", 100 * capped);
}

// A model rising 6 cm on tiptoe (frames 30-40) and staying up to frame 80:
// the hull's feet stay on the floor (not a jump) and its column over the
// head rises with the crown. The tracked waist's mean error over frames
// 50-80.
double WaistErrorOnTiptoe(double max_tiptoe_m, uint64_t seed) {
  const std::vector<Camera> cams = PinholeRig();
  const BodyShape shape = BodyShape::FromHeight(1.75);
  PoseTrackerOptions options;
  options.seed = seed;
  options.max_tiptoe_m = max_tiptoe_m;
  PoseTracker tracker(cams, {}, options);
  const Vector2d forward = Vector2d::UnitX(), side(0, -1);
  const double ankle_z = options.hull_legs.ankle * shape.height_m;
  double sum = 0;
  int count = 0;
  for (int f = 0; f < 80; ++f) {
    const double lift = 0.06 * std::clamp((f - 30) / 10.0, 0.0, 1.0);
    BodyPose truth = StandingPose(shape, Vector2d(0.1, 0.2), YawFacing(forward));
    truth.dof[kDofZ] += lift;
    FrameFeatures seen = ModelFeatures(cams, shape, truth, f);
    const PosedBody body = PoseBody(shape, truth);
    seen.placement->top_m = shape.height_m + lift;
    seen.voxels = LegsHull(body.joints[kModelRoot].head<2>(), side, forward, ankle_z, 0.0, 110);
    const Vector2d head = body.joints[kModelHead].head<2>();
    FillHull(&*seen.voxels, [&](const Vector3d& c) {
      return (c.head<2>() - head).norm() < 0.09 && c.z() > 1.2 && c.z() < shape.height_m + lift;
    });
    const PoseEstimate e = tracker.Step(seen, 1.0 / 30);
    if (f >= 50) {
      sum += std::abs(e.pose.dof[kDofZ] - truth.dof[kDofZ]);
      ++count;
    }
  }
  return sum / count;
}

TEST(PoseTracker, RisesOnTiptoeWhereTheHullOverTheHeadDoes) {
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    const double error = WaistErrorOnTiptoe(0.10, seed);
    EXPECT_LT(error, 0.015) << "seed " << seed;
    std::printf("tiptoe, seed %d: the waist %.1f cm off on average\n", int(seed), 100 * error);
  }
  // Held to max_rise_m above its standing height (the rule off, as it is
  // by default): 4 cm low.
  const double capped = WaistErrorOnTiptoe(PoseTrackerOptions().max_tiptoe_m, 1);
  EXPECT_GT(capped, 0.03);
  std::printf("tiptoe with the waist held down: %.1f cm off\n", 100 * capped);
}

TEST(PoseTracker, AStepBackIsNotAWalk) {
  int total = 0;
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    const int flipped = FlippedFramesOverAStepBack(PoseTrackerOptions().step_max_speed_mps, seed);
    EXPECT_LE(flipped, 2) << "seed " << seed;
    total += flipped;
  }
  EXPECT_LE(total, 2);
  // The case is one the walk's heading gets wrong: without the rule most of
  // the 80 frames from the step on are turned round.
  const int as_walk = FlippedFramesOverAStepBack(0.0, 1);
  EXPECT_GE(as_walk, 40);
  std::printf("step back: %d frames turned round over seeds 1-2; %d of 85 taken for a walk\n", total, as_walk);
  PoseTrackerOptions bad;
  bad.step_feet_angle_deg = 200;
  EXPECT_THROW(bad.Check(), InputError);
  bad = PoseTrackerOptions();
  bad.step_max_speed_mps = -1;
  EXPECT_THROW(bad.Check(), InputError);
}

// A step back that nothing but its length tells from a walk: a model
// side-on to the screen (it is towards +y) and facing +x, with no hull to
// show its feet, stands for 2 s, steps back 0.3 m at 0.6 m/s (frames
// 60-75) and stands again. Returns the frames from frame 15 on whose
// tracked heading lies more than 90 deg from the truth's.
int FlippedFramesOverAShortStepBack(double step_back_max_s, uint64_t seed) {
  PoseTrackerOptions options;
  options.seed = seed;
  options.step_back_max_s = step_back_max_s;
  return TurnedRoundFrames(options, 150, 15, [](int f, const BodyShape& shape) {
    const double x = 0.3 - 0.3 * std::clamp((f - 60) / 15.0, 0.0, 1.0);
    return StandingPose(shape, Vector2d(x, 0.2), YawFacing(Vector2d::UnitX()));
  });
}

TEST(PoseTracker, AShortStepBackDoesNotTurnTheModelRound) {
  int total = 0;
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    const int flipped = FlippedFramesOverAShortStepBack(PoseTrackerOptions().step_back_max_s, seed);
    EXPECT_LE(flipped, 2) << "seed " << seed;
    total += flipped;
  }
  // Taken for a walk (the rule off), the step turns the model round.
  const int as_walk = FlippedFramesOverAShortStepBack(0.0, 1);
  EXPECT_GE(as_walk, 30);
  std::printf("short step back: %d frames turned round over seeds 1-2; %d of 135 with the rule off\n", total,
              as_walk);
  PoseTrackerOptions bad;
  bad.step_back_max_s = -1;
  EXPECT_THROW(bad.Check(), InputError);
  bad = PoseTrackerOptions();
  bad.heading_settled_s = std::nan("");
  EXPECT_THROW(bad.Check(), InputError);
}

}  // namespace
}  // namespace irbench
