#include "tracker/hull/voxel_hull.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "common/error.h"
#include "tracker/hull/hull_test_util.h"

namespace irbench {
namespace {
using irbench::testing::BoxSilhouette;
using irbench::testing::HullRig;
using irbench::testing::SphereSilhouette;

using irbench::testing::kSphereCentre;
using irbench::testing::kSphereRadius;

// Points of the solid, sampled on a jittered grid at voxel spacing, that do not
// lie in an occupied voxel; `checked` counts the samples.
template <typename Inside>
int Missed(const VoxelHull& hull,
           const Eigen::Vector3d& lo,
           const Eigen::Vector3d& hi,
           Inside inside,
           int* checked_out = nullptr) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(0, 1);
  const double step = hull.voxel_size_m;
  int checked = 0, missed = 0;
  for (double x = lo.x(); x <= hi.x(); x += step) {
    for (double y = lo.y(); y <= hi.y(); y += step) {
      for (double z = lo.z(); z <= hi.z(); z += step) {
        const Eigen::Vector3d p = Eigen::Vector3d(x, y, z) +
                                  step * Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
        if (!inside(p)) continue;
        ++checked;
        if (!hull.ContainsPoint(p)) ++missed;
      }
    }
  }
  if (checked_out) *checked_out = checked;
  return missed;
}

// Silhouettes rasterised at pixel centres lie up to 1/sqrt(2) px inside the
// true outline, so containing every point of the solid takes that margin.
VoxelGridOptions Strict() {
  VoxelGridOptions options;
  options.margin_px = 0.75;
  return options;
}

std::vector<cv::Mat> Spheres(const std::vector<Camera>& cams) {
  std::vector<cv::Mat> out;
  for (const Camera& cam : cams) out.push_back(SphereSilhouette(cam, kSphereCentre, kSphereRadius));
  return out;
}

TEST(VoxelHullTest, ContainsTheSphereWithBoundedVolume) {
  auto in_sphere = [](const Eigen::Vector3d& p) { return (p - kSphereCentre).norm() < kSphereRadius; };
  const Eigen::Vector3d lo = kSphereCentre.array() - kSphereRadius, hi = kSphereCentre.array() + kSphereRadius;
  const double sphere = 4.0 / 3.0 * M_PI * std::pow(kSphereRadius, 3);
  for (int ring : {4, 6}) {
    const std::vector<Camera> cams = HullRig(ring, 2);
    const VoxelHull hull = VoxelCarver(cams, Strict()).Carve(Spheres(cams));
    int checked = 0;
    EXPECT_EQ(Missed(hull, lo, hi, in_sphere, &checked), 0);
    EXPECT_GT(checked, 5000);
    const double ratio = hull.VolumeM3() / sphere;
    EXPECT_GT(ratio, 1.0);
    // The exact visual hull of a sphere from 6-8 spread views is within ~15%
    // of the sphere; the test disk (projected voxel radius, 2.2 cm, plus
    // 0.75 px, 1 cm) adds a shell of at most about 3 cm: a factor
    // (0.33 / 0.3)^3 = 1.33.
    EXPECT_LT(ratio, 1.15 * 1.33);
    // No occupied voxel is far from the sphere (the cones meet near it).
    for (const Eigen::Vector3d& c : hull.OccupiedCenters())
      EXPECT_LT((c - kSphereCentre).norm(), kSphereRadius + 0.1);
    // The default (margin 0) loses at most a sliver at the outline.
    const VoxelHull tight = VoxelCarver(cams).Carve(Spheres(cams));
    const int missed = Missed(tight, lo, hi, in_sphere);
    EXPECT_LE(missed, checked / 500);
    EXPECT_LT(tight.occupied_count, hull.occupied_count);
    std::printf(
        "sphere, %d cameras: volume ratio %.3f (margin 0.75 px), %.3f with %.2f%% contained "
        "(margin 0)\n",
        ring + 2, ratio, tight.VolumeM3() / sphere, 100.0 - 100.0 * missed / checked);
  }
}

// One camera loses the sphere: the thesis's hull loses it with it; a carver
// that lets one view disagree keeps exactly the hull of the other views.
TEST(VoxelHullTest, OneMissingViewIsToleratedWhenAsked) {
  const std::vector<Camera> cams = HullRig(6, 2);
  std::vector<cv::Mat> sil = Spheres(cams);
  sil[3] = cv::Mat::zeros(sil[3].size(), CV_8UC1);
  VoxelGridOptions strict = Strict();
  strict.voxel_size_m = 0.03;
  strict.min_corner_m = {-0.5, -0.5, 0.4};
  strict.max_corner_m = {0.8, 0.7, 1.6};
  EXPECT_EQ(VoxelCarver(cams, strict).Carve(sil).occupied_count, 0);
  VoxelGridOptions tolerant = strict;
  tolerant.max_missing_views = 1;
  const VoxelHull kept = VoxelCarver(cams, tolerant).Carve(sil);
  std::vector<Camera> others = cams;
  others.erase(others.begin() + 3);
  std::vector<cv::Mat> other_sil = Spheres(others);
  const VoxelHull reference = VoxelCarver(others, strict).Carve(other_sil);
  // The same voxels, except where a voxel was seen by only two cameras, one
  // of them the blind one (then no hull holds it).
  int differ = 0;
  for (size_t i = 0; i < kept.occupied.size(); ++i) differ += kept.occupied[i] != reference.occupied[i];
  EXPECT_LE(differ, reference.occupied_count / 100);
  EXPECT_GT(reference.occupied_count, 300);
  auto in_sphere = [](const Eigen::Vector3d& p) { return (p - kSphereCentre).norm() < kSphereRadius; };
  EXPECT_EQ(Missed(kept, kSphereCentre.array() - kSphereRadius, kSphereCentre.array() + kSphereRadius, in_sphere), 0);
  tolerant.max_missing_views = -1;
  EXPECT_THROW(tolerant.Check(), InputError);
}

TEST(VoxelHullTest, ContainsTheBox) {
  const Eigen::Vector3d lo(-0.35, -0.2, 0.4), hi(0.25, 0.3, 1.6);
  const std::vector<Camera> cams = HullRig(4, 1);
  VoxelGridOptions options = Strict();
  options.voxel_size_m = 0.03;
  const VoxelCarver carver(cams, options);
  std::vector<cv::Mat> sil;
  for (const Camera& cam : cams) sil.push_back(BoxSilhouette(cam, lo, hi));
  const VoxelHull hull = carver.Carve(sil);
  EXPECT_EQ(Missed(hull, lo, hi,
                   [&](const Eigen::Vector3d& p) {
                     return (p.array() > lo.array()).all() && (p.array() < hi.array()).all();
                   }),
            0);
  const double ratio = hull.VolumeM3() / (hi - lo).prod();
  std::printf("box, 5 cameras: volume ratio %.3f\n", ratio);
  EXPECT_GT(ratio, 1.0);
  EXPECT_LT(ratio, 2.0);
}

// The look-up table and the interpolated distance transforms give the same
// answer as measuring, per voxel, the distance from its projected centre to
// every silhouette pixel centre: identical except within the interpolation
// error of the distance field (about half a pixel) of the threshold.
TEST(VoxelHullTest, MatchesABruteForceCarving) {
  const std::vector<Camera> cams = HullRig(4, 0);
  VoxelGridOptions options;
  options.voxel_size_m = 0.05;
  options.min_observing_cameras = 1;
  options.margin_px = 0.3;
  const VoxelCarver carver(cams, options);
  const std::vector<cv::Mat> sil = Spheres(cams);
  const VoxelHull hull = carver.Carve(sil);
  std::vector<std::vector<Eigen::Vector2d>> pixels(cams.size());
  for (size_t c = 0; c < cams.size(); ++c) {
    for (int v = 0; v < 240; ++v) {
      for (int u = 0; u < 320; ++u) {
        if (sil[c].at<uint8_t>(v, u)) pixels[c].emplace_back(u, v);
      }
    }
  }
  int agree = 0, borderline = 0;
  for (int z = 0; z < hull.nz; ++z) {
    for (int y = 0; y < hull.ny; ++y) {
      for (int x = 0; x < hull.nx; ++x) {
        const Eigen::Vector3d centre = hull.VoxelCenter(x, y, z);
        if ((centre - kSphereCentre).norm() > 0.6) {
          EXPECT_FALSE(hull.Occupied(x, y, z));  // every camera sees it, far off the sphere
          continue;
        }
        bool keep = true, unsure = false;
        for (size_t c = 0; c < cams.size(); ++c) {
          const Eigen::Vector2d pc = cams[c].Project(centre);
          double radius = 0;
          for (int k = 0; k < 8; ++k) {
            const Eigen::Vector3d corner =
                hull.origin_m +
                hull.voxel_size_m * Eigen::Vector3d(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2));
            radius = std::max(radius, (cams[c].Project(corner) - pc).norm());
          }
          radius += options.margin_px;
          double nearest = 1e9;
          for (const Eigen::Vector2d& p : pixels[c]) nearest = std::min(nearest, (p - pc).norm());
          if (std::abs(nearest - radius) < 0.6) unsure = true;
          if (nearest > radius) keep = false;
        }
        if (unsure) {
          ++borderline;
          continue;
        }
        EXPECT_EQ(hull.Occupied(x, y, z), keep) << x << " " << y << " " << z;
        agree += keep;
      }
    }
  }
  EXPECT_GT(agree, 100);
  EXPECT_LT(borderline, agree);
}

