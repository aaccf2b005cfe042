#include "tracker/frontend/frontend.h"

#include <array>
#include <chrono>
#include <functional>
#include <opencv2/core/utility.hpp>
#include <stdexcept>

#include "common/error.h"

namespace irbench {

void FrontEndOptions::Check() const {
  background.Check();
  shadow.Check();
  axes.Check();
  polygons.Check();
  voxels.Check();
  polyhedral.Check();
  health.Check();
  if (!(placement_max_coverage > 0 && placement_max_coverage <= 1)) {
    throw InputError("", "frontend.placement_max_coverage", "must be in (0, 1]");
  }
}

std::optional<BodyPlacement> PlaceBody(const VoxelHull& hull, double legs_height_m, double min_volume_m3) {
  if (hull.VolumeM3() < min_volume_m3) return std::nullopt;
  BodyPlacement p;
  p.volume_m3 = hull.VolumeM3();
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int count = 0;
  p.top_m = 0;
  for (const Eigen::Vector3d& c : hull.OccupiedCenters()) {
    p.top_m = std::max(p.top_m, c.z() + 0.5 * hull.voxel_size_m);
    if (c.z() < legs_height_m) sum += c.head<2>(), ++count;
  }
  if (count == 0) return std::nullopt;  // floating blob: not a person standing
  p.root = Eigen::Vector3d(sum.x() / count, sum.y() / count, 0);
  return p;
}

cv::Mat ScreenMask(const Camera& camera, const std::vector<ScreenSurface>& screens) {
  cv::Mat mask = cv::Mat::zeros(camera.height, camera.width, CV_8U);
  if (screens.empty()) return mask;
  const Eigen::Vector3d origin = camera.CenterInWorld();
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const auto dir = camera.PixelRayInWorld(Eigen::Vector2d(u, v));
      if (!dir) continue;
      for (const ScreenSurface& s : screens) {
        if (s.Intersect(origin, *dir)) {
          mask.at<uint8_t>(v, u) = 255;
          break;
        }
      }
    }
  }
  return mask;
}

FrontEnd FrontEnd::Train(const SequenceInput& input, const FrontEndOptions& options) {
  options.Check();
  if (input.background_count() == 0) {
    throw InputError((input.dir() / "background").string(), "",
                     "no empty-stage frames: the background model needs them (render with --background-frames)");
  }
  FrontEnd fe;
  fe.options_ = options;
  fe.cameras_ = input.cameras();
  for (size_t c = 0; c < input.cameras().size(); ++c) {
    const std::vector<cv::Mat> frames = input.Backgrounds(static_cast<int>(c));
    fe.camera_references_.push_back(ReferenceFromEmptyStage(frames));
    auto model = BackgroundModel::Train(frames, options.background,
                                        ScreenMask(input.cameras()[c], input.screens()));
    auto shadows = ShadowRemover::Train(frames, options.shadow);
    if (!model || !shadows) {
      throw InputError(input.BackgroundPath(static_cast<int>(c), 0).string(), "",
                       "empty-stage frames differ in size or type");
    }
    fe.background_.push_back(std::move(*model));
    fe.shadows_.push_back(std::move(*shadows));
  }
  if (options.carve_voxels) fe.carver_ = std::make_shared<VoxelCarver>(input.cameras(), options.voxels);
  return fe;
}

