// The tracker's front end against the truth on rendered sequences (thesis
// ch. 3): silhouettes from the background model on the `thesis` sensor preset
// (flicker, grain, soft shadows), shadow removal; the same frames without
// noise (the `clean` preset, with and without soft shadows); axis points and
// the voxel hull. The tracker's code reads only
// what a rig gives it (SequenceInput); this test reads the truth to score it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <random>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "ci/score/silhouette_score.h"
#include "sim/sequence/render_job.h"
#include "tests/test_util.h"
#include "tests/true_body.h"
#include "tracker/frontend/frontend.h"
#include "tracker/io/sequence_input.h"
#include "tracker/silhouette/background_model.h"
#include "tracker/silhouette/shadow_removal.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::WriteText;

cv::Mat TruthMask(const fs::path& seq, const std::string& cam, int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return cv::imread((seq / "truth/masks" / cam / name).string(), cv::IMREAD_UNCHANGED);
}

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const int u = cv::countNonZero(a | b);
  return u == 0 ? 1.0 : double(cv::countNonZero(a & b)) / u;
}

// The IoU the silhouette would have with the pixels within one pixel of the
// true outline (SilhouetteCounts' "near" pixels) set right and the rest as
// they are: how much of the error is the outline's pixel.
double OutlineRightIoU(const cv::Mat& truth, const cv::Mat& silhouette) {
  const SilhouetteCounts c = CountSilhouette(truth, silhouette);
  return double(c.intersection() + c.missed_near) / std::max(1L, c.truth + c.false_far);
}

