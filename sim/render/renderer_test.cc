#include "sim/render/renderer.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/camera/rig.h"

namespace irbench {
namespace {

Camera TheaterCamera(int index) {
  return LoadRig(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json").cameras.at(index);
}

class RendererTest : public ::testing::TestWithParam<GlBackend> {};

// The mask of a sphere matches its analytic projection through the distorted
// camera (a pixel is inside when its ray meets the sphere).
TEST_P(RendererTest, SphereMaskMatchesAnalyticProjection) {
  auto context = CreateGlContext(GetParam());
  for (int cam_index : {0, 2}) {  // a mild and a wide, strongly distorted lens
    const Camera cam = TheaterCamera(cam_index);
    Renderer renderer(*context, {cam}, RenderOptions{});
    // Off-centre, so the distortion matters.
    const Eigen::Vector3d center_in_cam(0.9, -0.5, 2.6);
    const Eigen::Vector3d center = cam.cam_from_world.inverse() * center_in_cam;
    const double radius = 0.35;
    TriangleMesh sphere;
    AppendSphere(sphere, center, radius, Material{0.6f, 0.0f}, 128, 64);
    renderer.SetPersonTopology(sphere.indices, sphere.vertices.size());
    renderer.UpdatePerson(sphere.vertices);
    CameraImages images;
    renderer.Render(0, &images, true);

    const Eigen::Vector3d eye = cam.CenterInWorld();
    int inter = 0, uni = 0, analytic_area = 0;
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        const Eigen::Vector3d dir = *cam.PixelRayInWorld({double(u), double(v)});
        const double along = (center - eye).dot(dir);
        const bool inside = along > 0 && ((center - eye) - along * dir).norm() < radius;
        const bool rendered = images.mask.at<uint8_t>(v, u) == 255;
        inter += inside && rendered;
        uni += inside || rendered;
        analytic_area += inside;
      }
    }
    ASSERT_GT(analytic_area, 1000) << "sphere too small to test";
    const double iou = double(inter) / uni;
    EXPECT_GE(iou, 0.98) << cam.name;
    RecordProperty("sphere_iou_" + cam.name, std::to_string(iou));
    // Depth at the sphere's projected centre is its front surface.
    const Eigen::Vector2d px = cam.Project(center);
    const float depth = images.depth.at<float>(int(std::lround(px.y())), int(std::lround(px.x())));
    // Camera depth is z in the camera frame, along the ray through the centre.
    const double along_ray = (center - eye).norm() - radius;
    EXPECT_NEAR(depth, along_ray * center_in_cam.z() / center_in_cam.norm(), 0.01);
  }
}

// A checkerboard rendered at 24 poses is found by OpenCV, and calibrateCamera
// recovers the rig's intrinsics: the pixels and the written calibration agree.
TEST_P(RendererTest, CheckerboardCalibrationRecoversTheRig) {
  auto context = CreateGlContext(GetParam());
  const Camera cam = TheaterCamera(0);
  RenderOptions options;
  options.supersample = 2;
  Renderer renderer(*context, {cam}, options);
  const int cols = 7, rows = 5;
  const double square = 0.065;
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  std::vector<cv::Point3f> board;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) board.emplace_back(float(c * square), float(r * square), 0.f);
  const Eigen::Isometry3d world_from_cam = cam.cam_from_world.inverse();
  int found = 0, n_corners = 0;
  double sum_dx = 0, sum_dy = 0, sum_sq = 0;
  for (int i = 0; i < 48; ++i) {
    // A 3 x 2 grid of positions over the image at two depths, each seen
    // tilted about a different axis (up to ~37 degrees), as a careful
    // calibration session would.
    const double x = -0.2 + 0.2 * (i % 3), y = (i / 3) % 2 == 0 ? -0.12 : 0.12;
    const double z = 0.95 + 0.175 * ((i / 6) % 3);
    const double tilt = (i < 36 ? 0.65 : 0.35) * (((i / 18) % 2) == 0 ? 1 : -1);
    const double tilt_x = (i % 2 == 0) ? tilt : 0.25 * tilt, tilt_y = (i % 2 == 0) ? 0.25 * tilt : tilt;
    Eigen::Isometry3d cam_from_board = Eigen::Isometry3d::Identity();
    cam_from_board.linear() = (Eigen::AngleAxisd(tilt_x, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(tilt_y, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(0.15 * std::sin(i), Eigen::Vector3d::UnitZ()))
                                  .toRotationMatrix();
    const Eigen::Vector3d board_center((cols - 1) * square / 2, (rows - 1) * square / 2, 0);
    cam_from_board.translation() = Eigen::Vector3d(x, y, z) - cam_from_board.linear() * board_center;
    TriangleMesh mesh;
    AppendCheckerboard(mesh, world_from_cam * cam_from_board, cols, rows, square);
    renderer.SetStaticMesh(mesh);
    CameraImages images;
    renderer.Render(0, &images, false);
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(images.grey, {cols, rows}, corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      continue;
    }
    cv::cornerSubPix(images.grey, corners, {6, 6}, {-1, -1},
                     {cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 100, 1e-4});
    // Detected corners against the exact projection of the board's corners.
    for (size_t c = 0; c < corners.size(); ++c) {
      const Eigen::Vector3d corner_in_world =
          world_from_cam * cam_from_board *
          Eigen::Vector3d(board[c].x, board[c].y, board[c].z);
      const Eigen::Vector2d expected = cam.Project(corner_in_world);
      sum_dx += corners[c].x - expected.x();
      sum_dy += corners[c].y - expected.y();
      sum_sq += std::pow(corners[c].x - expected.x(), 2) + std::pow(corners[c].y - expected.y(), 2);
      ++n_corners;
    }
    object_points.push_back(board);
    image_points.push_back(corners);
    ++found;
  }
  ASSERT_GE(found, 15);
  std::printf("detected corners - exact projections: mean (%.3f, %.3f) px, rms %.3f px over %d\n",
              sum_dx / n_corners, sum_dy / n_corners, std::sqrt(sum_sq / n_corners), n_corners);
  // No bias: the rendered pixels agree with the camera model.
  EXPECT_LT(std::hypot(sum_dx, sum_dy) / n_corners, 0.03);
  cv::Mat k, dist;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms = cv::calibrateCamera(object_points, image_points, {cam.width, cam.height}, k, dist,
                                         rvecs, tvecs, cv::CALIB_FIX_K3);
  EXPECT_LT(rms, 0.25);
  EXPECT_NEAR(k.at<double>(0, 0), cam.fx, 0.005 * cam.fx);
  EXPECT_NEAR(k.at<double>(1, 1), cam.fy, 0.005 * cam.fy);
  EXPECT_NEAR(k.at<double>(0, 2), cam.cx, 0.005 * cam.cx);
  EXPECT_NEAR(k.at<double>(1, 2), cam.cy, 0.005 * cam.cy);
  EXPECT_NEAR(dist.at<double>(0), cam.dist[0], 0.02);
  RecordProperty("rms_px", std::to_string(rms));
  std::printf("calibration: %d views, rms %.3f px, fx %.2f (%.2f) fy %.2f (%.2f) cx %.2f (%.2f) "
              "cy %.2f (%.2f) k1 %.4f (%.4f)\n",
              found, rms, k.at<double>(0, 0), cam.fx, k.at<double>(1, 1), cam.fy, k.at<double>(0, 2),
              cam.cx, k.at<double>(1, 2), cam.cy, dist.at<double>(0), cam.dist[0]);
}

INSTANTIATE_TEST_SUITE_P(Backends, RendererTest,
                         ::testing::Values(GlBackend::kEgl, GlBackend::kOsMesa),
                         [](const auto& info) { return GlBackendName(info.param); });

}  // namespace
}  // namespace irbench