std::optional<BodyPlacement> PlaceBodyWithoutOneView(const VoxelCarver& carver, const std::vector<cv::Mat>& silhouettes,
                                                     double max_coverage, const std::vector<cv::Mat>* distances) {
  if (distances && distances->size() != silhouettes.size()) {
    throw InputError("", "distances",
                     "expected " + std::to_string(silhouettes.size()) + " distance transforms, got " +
                         std::to_string(distances->size()));
  }
  std::vector<cv::Mat> own;
  if (!distances) {
    own = carver.DistanceTransforms(silhouettes);
    distances = &own;
  }
  std::optional<BodyPlacement> best;
  for (size_t c = 0; c < silhouettes.size(); ++c) {
    if (cv::countNonZero(silhouettes[c]) == 0) continue;  // nothing there: an empty stage, not a lost body
    std::vector<cv::Mat> others = *distances;
    // Camera c places no constraint: its image taken as all silhouette. (A
    // new matrix: assigning Mat::zeros would write into the shared one.)
    others[c] = cv::Mat(silhouettes[c].size(), CV_32F, cv::Scalar(0));
    const VoxelHull hull = carver.CarveDistances(others);
    std::optional<BodyPlacement> p = PlaceBody(hull);
    if (!p) continue;
    // The share of the others' hull (voxel centres) camera c's silhouette covers.
    const Camera& cam = carver.cameras()[c];
    int seen = 0, inside = 0;
    for (const Eigen::Vector3d& v : hull.OccupiedCenters()) {
      const Eigen::Vector3d v_in_cam = cam.cam_from_world * v;
      if (v_in_cam.z() <= carver.options().near_m) continue;
      const Eigen::Vector2d px = cam.ProjectInCamera(v_in_cam);
      const int u = static_cast<int>(std::lround(px.x())), w = static_cast<int>(std::lround(px.y()));
      if (u < 0 || w < 0 || u >= silhouettes[c].cols || w >= silhouettes[c].rows) continue;
      ++seen;
      inside += silhouettes[c].at<uint8_t>(w, u) > 127;
    }
    if (seen == 0) continue;
    p->dropped_view = static_cast<int>(c);
    p->dropped_view_coverage = static_cast<double>(inside) / seen;
    if (p->dropped_view_coverage < max_coverage &&
        (!best || p->dropped_view_coverage < best->dropped_view_coverage)) {
      best = p;
    }
  }
  return best;
}

int FrameFeatures::UsableCameras() const {
  int n = 0;
  for (size_t c = 0; c < cameras.size(); ++c) n += !LeftOut(c);
  return n;
}