TEST(VoxelHullTest, CamerasThatDoNotSeeAVoxelDoNotCarveIt) {
  std::vector<Camera> cams = HullRig(4, 0);
  const VoxelCarver base(cams);
  const VoxelHull reference = base.Carve(Spheres(cams));
  EXPECT_GT(reference.occupied_count, 300);
  // A camera behind the stage looking away, with an empty silhouette.
  Camera away = cams[0];
  away.cam_from_world = *LookAt({0, -4, 1.5}, {0, -8, 1.5}, Eigen::Vector3d::UnitZ());
  cams.push_back(away);
  std::vector<cv::Mat> sil = Spheres(cams);
  EXPECT_EQ(cv::countNonZero(sil.back()), 0);
  const VoxelHull hull = VoxelCarver(cams).Carve(sil);
  EXPECT_EQ(hull.occupied, reference.occupied);
  // An empty silhouette in a camera that sees the sphere carves everything.
  sil = Spheres(cams);
  sil[1].setTo(0);
  EXPECT_EQ(VoxelCarver(cams).Carve(sil).occupied_count, 0);
}

// The coarse-to-fine carving (block bounds from the distance transform) keeps
// exactly the voxels that testing every candidate in every camera keeps: on
// the sphere and box fixtures, with 0 and 1 missing views allowed, with a view
// that lost the solid, with wide and zero footprints, and on random blobs.
TEST(VoxelHullTest, CoarseToFineEqualsThePerVoxelReference) {
  struct Case {
    std::string name;
    std::vector<Camera> cams;
    VoxelGridOptions options;
    std::vector<std::vector<cv::Mat>> silhouette_sets;
    int min_occupied;  // over the first set; guards against a vacuous match
  };
  const std::vector<Camera> ring8 = HullRig(6, 2), ring5 = HullRig(4, 1), ring4 = HullRig(4, 0);
  std::vector<cv::Mat> lost = Spheres(ring8);
  lost[3].setTo(0);
  const Eigen::Vector3d lo(-0.35, -0.2, 0.4), hi(0.25, 0.3, 1.6);
  std::vector<cv::Mat> box;
  for (const Camera& cam : ring5) box.push_back(BoxSilhouette(cam, lo, hi));
  // Random spheres scattered over the stage: many separate silhouette edges,
  // some of them near the image borders.
  std::vector<cv::Mat> blobs(ring4.size());
  for (cv::Mat& m : blobs) m = cv::Mat::zeros(240, 320, CV_8UC1);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> xy(-1.4, 1.4), z(0.1, 2.1), r(0.03, 0.25);
  for (int i = 0; i < 12; ++i) {
    const Eigen::Vector3d centre(xy(rng), xy(rng), z(rng));
    const double radius = r(rng);
    for (size_t c = 0; c < ring4.size(); ++c) blobs[c] |= SphereSilhouette(ring4[c], centre, radius);
  }
  std::vector<Case> cases;
  for (int missing : {0, 1}) {
    const std::string tag = ", max_missing_views " + std::to_string(missing);
    VoxelGridOptions options;  // the default 2 cm grid over the stage
    options.max_missing_views = missing;
    cases.push_back({"sphere, 8 cameras, default" + tag, ring8, options, {Spheres(ring8), lost}, 10000});
    VoxelGridOptions strict = Strict();
    strict.max_missing_views = missing;
    strict.voxel_size_m = 0.025;
    cases.push_back({"sphere, 8 cameras, margin 0.75 px" + tag, ring8, strict, {Spheres(ring8)}, 5000});
    VoxelGridOptions centre_only = options;
    centre_only.footprint_scale = 0;
    centre_only.voxel_size_m = 0.03;
    cases.push_back({"sphere, 8 cameras, centre only" + tag, ring8, centre_only, {Spheres(ring8)}, 2000});
    VoxelGridOptions wide = options;
    wide.footprint_scale = 2;
    wide.margin_px = 3;
    wide.voxel_size_m = 0.03;
    cases.push_back({"sphere, 8 cameras, wide disk" + tag, ring8, wide, {Spheres(ring8)}, 2000});
    VoxelGridOptions box_options = Strict();
    box_options.max_missing_views = missing;
    box_options.voxel_size_m = 0.03;
    cases.push_back({"box, 5 cameras" + tag, ring5, box_options, {box}, 10000});
    VoxelGridOptions blob_options = options;
    blob_options.min_observing_cameras = missing + 1;  // the least that lets every voxel be carved
    blob_options.voxel_size_m = 0.025;
    cases.push_back({"random spheres, 4 cameras" + tag, ring4, blob_options, {blobs}, 10000});
  }
  for (const Case& test : cases) {
    SCOPED_TRACE(test.name);
    const VoxelCarver carver(test.cams, test.options);
    for (const std::vector<cv::Mat>& sil : test.silhouette_sets) {
      const VoxelHull fast = carver.Carve(sil);
      const VoxelHull reference = carver.CarveReference(sil);
      EXPECT_EQ(fast.occupied_count, reference.occupied_count);
      EXPECT_TRUE(fast.occupied == reference.occupied);
      // The blocks are carved in parallel: one thread gives the same hull.
      const int threads = cv::getNumThreads();
      cv::setNumThreads(1);
      std::vector<cv::Mat> distances;
      for (const cv::Mat& m : sil) distances.push_back(DistanceToSilhouette(m));
      const VoxelHull serial = carver.CarveDistances(distances);
      cv::setNumThreads(threads);
      EXPECT_EQ(serial.occupied_count, reference.occupied_count);
      EXPECT_TRUE(serial.occupied == reference.occupied);
      int counted = 0;
      for (uint8_t o : fast.occupied) counted += o;
      EXPECT_EQ(counted, fast.occupied_count);
      // OccupiedCenters reads only the carver's box and skips empty runs:
      // the same centres, in index order.
      std::vector<Eigen::Vector3d> centres;
      for (int z = 0; z < fast.nz; ++z) {
        for (int y = 0; y < fast.ny; ++y) {
          for (int x = 0; x < fast.nx; ++x) {
            if (fast.Occupied(x, y, z)) centres.push_back(fast.VoxelCenter(x, y, z));
          }
        }
      }
      const std::vector<Eigen::Vector3d> listed = fast.OccupiedCenters();
      EXPECT_TRUE(listed.size() == centres.size() &&
                  std::equal(listed.begin(), listed.end(), centres.begin()));
      std::printf("%s: %d voxels\n", test.name.c_str(), fast.occupied_count);
    }
    EXPECT_GE(carver.CarveReference(test.silhouette_sets[0]).occupied_count, test.min_occupied);
  }
}

