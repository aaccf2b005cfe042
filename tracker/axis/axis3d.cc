#include "tracker/axis/axis3d.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <unordered_map>

#include "common/error.h"

namespace irbench {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr std::array<BodyPart, 4> kImageParts = {BodyPart::kHead, BodyPart::kTorso, BodyPart::kLeftImageArm,
                                                 BodyPart::kRightImageArm};

bool IsArm(BodyPart part) { return part == BodyPart::kLeftImageArm || part == BodyPart::kRightImageArm; }

// Per view: undistorted normalised coordinates of the labelled points, their
// polyline edges per image part, and the distance to the silhouette.
struct PreparedView {
  Eigen::Matrix3d cam_from_world_rotation;
  Eigen::Vector3d cam_from_world_translation;
  Eigen::Vector3d center_in_world;
  std::vector<Eigen::Vector2d> normalized;  // per graph point; NaN when not labelled or not undistortable
  std::array<std::vector<int>, 4> members;  // per kImageParts entry
  std::array<std::vector<std::pair<int, int>>, 4> edges;
  cv::Mat1f distance_to_silhouette;  // pixels
};

PreparedView Prepare(const AxisView& view, const Axis3dOptions& options) {
  PreparedView out;
  out.cam_from_world_rotation = view.camera.cam_from_world.linear();
  out.cam_from_world_translation = view.camera.cam_from_world.translation();
  out.center_in_world = view.camera.CenterInWorld();
  if (view.distance_to_silhouette.empty()) {
    cv::distanceTransform(view.silhouette == 0, out.distance_to_silhouette, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  } else {
    out.distance_to_silhouette = view.distance_to_silhouette;
  }
  out.normalized.assign(view.graph.points.size(), Eigen::Vector2d::Constant(std::nan("")));
  for (size_t i = 0; i < view.labels.size(); ++i) {
    const auto slot = std::find(kImageParts.begin(), kImageParts.end(), view.labels[i]);
    if (slot == kImageParts.end()) continue;
    const Eigen::Vector2d& px = view.graph.points[i].px;
    const auto x = view.camera.UndistortPixel(px);
    if (!x) continue;
    out.normalized[i] = *x;
    out.members[slot - kImageParts.begin()].push_back(int(i));
  }
  // Trim the ends: runs across a limb's cap shrink to nothing, and the cap's
  // outline in one view is not the same 3D curve as in another.
  for (std::vector<int>& m : out.members) {
    if (m.empty()) continue;
    std::vector<double> diameters;
    for (int i : m) diameters.push_back(view.graph.points[i].diameter_px);
    std::nth_element(diameters.begin(), diameters.begin() + diameters.size() / 2, diameters.end());
    const double min_diameter = options.min_diameter_fraction * diameters[diameters.size() / 2];
    std::erase_if(m, [&](int i) { return view.graph.points[i].diameter_px < min_diameter; });
  }
  for (size_t p = 0; p < kImageParts.size(); ++p) {
    const std::vector<int>& m = out.members[p];
    for (size_t a = 0; a < m.size(); ++a) {
      for (size_t b = a + 1; b < m.size(); ++b) {
        if ((view.graph.points[m[a]].px - view.graph.points[m[b]].px).norm() <= options.link_px) {
          out.edges[p].emplace_back(m[a], m[b]);
        }
      }
    }
  }
  return out;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Midpoint of the shortest segment between two rays; nullopt when the rays are
// within min_angle_rad of parallel or antiparallel (opposite cameras are as
// ill-conditioned as neighbours), or the point lies behind either camera.
std::optional<Eigen::Vector3d> TriangulateMidpoint(const Eigen::Vector3d& center_a,
                                                   const Eigen::Vector3d& ray_a,
                                                   const Eigen::Vector3d& center_b,
                                                   const Eigen::Vector3d& ray_b,
                                                   double min_angle_rad) {
  const double cosine = ray_a.dot(ray_b);
  if (std::acos(std::min(1.0, std::abs(cosine))) < min_angle_rad) return std::nullopt;
  const Eigen::Vector3d w0 = center_a - center_b;
  const double d = ray_a.dot(w0), e = ray_b.dot(w0);
  const double denom = 1 - cosine * cosine;
  const double s = (cosine * e - d) / denom;
  const double t = (e - cosine * d) / denom;
  if (s <= 0 || t <= 0) return std::nullopt;
  return 0.5 * (center_a + s * ray_a + center_b + t * ray_b);
}

// Throws std::invalid_argument when a view's silhouette, labels or distance
// map do not fit its camera and graph.
void CheckViews(const std::vector<AxisView>& views) {
  for (const AxisView& view : views) {
    if (view.silhouette.type() != CV_8UC1 || view.silhouette.cols != view.camera.width ||
        view.silhouette.rows != view.camera.height) {
      throw std::invalid_argument("ReconstructAxis3d: silhouette of camera '" + view.camera.name +
                                  "' is not CV_8UC1 of the camera's size");
    }
    if (!view.labels.empty() && view.labels.size() != view.graph.points.size()) {
      throw std::invalid_argument("ReconstructAxis3d: labels of camera '" + view.camera.name +
                                  "' do not match its axis graph");
    }
    if (!view.distance_to_silhouette.empty() && (view.distance_to_silhouette.type() != CV_32FC1 ||
                                                 view.distance_to_silhouette.size() != view.silhouette.size())) {
      throw std::invalid_argument("ReconstructAxis3d: distance_to_silhouette of camera '" + view.camera.name +
                                  "' is not CV_32FC1 of the camera's size");
    }
  }
}

// Whether X projects onto (or near) every silhouette that sees it; counts them
// (-1: some silhouette is missed).
int Support(const std::vector<AxisView>& views,
            const std::vector<PreparedView>& prepared,
            const Axis3dOptions& options,
            const Eigen::Vector3d& x) {
  int count = 0;
  for (size_t k = 0; k < views.size(); ++k) {
    const Camera& camera = views[k].camera;
    if ((camera.cam_from_world * x).z() <= 0) continue;
    const Eigen::Vector2d px = camera.Project(x);
    const int u = int(std::lround(px.x())), v = int(std::lround(px.y()));
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
    if (prepared[k].distance_to_silhouette(v, u) > options.silhouette_tolerance_px) return -1;
    ++count;
  }
  return count;
}

// The 3D axis points of views i and j: each labelled point of i meets the
// matching part's polyline in j along its epipolar line, and the two rays
// triangulate; in the order of the parts, i's points and j's edges.
// min_epipolar_sin: sin(options.min_epipolar_angle_deg).
std::vector<AxisPoint3d> TriangulatePair(const std::vector<AxisView>& views,
                                         const std::vector<PreparedView>& prepared,
                                         size_t i,
                                         size_t j,
                                         double min_epipolar_sin,
                                         const Axis3dOptions& options) {
  std::vector<AxisPoint3d> found;
  const PreparedView& vi = prepared[i];
  const PreparedView& vj = prepared[j];
  // Essential matrix mapping normalised points of i to epipolar lines of j.
  const Eigen::Matrix3d j_from_i = vj.cam_from_world_rotation * vi.cam_from_world_rotation.transpose();
  const Eigen::Vector3d t_j_from_i = vj.cam_from_world_translation - j_from_i * vi.cam_from_world_translation;
  const Eigen::Matrix3d essential = Skew(t_j_from_i) * j_from_i;
  const Eigen::Vector3d epipole_in_i = vi.cam_from_world_rotation * vj.center_in_world + vi.cam_from_world_translation;
  for (size_t pa = 0; pa < kImageParts.size(); ++pa) {
    for (size_t pb = 0; pb < kImageParts.size(); ++pb) {
      const bool arms = IsArm(kImageParts[pa]) && IsArm(kImageParts[pb]);
      if (pa != pb && !arms) continue;
      const BodyPart part3d = arms ? BodyPart::kArm : kImageParts[pa];
      for (int a : vi.members[pa]) {
        const Eigen::Vector2d& xa = vi.normalized[a];
        const Eigen::Vector3d line = essential * xa.homogeneous();
        const double line_norm = line.head<2>().norm();
        if (line_norm < 1e-12) continue;
        const Eigen::Vector2d line_dir = Eigen::Vector2d(-line.y(), line.x()) / line_norm;
        // The coplanar case seen from view i: the epipolar line through a
        // (towards the epipole, camera j's centre) runs along a's own axis.
        const Eigen::Vector3d line_in_i = xa.homogeneous().cross(epipole_in_i);
        const Eigen::Vector2d& axis_a = views[i].graph.points[a].axis_dir;
        if (line_in_i.head<2>().norm() > 1e-12 && axis_a.norm() > 0.5 &&
            std::abs(axis_a.dot(line_in_i.head<2>().normalized())) < min_epipolar_sin) {
          continue;
        }
        for (const auto& [b1, b2] : vj.edges[pb]) {
          const double s1 = line.dot(vj.normalized[b1].homogeneous());
          const double s2 = line.dot(vj.normalized[b2].homogeneous());
          if (s1 * s2 > 0 || s1 == s2) continue;
          const AxisPoint2d& q1 = views[j].graph.points[b1];
          const AxisPoint2d& q2 = views[j].graph.points[b2];
          Eigen::Vector2d axis = q1.axis_dir + (q1.axis_dir.dot(q2.axis_dir) < 0 ? -1.0 : 1.0) * q2.axis_dir;
          if (axis.norm() < 1e-9) axis = q2.px - q1.px;
          axis.normalize();
          // |sin| of the angle between the epipolar line and the 2D axis.
          if (std::abs(axis.x() * line_dir.y() - axis.y() * line_dir.x()) < min_epipolar_sin) continue;
          const double lambda = s1 / (s1 - s2);
          const Eigen::Vector2d xb = vj.normalized[b1] + lambda * (vj.normalized[b2] - vj.normalized[b1]);
          const Eigen::Vector3d ray_a = (vi.cam_from_world_rotation.transpose() * xa.homogeneous()).normalized();
          const Eigen::Vector3d ray_b = (vj.cam_from_world_rotation.transpose() * xb.homogeneous()).normalized();
          const auto x = TriangulateMidpoint(vi.center_in_world, ray_a, vj.center_in_world, ray_b,
                                             options.min_ray_angle_deg * kDegToRad);
          if (!x) continue;
          const int count = Support(views, prepared, options, *x);
          if (count < 2) continue;
          const double depth_a = (views[i].camera.cam_from_world * *x).z();
          const double depth_b = (views[j].camera.cam_from_world * *x).z();
          const double diameter_b_px = q1.diameter_px + lambda * (q2.diameter_px - q1.diameter_px);
          AxisPoint3d point;
          point.p_in_world = *x;
          point.part = part3d;
          point.diameter_m = 0.5 * (views[i].graph.points[a].diameter_px * depth_a / views[i].camera.fx +
                                    diameter_b_px * depth_b / views[j].camera.fx);
          point.camera_a = int(i);
          point.camera_b = int(j);
          point.support = count;
          found.push_back(point);
        }
      }
    }
  }
  return found;
}

// Greedy merge of one part's points within merge_radius_m (> 0) of a seed, in
// index order: each merged point averages its group.
std::vector<AxisPoint3d> MergeNearby(const std::vector<AxisPoint3d>& raw,
                                     const Axis3dOptions& options) {
  // The points are binned in cubes of that edge: those within the radius of a
  // seed lie in the 27 cubes about its own, and taken in index order they give
  // the plain scan's sums.
  std::vector<AxisPoint3d> merged;
  std::vector<bool> used(raw.size(), false);
  const double radius2 = options.merge_radius_m * options.merge_radius_m;
  // Cubes a little larger than the radius (the divisions round on their own)
  // and at least a millimetre; indices clamped so the keys cannot overflow
  // (points clamped together share a cube, which only adds candidates).
  const double cube = std::max(options.merge_radius_m, 1e-3) * (1 + 1e-6);
  auto cell_of = [&](const Eigen::Vector3d& p) {
    auto index = [&](double u) { return int(std::clamp(std::floor(u / cube), -1048575.0, 1048575.0)); };
    return Eigen::Vector3i(index(p.x()), index(p.y()), index(p.z()));
  };
  auto key_of = [](const Eigen::Vector3i& c) {
    return (int64_t(c.x()) * 2097152 + c.y()) * 2097152 + c.z();
  };
  std::unordered_map<int64_t, std::vector<size_t>> cells;
  for (size_t k = 0; k < raw.size(); ++k) cells[key_of(cell_of(raw[k].p_in_world))].push_back(k);
  std::vector<size_t> near;
  for (size_t s = 0; s < raw.size(); ++s) {
    if (used[s]) continue;
    AxisPoint3d sum = raw[s];
    sum.merged = 1;
    used[s] = true;
    near.clear();
    const Eigen::Vector3i c = cell_of(raw[s].p_in_world);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = cells.find(key_of(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells.end()) continue;
          for (size_t k : it->second) {
            if (k > s) near.push_back(k);
          }
        }
      }
    }
    std::sort(near.begin(), near.end());
    for (size_t k : near) {
      if (used[k] || raw[k].part != raw[s].part) continue;
      if ((raw[k].p_in_world - raw[s].p_in_world).squaredNorm() > radius2) continue;
      used[k] = true;
      sum.p_in_world += raw[k].p_in_world;
      sum.diameter_m += raw[k].diameter_m;
      sum.support = std::max(sum.support, raw[k].support);
      ++sum.merged;
    }
    sum.p_in_world /= double(sum.merged);
    sum.diameter_m /= double(sum.merged);
    merged.push_back(sum);
  }
  return merged;
}

}  // namespace