namespace irbench {
namespace {

// Penumbra of a plate's straight edge on the floor under a square light of
// side S straight above: geometry predicts a linear ramp of width
// S * (z_r - z_b) / z_b along the floor (z_b, z_r: the plate's and the
// floor's distances from the light). Measured between 10% and 90% of the
// lit level, divided by 0.8; the lit level comes from the same render without
// the plate.
double MeasurePenumbra(GlContext& context, double light_size, double* predicted) {
  Camera cam;
  cam.width = 640;
  cam.height = 480;
  cam.fx = cam.fy = 600;
  cam.cx = 319.5;
  cam.cy = 239.5;
  cam.cam_from_world = *LookAt({1.2, 0.0, 2.6}, {0.0, 0.0, 0.0}, Eigen::Vector3d::UnitZ());
  RenderOptions options;
  options.shadows = true;
  options.shadow_map_size = 2048;
  Renderer renderer(context, {cam}, options);
  IrLight light;
  light.position = {0, 0, 3.0};
  light.direction = {0, 0, -1};
  light.cone_deg = 100;
  light.power = 8.0;
  light.size_m = light_size;
  renderer.SetLighting({light}, 0.0);
  const double plate_top = 1.02;
  auto render = [&](bool with_plate) {
    TriangleMesh mesh;
    AppendQuad(mesh, {-3, -3, 0}, {6, 0, 0}, {0, 6, 0}, Material{0.8f, 0.0f});
    if (with_plate) AppendBox(mesh, {-2.5, -2.5, 1.0}, {0.0, 2.5, plate_top}, Material{0.5f, 0.0f}, false);
    renderer.SetStaticMesh(mesh);
    CameraImages images;
    renderer.Render(0, &images, false);
    return images.grey;
  };
  const cv::Mat shadowed = render(true), lit = render(false);
  // Visibility along the floor line y = 0, x in [-0.6, 0.6].
  std::vector<std::pair<double, double>> profile;
  for (double x = -0.6; x <= 0.6; x += 0.002) {
    const Eigen::Vector2d px = cam.Project({x, 0, 0});
    cv::Mat patch_s, patch_l;
    cv::getRectSubPix(shadowed, {1, 1}, cv::Point2f(px.x(), px.y()), patch_s, CV_32F);
    cv::getRectSubPix(lit, {1, 1}, cv::Point2f(px.x(), px.y()), patch_l, CV_32F);
    profile.emplace_back(x, patch_s.at<float>(0, 0) / std::max(1.0f, patch_l.at<float>(0, 0)));
  }
  auto crossing = [&](double level) {
    for (size_t i = 1; i < profile.size(); ++i) {
      if (profile[i - 1].second < level && profile[i].second >= level) {
        const double u = (level - profile[i - 1].second) / (profile[i].second - profile[i - 1].second);
        return profile[i - 1].first + u * (profile[i].first - profile[i - 1].first);
      }
    }
    return std::nan("");
  };
  const double z_b = 3.0 - plate_top, z_r = 3.0;
  *predicted = light_size * (z_r - z_b) / z_b;
  EXPECT_LT(profile.front().second, 0.05) << "the plate's shadow is dark";
  EXPECT_GT(profile.back().second, 0.95) << "beyond the penumbra the floor is lit";
  return (crossing(0.9) - crossing(0.1)) / 0.8;
}

// The static scene drawn once and copied under the person (the default) gives
// the pixels of drawing everything every frame, bit for bit, while the
// person's soft shadows move over the stage: a sphere walks across the
// theater's stage lit by its three shadowing lights, seen by the four cameras.
// Shadow maps and images return to the empty stage's when it leaves.
TEST(StaticCacheTest, SamePixelsAsDrawingEverythingEveryFrame) {
  auto context = CreateGlContext(GlBackend::kAuto);
  const Rig rig = LoadRig(std::string(IRBENCH_SOURCE_DIR) + "/rigs/theater4.json");
  const Scene scene = LoadScene(std::string(IRBENCH_SOURCE_DIR) + "/scenes/theater.json");
  RenderOptions cached_options;
  cached_options.shadows = true;
  cached_options.static_cache_min_pixels = 0;  // the cache at any size
  RenderOptions full_options = cached_options;
  full_options.static_cache = false;
  Renderer cached(*context, rig.cameras, cached_options), full(*context, rig.cameras, full_options);
  TriangleMesh body;
  AppendSphere(body, Eigen::Vector3d::Zero(), 0.3, Material{0.6f, 0.0f}, 48, 24);
  AppendBox(body, {-0.15, -0.1, -1.2}, {0.15, 0.1, -0.3}, Material{0.5f, 0.0f}, false);
  std::vector<CameraImages> empty;
  for (Renderer* r : {&cached, &full}) {
    r->SetScene(scene);
    r->SetPersonTopology(body.indices, body.vertices.size());
  }
  full.SetPersonVisible(false);
  full.RenderAll(&empty, true);
  full.SetPersonVisible(true);
  int shadowed_pixels = 0;
  for (const Eigen::Vector3d& at : {Eigen::Vector3d(-0.8, 0.4, 1.5), Eigen::Vector3d(0.0, 0.0, 1.5),
                                    Eigen::Vector3d(0.9, -0.5, 1.4)}) {
    TriangleMesh moved = body;
    for (MeshVertex& v : moved.vertices) v.position += at.cast<float>();
    std::vector<CameraImages> a, b;
    for (Renderer* r : {&cached, &full}) r->UpdatePerson(moved.vertices);
    cached.RenderAll(&a, true);
    full.RenderAll(&b, true);
    for (size_t c = 0; c < a.size(); ++c) {
      EXPECT_EQ(cv::norm(a[c].radiance, b[c].radiance, cv::NORM_INF), 0.0) << rig.cameras[c].name;
      EXPECT_EQ(cv::norm(a[c].mask, b[c].mask, cv::NORM_INF), 0.0) << rig.cameras[c].name;
      EXPECT_EQ(cv::norm(a[c].depth, b[c].depth, cv::NORM_INF), 0.0) << rig.cameras[c].name;
      // Darker than the empty stage off the person: its shadow.
      cv::Mat darker;
      cv::compare(b[c].grey + 3, empty[c].grey, darker, cv::CMP_LT);
      darker.setTo(0, b[c].mask);
      shadowed_pixels += cv::countNonZero(darker);
    }
  }
  EXPECT_GT(shadowed_pixels, 2000) << "the person's shadows on the stage";
  // Gone again, nothing of it stays in the shadow maps (each frame restores
  // only the texels it was drawn on) or the images.
  cached.SetPersonVisible(false);
  std::vector<CameraImages> after;
  cached.RenderAll(&after, true);
  for (size_t c = 0; c < after.size(); ++c) {
    EXPECT_EQ(cv::norm(after[c].radiance, empty[c].radiance, cv::NORM_INF), 0.0) << rig.cameras[c].name;
  }
}

TEST(ShadowTest, PenumbraWidthFollowsTheLightSize) {
  auto context = CreateGlContext(GlBackend::kAuto);
  double predicted = 0;
  for (double size : {0.3, 0.6}) {
    const double measured = MeasurePenumbra(*context, size, &predicted);
    EXPECT_NEAR(measured, predicted, 0.2 * predicted) << "light size " << size;
    std::printf("area light %.2f m: penumbra %.3f m, predicted %.3f m\n", size, measured, predicted);
  }
  // A point source: a hard edge, as sharp as the shadow map and pixels allow.
  const double point = MeasurePenumbra(*context, 0.0, &predicted);
  EXPECT_LT(point, 0.02);
  std::printf("point light: penumbra %.4f m (predicted 0)\n", point);
}

}  // namespace
}  // namespace irbench