TEST(VoxelHullTest, DistanceToSilhouetteEqualsOpenCvsExactTransform) {
  std::mt19937 rng(5);
  std::vector<cv::Mat> masks;
  cv::Mat one = cv::Mat::zeros(240, 320, CV_8UC1);
  one.at<uint8_t>(7, 311) = 255;
  masks.push_back(one);
  masks.push_back(cv::Mat(240, 320, CV_8UC1, cv::Scalar(255)));
  cv::Mat body = cv::Mat::zeros(240, 320, CV_8UC1);
  cv::ellipse(body, {160, 130}, {22, 45}, 0, 0, 360, 255, cv::FILLED);
  cv::line(body, {150, 100}, {95, 40}, 255, 8);
  cv::line(body, {170, 165}, {180, 239}, 255, 14);
  masks.push_back(body);
  for (double density : {0.0005, 0.01, 0.3}) {  // scattered pixels, the image borders included
    cv::Mat m(173, 251, CV_8UC1);
    cv::randu(m, 0, 255);
    std::uniform_real_distribution<double> u(0, 1);
    for (int y = 0; y < m.rows; ++y) {
      for (int x = 0; x < m.cols; ++x) m.at<uint8_t>(y, x) = u(rng) < density ? 200 : 100;
    }
    masks.push_back(m);
  }
  for (size_t i = 0; i < masks.size(); ++i) {
    SCOPED_TRACE("mask " + std::to_string(i));
    cv::Mat background, expected;
    cv::threshold(masks[i], background, 127, 255, cv::THRESH_BINARY_INV);
    cv::distanceTransform(background, expected, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
    const cv::Mat got = DistanceToSilhouette(masks[i]);
    ASSERT_EQ(got.type(), CV_32FC1);
    ASSERT_EQ(got.size(), masks[i].size());
    EXPECT_TRUE(got.isContinuous());
    EXPECT_EQ(cv::norm(got, expected, cv::NORM_INF), 0);  // bit for bit
  }
  // No silhouette: everything far.
  double lo = 0;
  cv::minMaxLoc(DistanceToSilhouette(cv::Mat::zeros(240, 320, CV_8UC1)), &lo);
  EXPECT_GE(lo, 1e5);
}

TEST(VoxelHullTest, RejectsBadInput) {
  VoxelGridOptions bad;
  bad.voxel_size_m = 0;
  EXPECT_THROW(bad.Check(), InputError);
  bad = {};
  bad.max_corner_m.z() = -1;
  EXPECT_THROW(bad.Check(), InputError);
  bad = {};
  bad.footprint_scale = -1;
  EXPECT_THROW(bad.Check(), InputError);
  EXPECT_THROW(VoxelCarver({}, {}), InputError);
  const std::vector<Camera> cams = HullRig(2, 0);
  VoxelGridOptions coarse;
  coarse.voxel_size_m = 0.1;
  const VoxelCarver carver(cams, coarse);
  EXPECT_THROW(carver.Carve({cv::Mat::zeros(240, 320, CV_8UC1)}), InputError);
  EXPECT_THROW(carver.Carve({cv::Mat::zeros(240, 320, CV_8UC1), cv::Mat::zeros(100, 320, CV_8UC1)}),
               InputError);
  EXPECT_THROW(carver.CarveDistances({cv::Mat::zeros(240, 320, CV_32F)}), InputError);
  EXPECT_THROW(carver.CarveDistances({cv::Mat::zeros(240, 320, CV_32F), cv::Mat::zeros(240, 320, CV_8U)}),
               InputError);
  EXPECT_THROW(carver.CarveDistances({cv::Mat::zeros(240, 320, CV_32F), cv::Mat::zeros(240, 300, CV_32F)}),
               InputError);
  const VoxelHull hull =
      carver.Carve({cv::Mat::zeros(240, 320, CV_8UC1), cv::Mat::zeros(240, 320, CV_8UC1)});
  EXPECT_EQ(hull.occupied_count, 0);
  EXPECT_FALSE(hull.ContainsPoint({5, 5, 5}));
  EXPECT_EQ(hull.nx, 30);
  EXPECT_EQ(hull.nz, 22);
}

}  // namespace
}  // namespace irbench