FrameFeatures FrontEnd::Process(int frame, const std::vector<cv::Mat>& frames, const std::vector<bool>& left_out) const {
  const int nc = static_cast<int>(background_.size());
  if (static_cast<int>(frames.size()) != nc || (!left_out.empty() && static_cast<int>(left_out.size()) != nc)) {
    throw std::invalid_argument("front end: expected " + std::to_string(nc) + " frames and flags, got " +
                                std::to_string(frames.size()) + " and " + std::to_string(left_out.size()));
  }
  FrameFeatures out;
  out.frame = frame;
  out.left_out = left_out;
  for (int c = 0; c < nc; ++c) {
    if (out.LeftOut(c)) continue;
    if (frames[c].type() != CV_8UC1 || frames[c].cols != cameras_[c].width || frames[c].rows != cameras_[c].height) {
      throw std::invalid_argument("front end: the frame of camera '" + cameras_[c].name +
                                  "' is not 8-bit grey of the camera's size");
    }
  }
  auto since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  };
  // Per-camera work runs in parallel over the cameras (each camera's result
  // is its own, so the output does not depend on the thread count).
  auto per_camera = [nc](const std::function<void(int)>& f) {
    cv::parallel_for_(cv::Range(0, nc), [&](const cv::Range& r) {
      for (int c = r.start; c < r.end; ++c) f(c);
    });
  };
  // The per-camera stages (silhouette, shadows, distance transform, 2D axes
  // and parts, polygons) run as one task per camera: one hand-over between
  // the threads instead of one per stage. The wall time of this part is
  // shared among its stages in proportion to the time each took on its
  // thread, so the stage times still add up to the front end's.
  auto t = std::chrono::steady_clock::now();
  out.cameras.resize(nc);
  out.polygons.resize(nc);
  const bool need_distances = options_.find_axes || carver_;
  std::vector<cv::Mat> silhouettes(nc), distances(need_distances ? nc : 0);
  std::vector<AxisView> views(options_.find_axes ? nc : 0);
  // Per camera, ms on its thread: silhouettes, axes, polygons, voxels.
  std::vector<std::array<double, 4>> thread_ms(nc, {0, 0, 0, 0});
  per_camera([&](int c) {
    if (out.LeftOut(c)) {
      LeaveOut(c, need_distances, &out, &silhouettes, &distances, &views);
      return;
    }
    auto tc = std::chrono::steady_clock::now();
    const SilhouetteResult r = background_[c].Segment(frames[c]);
    CameraFeatures& cf = out.cameras[c];
    cf.before_shadows = r.mask;
    cf.silhouette = options_.remove_shadows ? shadows_[c].Remove(frames[c], r.mask, r.darker) : r.mask;
    cf.light_level = r.light_level;
    cf.blobs_removed = r.blobs_removed;
    silhouettes[c] = cf.silhouette;
    thread_ms[c][0] = since(tc);
    // The distance transform serves the 3D axes' silhouette test and the
    // voxel carving; it counts with the first of them that runs.
    tc = std::chrono::steady_clock::now();
    if (need_distances) distances[c] = DistanceToSilhouette(silhouettes[c]);
    if (options_.find_axes) views[c] = MakeAxisView(cameras_[c], silhouettes[c], options_.axes);
    thread_ms[c][options_.find_axes ? 1 : 3] = since(tc);
    tc = std::chrono::steady_clock::now();
    out.polygons[c] = ApproximateSilhouette(silhouettes[c], options_.polygons);
    thread_ms[c][2] = since(tc);
  });
  {
    const double wall = since(t);
    std::array<double, 4> sum = {0, 0, 0, 0};
    for (const auto& ms : thread_ms) {
      for (int s = 0; s < 4; ++s) sum[s] += ms[s];
    }
    const double total = sum[0] + sum[1] + sum[2] + sum[3];
    const double share = total > 0 ? wall / total : 0;
    out.ms_silhouettes = sum[0] * share;
    out.ms_axes = sum[1] * share;
    out.ms_polygons = sum[2] * share;
    out.ms_voxels = sum[3] * share;
  }
  if (options_.find_axes) {
    t = std::chrono::steady_clock::now();
    for (int c = 0; c < nc; ++c) views[c].distance_to_silhouette = distances[c];
    out.axis3d = ReconstructAxis3d(views, options_.axes.axis3d);
    // The distance maps stay with the front end (four floats a pixel).
    for (AxisView& view : views) view.distance_to_silhouette.release();
    out.views = std::move(views);
    out.ms_axes += since(t);
  }
  // Two views at least make a hull; with fewer the stage cannot be seen.
  if (carver_ && out.UsableCameras() >= 2) {
    t = std::chrono::steady_clock::now();
    out.voxels = carver_->CarveDistances(distances);
    out.placement = PlaceBody(*out.voxels);
    if (!out.placement && options_.placement_drop_view && out.UsableCameras() >= 4 &&
        options_.voxels.max_missing_views == 0) {
      out.placement = PlaceBodyWithoutOneView(*carver_, silhouettes, options_.placement_max_coverage, &distances);
    }
    out.ms_voxels += since(t);
  }
  if (options_.polyhedral_hull && out.UsableCameras() >= 2) {
    t = std::chrono::steady_clock::now();
    if (out.UsableCameras() == nc) {
      out.hull = PolyhedralVisualHull(cameras_, out.polygons, options_.polyhedral);
    } else {
      std::vector<Camera> cameras;
      std::vector<SilhouettePolygons> polygons;
      for (int c = 0; c < nc; ++c) {
        if (!out.LeftOut(c)) cameras.push_back(cameras_[c]), polygons.push_back(out.polygons[c]);
      }
      out.hull = PolyhedralVisualHull(cameras, polygons, options_.polyhedral);
    }
    out.ms_polyhedral = since(t);
  }
  return out;
}

void FrontEnd::LeaveOut(int c, bool need_distances, FrameFeatures* out, std::vector<cv::Mat>* silhouettes,
                        std::vector<cv::Mat>* distances, std::vector<AxisView>* views) const {
  const Camera& cam = cameras_[c];
  CameraFeatures& cf = out->cameras[c];
  cf.silhouette = cv::Mat::zeros(cam.height, cam.width, CV_8U);
  cf.before_shadows = cf.silhouette.clone();
  (*silhouettes)[c] = cf.silhouette;
  out->polygons[c].width = cam.width;
  out->polygons[c].height = cam.height;
  // Constrains nothing: distance 0 (inside) everywhere, so the hull and the
  // other views' 3D axis points pass it; no axis points of its own.
  if (need_distances) (*distances)[c] = cv::Mat(cam.height, cam.width, CV_32F, cv::Scalar(0));
  if (!views->empty()) {
    AxisView& view = (*views)[c];
    view.camera = cam;
    view.silhouette = cv::Mat(cam.height, cam.width, CV_8U, cv::Scalar(255));
  }
}

}  // namespace irbench