namespace irbench {
namespace {

// A camera 3 m above the origin looking straight down, no distortion.
Camera DownCamera() {
  Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.fx = cam.fy = 300;
  cam.cx = 159.5;
  cam.cy = 119.5;
  cam.cam_from_world = *LookAt({0.0, 0.0, 3.0}, {0.0, 0.0, 0.0}, Eigen::Vector3d::UnitY());
  return cam;
}

cv::Vec4f RadianceAt(const CameraImages& images, const Camera& cam, const Eigen::Vector3d& p) {
  const Eigen::Vector2d px = cam.Project(p);
  const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
  EXPECT_TRUE(u >= 0 && v >= 0 && u < images.radiance.cols && v < images.radiance.rows) << p.transpose();
  if (u < 0 || v < 0 || u >= images.radiance.cols || v >= images.radiance.rows) return cv::Vec4f(-1, -1, -1, -1);
  return images.radiance.at<cv::Vec4f>(v, u);
}

// Each light lights in its own band, and a surface answers with its
// reflectance at that wavelength: a floor of 0.6 at 850 nm and 0.3 at 940 nm
// under the same light at either wavelength.
TEST(IlluminationTest, ReflectanceFollowsTheLightsWavelength) {
  auto context = CreateGlContext(GlBackend::kAuto);
  const Camera cam = DownCamera();
  Renderer renderer(*context, {cam}, RenderOptions{});
  TriangleMesh floor;
  Material m;
  m.albedo = 0.6f;
  m.albedo_940 = 0.3f;
  AppendQuad(floor, {-3, -3, 0}, {6, 0, 0}, {0, 6, 0}, m);
  renderer.SetStaticMesh(floor);
  IrLight light;
  light.position = {0.5, 0.0, 2.0};
  light.direction = {0, 0, -1};
  light.cone_deg = 170;
  light.power = 2.0;
  const Eigen::Vector3d p(0.2, 0.3, 0.0);
  const Eigen::Vector3d to_light = light.position - p;
  const double e = light.power * to_light.normalized().z() / to_light.squaredNorm();
  CameraImages at_850, at_940;
  renderer.SetLighting({light}, 0.0);
  renderer.Render(0, &at_850, false);
  light.wavelength_nm = 940;
  renderer.SetLighting({light}, 0.0);
  renderer.Render(0, &at_940, false);
  const cv::Vec4f r850 = RadianceAt(at_850, cam, p), r940 = RadianceAt(at_940, cam, p);
  EXPECT_NEAR(r850[0], 0.6 * e, 0.01 * 0.6 * e);
  EXPECT_NEAR(r940[1], 0.3 * e, 0.01 * 0.3 * e);
  EXPECT_EQ(r850[1], 0.0f);
  EXPECT_EQ(r940[0], 0.0f);
  EXPECT_EQ(r850[2] + r940[2] + r850[3] + r940[3], 0.0f);
  std::printf("floor under 850 nm: %.4f (0.6 E = %.4f); under 940 nm: %.4f (0.3 E = %.4f)\n", r850[0], 0.6 * e,
              r940[1], 0.3 * e);
}

// The renderer shades from the bounce light's irradiance volume as the CPU
// reads it: a floor beside a wall whose projected content glows, no lights.
TEST(IlluminationTest, BounceLightMatchesTheIrradianceVolume) {
  auto context = CreateGlContext(GlBackend::kAuto);
  const Camera cam = DownCamera();
  // The floor is bisected into right triangles with vertices every 0.1875 m
  // (6 m / 32): the test points below are vertices, where the per-vertex
  // bounce is exact.
  RenderOptions options_for_test;
  options_for_test.static_edge_m = 0.25;
  Renderer renderer(*context, {cam}, options_for_test);
  TriangleMesh mesh;
  AppendQuad(mesh, {-3, -3, 0}, {6, 0, 0}, {0, 6, 0}, Material{0.5f, 0.0f});
  Material screen;
  screen.albedo = 0.0f;
  screen.content = 1.0f;
  // A 4 m x 2 m screen at y = 1.5 facing -y (u x v = -y).
  AppendQuad(mesh, {-2, 1.5, 0}, {4, 0, 0}, {0, 0, 2}, screen);
  // Two small tilts, facing +x and -x (and up): they read the +x and -x
  // samplers besides +z.
  const Eigen::Vector3d tilt_pos(0.6, 0, 0.8), tilt_neg(-0.6, 0, 0.8);
  const Eigen::Vector3d tilt_pos_centre(1.2, 0.375, 0.05), tilt_neg_centre(0.95, 0.375, 0.05);
  for (const auto& [n, c] : {std::pair{tilt_pos, tilt_pos_centre}, std::pair{tilt_neg, tilt_neg_centre}}) {
    const Eigen::Vector3d u = Eigen::Vector3d(0, 1, 0).cross(n).normalized() * 0.1, v(0, 0.1, 0);
    AppendQuad(mesh, c - 0.5 * u - 0.5 * v, u, v, Material{0.5f, 0.0f});
  }
  renderer.SetStaticMesh(mesh);
  renderer.SetLighting({}, 0.0);
  BounceOptions options;
  options.patch_m = 0.1;
  options.grid_m = 0.25;
  options.bounces = 1;
  const IrradianceVolume volume = ComputeBounce(mesh, {}, options);
  renderer.SetBounce(volume);
  CameraImages images;
  renderer.Render(0, &images, false);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0.75, 0), Eigen::Vector3d(0.375, 0.1875, 0),
                                  Eigen::Vector3d(-0.75, -0.375, 0)}) {
    const double expected = 0.5 * volume.Irradiance(p, Eigen::Vector3d::UnitZ())[kScreenContent];
    const cv::Vec4f r = RadianceAt(images, cam, p);
    EXPECT_GT(expected, 0.01);
    EXPECT_NEAR(r[2], expected, 0.01 * expected) << p.transpose();
    EXPECT_EQ(r[0] + r[1] + r[3], 0.0f);
    std::printf("floor at (%.1f, %.1f): content radiance %.4f, volume %.4f\n", p.x(), p.y(), r[2], expected);
  }
  // The tilted faces, at their centres (0.1 m faces, linear in between).
  double tilted[2];
  int k = 0;
  for (const auto& [n, c] : {std::pair{tilt_pos, tilt_pos_centre}, std::pair{tilt_neg, tilt_neg_centre}}) {
    const double expected = 0.5 * volume.Irradiance(c, n)[kScreenContent];
    const cv::Vec4f r = RadianceAt(images, cam, c);
    EXPECT_NEAR(r[2], expected, 0.02 * expected) << n.transpose();
    tilted[k++] = r[2];
    std::printf("face tilted to (%.1f, %.1f, %.1f): content radiance %.4f, volume %.4f\n", n.x(), n.y(), n.z(), r[2],
                expected);
  }
  // Beside the wall's right end, facing +x sees little of it, facing -x most.
  EXPECT_GT(tilted[1], 1.2 * tilted[0]);
  // Off: nothing.
  renderer.SetBounce(IrradianceVolume{});
  renderer.Render(0, &images, false);
  EXPECT_EQ(RadianceAt(images, cam, {0, 1.0, 0})[2], 0.0f);
}

}  // namespace
}  // namespace irbench