void Axis3dOptions::Check() const {
  if (!(min_epipolar_angle_deg >= 0 && min_epipolar_angle_deg < 90)) {
    throw InputError("", "Axis3dOptions.min_epipolar_angle_deg", "must be in [0, 90)");
  }
  if (!(min_ray_angle_deg >= 0 && min_ray_angle_deg < 90)) {
    throw InputError("", "Axis3dOptions.min_ray_angle_deg", "must be in [0, 90)");
  }
  if (!(link_px > 0)) throw InputError("", "Axis3dOptions.link_px", "must be > 0");
  if (!(silhouette_tolerance_px >= 0)) throw InputError("", "Axis3dOptions.silhouette_tolerance_px", "must be >= 0");
  if (!(min_diameter_fraction >= 0 && min_diameter_fraction < 1)) {
    throw InputError("", "Axis3dOptions.min_diameter_fraction", "must be in [0, 1)");
  }
  if (!(merge_radius_m >= 0)) throw InputError("", "Axis3dOptions.merge_radius_m", "must be >= 0");
}

void BodyAxesOptions::Check() const {
  points.Check();
  parts.Check();
  axis3d.Check();
  if (!(max_view_elevation_deg >= 0 && max_view_elevation_deg <= 90)) {
    throw InputError("", "BodyAxesOptions.max_view_elevation_deg", "must be in [0, 90]");
  }
}