// Front-end options for the silhouettes alone (they are made before the axes
// and the hull, which these tests do not read).
FrontEndOptions SilhouettesOnly() {
  FrontEndOptions options;
  options.find_axes = false;
  options.carve_voxels = false;
  return options;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// Renders `person` on theater4 with a sensor preset (default: the thesis
// preset; soft shadows as the preset has them unless `shadows` is given): a
// few frames of the atom tour, time-warped so they span many arm postures.
fs::path RenderThesis(const fs::path& dir, const std::string& person, int frames,
                      const std::string& sensor = "thesis", std::optional<bool> shadows = {}) {
  const fs::path session = dir / "tour.json";
  WriteText(session, R"({"format": "irbench.session/1", "items": [{"motion": "atom_tour", "speed": 6}]})");
  RenderJobOptions options;
  options.rig = "theater4";
  options.avatar = person;
  options.motion = session.string();
  options.sensor = sensor;
  options.shadows = shadows;
  options.frames = frames;
  options.background_frames = 12;
  options.seed = 7;
  options.out = dir / (person + "_" + sensor + (shadows ? (*shadows ? "_shadows" : "_no_shadows") : ""));
  return RunRenderJob(options);
}

TEST(FrontendClosedLoopTest, SilhouettesOnTheThesisPreset) {
  const fs::path dir = FreshTempDir("frontend_silhouettes");
  std::vector<double> iou_flicker, iou_plain, iou_raw, iou_outline_right;
  long fp_before = 0, fp_after = 0, body_before = 0, body_after = 0, truth_pixels = 0;
  for (const std::string person : {"p1", "p2", "p3", "p4", "p5"}) {
    const fs::path seq = RenderThesis(dir, person, 4);
    const SequenceInput in = SequenceInput::Open(seq);
    for (size_t c = 0; c < in.cameras().size(); ++c) {
      const int cam = static_cast<int>(c);
      const std::vector<cv::Mat> background = in.Backgrounds(cam);
      BackgroundOptions plain_options;
      plain_options.model = BackgroundKind::kPlain;
      const auto flicker = BackgroundModel::Train(background, {});
      const auto plain = BackgroundModel::Train(background, plain_options);
      const auto shadows = ShadowRemover::Train(background, {});
      ASSERT_TRUE(flicker && plain && shadows);
      for (int f = 0; f < in.frame_count(); ++f) {
        const cv::Mat frame = in.Frame(cam, f);
        const cv::Mat truth = TruthMask(seq, in.cameras()[c].name, f);
        const SilhouetteResult r = flicker->Segment(frame);
        const cv::Mat& sil = r.mask;
        const cv::Mat cleaned = shadows->Remove(frame, sil, r.darker);
        iou_raw.push_back(IoU(sil, truth));
        iou_flicker.push_back(IoU(cleaned, truth));
        iou_outline_right.push_back(OutlineRightIoU(truth, cleaned));
        const SilhouetteResult rp = plain->Segment(frame);
        iou_plain.push_back(IoU(shadows->Remove(frame, rp.mask, rp.darker), truth));
        fp_before += cv::countNonZero(sil & ~truth);
        fp_after += cv::countNonZero(cleaned & ~truth);
        body_before += cv::countNonZero(sil & truth);
        body_after += cv::countNonZero(cleaned & truth);
        truth_pixels += cv::countNonZero(truth);
      }
    }
    fs::remove_all(seq);
  }
  std::printf("silhouette IoU, median over %zu camera-frames: flicker model %.3f (before shadow removal %.3f), "
              "thesis plain model %.3f\n",
              iou_flicker.size(), Median(iou_flicker), Median(iou_raw), Median(iou_plain));
  std::printf("the same with the pixels within a pixel of the true outline set right (the rest as found): %.3f\n",
              Median(iou_outline_right));
  std::printf("truth pixels %ld: found %ld (%.1f%%), false foreground after %ld (%.1f%% of truth)\n", truth_pixels,
              body_after, 100.0 * body_after / std::max(1L, truth_pixels), fp_after,
              100.0 * fp_after / std::max(1L, truth_pixels));
  std::printf("false foreground pixels %ld -> %ld (%.0f%% fewer); body pixels lost %.2f%%\n", fp_before, fp_after,
              100.0 * (1 - double(fp_after) / std::max(1L, fp_before)),
              100.0 * (1 - double(body_after) / std::max(1L, body_before)));
  // Measured: median IoU 0.886 (0.821 before the outline refinement), plain
  // 0.561 (0.547 while shadow removal blurred the frame the plain model then
  // read); 92% fewer false-foreground pixels with 1.1% of the body lost.
  // Issue 6's shadow bar (down 70% with at most 3% of the body lost) is
  // asserted; the IoU floor sits under today's figure, so a regression fails.
  // The IoU bar (0.92) is not met: the front views reach 0.907, the side
  // 0.863 (clothing as grey as the floor behind it: p3's and p5's legs) and
  // the overhead 0.667 (body shadows on the floor, small silhouettes).
  EXPECT_GE(Median(iou_flicker), 0.85);
  // What is left lies on the outline: with its pixel right, 0.970 (issue 6's
  // bar, 0.92, is out of reach of the outline as found; see the test below).
  EXPECT_GE(Median(iou_outline_right), 0.95);
  EXPECT_GE(Median(iou_flicker) - Median(iou_plain), 0.2);
  EXPECT_LE(double(fp_after), 0.30 * double(fp_before));
  EXPECT_LE(1 - double(body_after) / std::max(1L, body_before), 0.03);
}

// The ceiling of the outline as the intensities show it: the same frames
// rendered with the `clean` preset (no noise, flicker or lens blur, and by its
// default no soft shadows). The body's brightness falls towards its rims (a
// rounded body lit from near the cameras), so its outermost half pixel is
// barely brighter than the stage even here: the median stays under issue 6's
// bar of 0.92 on these frames too, and the outline's pixel is still nearly
// all of what is missing.
TEST(FrontendClosedLoopTest, SilhouettesOnNoiseFreeFrames) {
  const fs::path dir = FreshTempDir("frontend_noise_free");
  std::vector<double> iou, iou_outline_right;
  std::vector<std::vector<double>> by_camera(4);
  std::vector<std::string> camera_names(4);
  for (const std::string person : {"p1", "p2", "p3", "p4", "p5"}) {
    const fs::path seq = RenderThesis(dir, person, 4, "clean");
    const SequenceInput in = SequenceInput::Open(seq);
    ASSERT_EQ(in.cameras().size(), by_camera.size());
    const FrontEnd front_end = FrontEnd::Train(in, SilhouettesOnly());
    for (int f = 0; f < in.frame_count(); ++f) {
      const std::vector<cv::Mat> images = in.FrameSet(f);
      const FrameFeatures features = front_end.Process(f, images);
      for (size_t c = 0; c < in.cameras().size(); ++c) {
        const cv::Mat truth = TruthMask(seq, in.cameras()[c].name, f);
        iou.push_back(IoU(features.cameras[c].silhouette, truth));
        iou_outline_right.push_back(OutlineRightIoU(truth, features.cameras[c].silhouette));
        by_camera[c].push_back(iou.back());
        camera_names[c] = in.cameras()[c].name;
      }
    }
    fs::remove_all(seq);
  }
  std::string per_camera;
  for (size_t c = 0; c < by_camera.size(); ++c) {
    char item[64];
    std::snprintf(item, sizeof(item), "%s%s %.3f", c ? ", " : "", camera_names[c].c_str(), Median(by_camera[c]));
    per_camera += item;
  }
  std::printf("noise-free frames: silhouette IoU median over %zu camera-frames %.3f (%s); with the outline's pixel "
              "set right %.3f\n",
              iou.size(), Median(iou), per_camera.c_str(), Median(iou_outline_right));
  // Measured 2026-11-26: 0.897 (front 0.901 and 0.886, overhead 0.844, side
  // 0.915); with the outline's pixel right 0.988. Floors under them.
  EXPECT_GE(Median(iou), 0.87);
  EXPECT_GE(Median(iou_outline_right), 0.97);
}

// Soft shadows without noise (the clean preset with its soft shadows turned
// on): the pooled evidence finds the floor shadows a grey level deep, and with
// Canny's thresholds set for the washed-out thesis images the penumbra next to
// the feet passes as an edge, so shadow removal keeps a wedge of it. Scaled
// for the clean image's contrast (irbench track --shadow-edge-scale 2), the
// thresholds keep the penumbra out.
TEST(FrontendClosedLoopTest, SoftShadowsWithoutNoiseNeedTheEdgeThresholdsScaled) {
  const fs::path dir = FreshTempDir("frontend_clean_shadows");
  std::vector<double> iou_thesis_edges, iou_scaled;
  FrontEndOptions scaled = SilhouettesOnly();
  scaled.shadow.canny_low *= 2;
  scaled.shadow.canny_high *= 2;
  for (const std::string person : {"p1", "p2", "p3", "p4", "p5"}) {
    const fs::path seq = RenderThesis(dir, person, 4, "clean", true);
    const SequenceInput in = SequenceInput::Open(seq);
    const FrontEnd thesis_edges = FrontEnd::Train(in, SilhouettesOnly());
    const FrontEnd scaled_edges = FrontEnd::Train(in, scaled);
    for (int f = 0; f < in.frame_count(); ++f) {
      const std::vector<cv::Mat> images = in.FrameSet(f);
      const FrameFeatures a = thesis_edges.Process(f, images), b = scaled_edges.Process(f, images);
      for (size_t c = 0; c < in.cameras().size(); ++c) {
        const cv::Mat truth = TruthMask(seq, in.cameras()[c].name, f);
        iou_thesis_edges.push_back(IoU(a.cameras[c].silhouette, truth));
        iou_scaled.push_back(IoU(b.cameras[c].silhouette, truth));
      }
    }
    fs::remove_all(seq);
  }
  std::printf("clean preset with soft shadows: silhouette IoU median over %zu camera-frames %.3f with the thesis "
              "preset's edge thresholds, %.3f with them doubled\n",
              iou_scaled.size(), Median(iou_thesis_edges), Median(iou_scaled));
  // Measured 2026-11-26: 0.608 and 0.872 (Canny's thresholds x1.5: 0.870,
  // x3: 0.871; on the thesis preset x1 is best).
  EXPECT_GE(Median(iou_scaled), 0.85);
  EXPECT_GE(Median(iou_scaled) - Median(iou_thesis_edges), 0.15);
}

Eigen::Vector3d Joint(const nlohmann::json& frame, const std::string& name) {
  const auto& j = frame["joints3d"][name];
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double s = std::clamp((p - a).dot(b - a) / std::max(1e-12, (b - a).squaredNorm()), 0.0, 1.0);
  return (a + s * (b - a) - p).norm();
}

// The whole front end on the thesis preset — silhouettes from the background
// model, shadows removed, 2D axes, body parts, 3D axis points — while an arm
// is raised: the 3D arm points against the true arm bones (issue bar: median
// within 4 cm).
TEST(FrontendClosedLoopTest, ArmAxisFromThesisSilhouettes) {
  const fs::path dir = FreshTempDir("frontend_axes");
  std::vector<double> distances;
  for (const auto& [person, motion] : {std::pair<std::string, std::string>{"p1", "raise_overhead"},
                                       {"p3", "flap_both"}}) {
    RenderJobOptions options;
    options.rig = "theater4";
    options.avatar = person;
    options.motion = motion;
    options.sensor = "thesis";
    options.frames = 34;
    options.background_frames = 12;
    options.seed = 3;
    options.out = dir / person;
    const fs::path seq = RunRenderJob(options);
    const SequenceInput in = SequenceInput::Open(seq);
    const FrontEnd front_end = FrontEnd::Train(in, {});
    std::ifstream truth(seq / "truth/frames.jsonl");
    int frames = 0, total_arm_points = 0;
    for (std::string line; std::getline(truth, line);) {
      const auto frame = nlohmann::json::parse(line);
      const int f = frame["frame"];
      bool raised = false;
      for (const std::string side : {"left", "right"}) {
        raised |= Joint(frame, side + "_wrist").z() > Joint(frame, side + "_shoulder").z() - 0.1;
      }
      if (!raised || f % 3 != 0) continue;
      const std::vector<cv::Mat> images = in.FrameSet(f);
      const FrameFeatures features = front_end.Process(f, images);
      int arm_points = 0;
      for (const AxisPoint3d& p : features.axis3d) {
        if (p.part != BodyPart::kArm) continue;
        double nearest = 1e9;
        for (const std::string side : {"left", "right"}) {
          nearest = std::min({nearest,
                              DistanceToSegment(p.p_in_world, Joint(frame, side + "_shoulder"), Joint(frame, side + "_elbow")),
                              DistanceToSegment(p.p_in_world, Joint(frame, side + "_elbow"), Joint(frame, side + "_wrist")),
                              DistanceToSegment(p.p_in_world, Joint(frame, side + "_wrist"), Joint(frame, side + "_hand_tip"))});
        }
        distances.push_back(nearest);
        ++arm_points;
      }
      total_arm_points += arm_points;
      ++frames;
    }
    EXPECT_GE(frames, 3) << person;
    // Some views lose a forearm against the wall; most frames keep plenty.
    EXPECT_GT(total_arm_points, 8 * frames) << person;
    fs::remove_all(seq);
  }
  std::sort(distances.begin(), distances.end());
  ASSERT_FALSE(distances.empty());
  const double median = distances[distances.size() / 2], p90 = distances[distances.size() * 9 / 10];
  std::printf("3D arm axis points from thesis-preset silhouettes: %zu points, distance to the true arm bones "
              "median %.1f mm, p90 %.1f mm\n",
              distances.size(), 1000 * median, 1000 * p90);
  EXPECT_LE(median, 0.04);
}

// The voxel hull carved from the front end's own silhouettes (thesis preset),
// against the true body: how much of it the hull holds and how large it is.
TEST(FrontendClosedLoopTest, VoxelHullFromThesisSilhouettes) {
  const fs::path dir = FreshTempDir("frontend_hull");
  std::vector<double> containment, ratio, containment_tolerant, ratio_tolerant;
  std::mt19937 rng(5);
  for (const std::string person : {"p1", "p3", "p4"}) {
    RenderJobOptions options;
    options.rig = "theater4";
    options.avatar = person;
    options.motion = (dir / "tour.json").string();
    WriteText(dir / "tour.json", R"({"format": "irbench.session/1", "items": [{"motion": "atom_tour", "speed": 6}]})");
    options.sensor = "thesis";
    options.frames = 3;
    options.background_frames = 12;
    options.seed = 9;
    options.out = dir / person;
    const fs::path seq = RunRenderJob(options);
    const RenderInputs truth_inputs = LoadRenderInputs(options);
    const SequenceInput in = SequenceInput::Open(seq);
    FrontEndOptions fe_options;
    fe_options.find_axes = false;
    fe_options.polyhedral_hull = false;
    const FrontEnd front_end = FrontEnd::Train(in, fe_options);
    VoxelGridOptions tolerant_options;
    tolerant_options.max_missing_views = 1;
    const VoxelCarver tolerant(in.cameras(), tolerant_options);
    for (int f = 0; f < in.frame_count(); ++f) {
      const std::vector<cv::Mat> images = in.FrameSet(f);
      const FrameFeatures features = front_end.Process(f, images);
      ASSERT_TRUE(features.voxels);
      const irbench::testing::BodyMesh body = irbench::testing::PosedBody(truth_inputs, f);
      std::uniform_real_distribution<double> ux(body.lo.x(), body.hi.x()), uy(body.lo.y(), body.hi.y()),
          uz(body.lo.z(), body.hi.z());
      std::vector<cv::Mat> silhouettes;
      for (const CameraFeatures& cf : features.cameras) silhouettes.push_back(cf.silhouette);
      const VoxelHull tolerant_hull = tolerant.Carve(silhouettes);
      int inside = 0, held = 0, held_tolerant = 0;
      while (inside < 2000) {
        const Eigen::Vector3d p(ux(rng), uy(rng), uz(rng));
        if (!irbench::testing::Inside(body, p)) continue;
        ++inside;
        held += features.voxels->ContainsPoint(p);
        held_tolerant += tolerant_hull.ContainsPoint(p);
      }
      const double volume = irbench::testing::Volume(body);
      containment.push_back(double(held) / inside);
      ratio.push_back(features.voxels->VolumeM3() / volume);
      containment_tolerant.push_back(double(held_tolerant) / inside);
      ratio_tolerant.push_back(tolerant_hull.VolumeM3() / volume);
      std::printf("%s frame %d: voxel hull holds %.1f%% of the body, volume %.2fx; one view may miss: %.1f%%, %.2fx\n",
                  person.c_str(), f, 100 * containment.back(), ratio.back(), 100 * containment_tolerant.back(),
                  ratio_tolerant.back());
    }
    fs::remove_all(seq);
  }
  std::printf("voxel hull from thesis-preset silhouettes: containment median %.1f%%, volume ratio median %.2f; "
              "one view may miss: %.1f%%, %.2f\n",
              100 * Median(containment), Median(ratio), 100 * Median(containment_tolerant), Median(ratio_tolerant));
  // Floors under today's figures (94.2%, 1.47x; tolerant 99.9%, 3.50x;
  // before the outline refinement 79.3%, 1.35x and 93.8%, 2.95x). The
  // issue's bars (98%, at most 2x) are met on the truth masks
  // (tracker/hull/hull_closed_loop_test.cc), not yet on the tracker's own
  // silhouettes: a body part one camera loses is carved away.
  EXPECT_GE(Median(containment), 0.9);
  EXPECT_LE(Median(ratio), 2.0);
  EXPECT_GE(Median(containment_tolerant), 0.97);
  EXPECT_GT(Median(containment_tolerant), Median(containment));
}

// One camera's silhouette loses the legs (in the `harsh` preset the side
// camera sees trousers as grey as the wall behind): the hull of all views
// then holds no standing person, and the placement comes from the other
// views. Truth masks stand for the silhouettes; the lost legs are cut out of
// one camera's mask below the waist.
TEST(FrontendClosedLoopTest, PlacementWithoutTheViewThatLostTheLegs) {
  const fs::path dir = FreshTempDir("frontend_placement");
  const fs::path seq = RenderThesis(dir, "p2", 3);
  const SequenceInput in = SequenceInput::Open(seq);
  const VoxelCarver carver(in.cameras());
  std::ifstream truth_in(seq / "truth/frames.jsonl");
  std::vector<nlohmann::json> truth;
  for (std::string line; std::getline(truth_in, line);) truth.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(static_cast<int>(truth.size()), in.frame_count());
  for (int f = 0; f < in.frame_count(); ++f) {
    std::vector<cv::Mat> masks;
    for (const Camera& cam : in.cameras()) masks.push_back(TruthMask(seq, cam.name, f));
    const std::optional<BodyPlacement> full = PlaceBody(carver.Carve(masks));
    ASSERT_TRUE(full) << "frame " << f;
    EXPECT_LT((full->root.head<2>() - Joint(truth[f], "root").head<2>()).norm(), 0.10);
    // Every view agrees with the others' hull (the least, the side camera,
    // covers 0.59-0.60 of it here; a view that lost the legs 0.24-0.35):
    // none is dropped.
    const double max_coverage = FrontEndOptions().placement_max_coverage;
    EXPECT_FALSE(PlaceBodyWithoutOneView(carver, masks, max_coverage)) << "frame " << f;
    for (size_t lost = 0; lost < masks.size(); ++lost) {
      const Camera& cam = in.cameras()[lost];
      const auto& waist = truth[f]["joints2d"][cam.name]["waist"];
      const int cut = static_cast<int>(waist[1].get<double>());
      // The overhead camera sees the legs under the body, not below the waist.
      if (cam.name == "overhead" || cut <= 0 || cut >= cam.height) continue;
      std::vector<cv::Mat> broken = masks;
      broken[lost] = masks[lost].clone();
      broken[lost].rowRange(cut, cam.height).setTo(0);
      EXPECT_FALSE(PlaceBody(carver.Carve(broken))) << cam.name << ", frame " << f;
      const std::optional<BodyPlacement> p = PlaceBodyWithoutOneView(carver, broken, max_coverage);
      ASSERT_TRUE(p) << cam.name << ", frame " << f;
      EXPECT_EQ(p->dropped_view, static_cast<int>(lost)) << cam.name << ", frame " << f;
      // From the caller's distance transforms: the same placement, and the
      // transforms as they were (the view left out must not be written into).
      std::vector<cv::Mat> distances, before;
      for (const cv::Mat& m : broken) {
        distances.push_back(DistanceToSilhouette(m));
        before.push_back(distances.back().clone());
      }
      const std::optional<BodyPlacement> q = PlaceBodyWithoutOneView(carver, broken, max_coverage, &distances);
      ASSERT_TRUE(q) << cam.name << ", frame " << f;
      EXPECT_EQ(q->dropped_view, p->dropped_view);
      EXPECT_EQ(q->root, p->root);
      EXPECT_EQ(q->dropped_view_coverage, p->dropped_view_coverage);
      for (size_t c = 0; c < distances.size(); ++c) EXPECT_EQ(cv::norm(distances[c], before[c], cv::NORM_INF), 0);
      // Without the side camera the legs' hull is longer in depth: 6 cm.
      EXPECT_LT((p->root - full->root).norm(), 0.08) << cam.name << ", frame " << f;
      std::printf("frame %d, %s without legs: placed from the others, coverage %.2f, root %.1f cm from the full hull's\n",
                  f, cam.name.c_str(), p->dropped_view_coverage, 100 * (p->root - full->root).norm());
    }
  }
  // An empty stage stays empty.
  std::vector<cv::Mat> empty;
  for (const Camera& cam : in.cameras()) empty.push_back(cv::Mat::zeros(cam.height, cam.width, CV_8U));
  EXPECT_FALSE(PlaceBodyWithoutOneView(carver, empty, FrontEndOptions().placement_max_coverage));
  FrontEndOptions bad;
  bad.placement_max_coverage = 0;
  EXPECT_THROW(bad.Check(), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace irbench