std::vector<AxisPoint3d> ReconstructAxis3d(const std::vector<AxisView>& views, const Axis3dOptions& options) {
  options.Check();
  CheckViews(views);
  std::vector<PreparedView> prepared(views.size());
  cv::parallel_for_(cv::Range(0, int(views.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) prepared[i] = Prepare(views[i], options);
  });

  const double min_epipolar_sin = std::sin(options.min_epipolar_angle_deg * kDegToRad);
  // Every pair of views, in parallel; the points are gathered in pair order,
  // so the result does not depend on the thread count.
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i < views.size(); ++i) {
    for (size_t j = i + 1; j < views.size(); ++j) pairs.emplace_back(i, j);
  }
  std::vector<std::vector<AxisPoint3d>> per_pair(pairs.size());
  cv::parallel_for_(cv::Range(0, int(pairs.size())), [&](const cv::Range& r) {
    for (int pair = r.start; pair < r.end; ++pair) {
      const auto [i, j] = pairs[pair];
      per_pair[pair] = TriangulatePair(views, prepared, i, j, min_epipolar_sin, options);
    }
  });
  std::vector<AxisPoint3d> raw;
  for (const std::vector<AxisPoint3d>& found : per_pair) raw.insert(raw.end(), found.begin(), found.end());
  if (options.merge_radius_m <= 0) return raw;
  return MergeNearby(raw, options);
}

AxisView MakeAxisView(const Camera& camera, const cv::Mat& silhouette, const BodyAxesOptions& options) {
  AxisView view;
  view.camera = camera;
  view.silhouette = silhouette;
  view.graph = ExtractAxisPoints(silhouette, options.points);
  const Eigen::Vector3d optical_axis_in_world = camera.cam_from_world.linear().transpose().col(2);
  const double elevation_deg = std::asin(std::clamp(optical_axis_in_world.z(), -1.0, 1.0)) / kDegToRad;
  if (std::abs(elevation_deg) > options.max_view_elevation_deg) return view;
  if (auto parts = SegmentBodyParts(silhouette, view.graph, options.parts)) view.labels = std::move(parts->labels);
  return view;
}

std::vector<AxisPoint3d> ReconstructBodyAxes(const std::vector<Camera>& cameras,
                                             const std::vector<cv::Mat>& silhouettes,
                                             const BodyAxesOptions& options,
                                             std::vector<AxisView>* views_out,
                                             const std::vector<cv::Mat>* distances) {
  options.Check();
  if (cameras.size() != silhouettes.size()) {
    throw std::invalid_argument("ReconstructBodyAxes: one silhouette per camera");
  }
  if (distances && distances->size() != cameras.size()) {
    throw std::invalid_argument("ReconstructBodyAxes: one distance transform per camera");
  }
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (silhouettes[i].type() != CV_8UC1 || silhouettes[i].cols != cameras[i].width ||
        silhouettes[i].rows != cameras[i].height) {
      throw std::invalid_argument("ReconstructBodyAxes: silhouette of camera '" + cameras[i].name +
                                  "' is not CV_8UC1 of the camera's size");
    }
  }
  std::vector<AxisView> views(cameras.size());
  cv::parallel_for_(cv::Range(0, int(cameras.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      views[i] = MakeAxisView(cameras[i], silhouettes[i], options);
      if (distances) views[i].distance_to_silhouette = (*distances)[i];
    }
  });
  std::vector<AxisPoint3d> points = ReconstructAxis3d(views, options.axis3d);
  // The caller's distance maps stay with the caller (four floats a pixel).
  for (AxisView& view : views) view.distance_to_silhouette.release();
  if (views_out) *views_out = std::move(views);
  return points;
}

}  // namespace irbench
