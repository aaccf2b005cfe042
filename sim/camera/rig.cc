#include "sim/camera/rig.h"

#include <cmath>
#include <set>
#include <sstream>

#include "common/json_reader.h"

namespace irbench {

std::string CheckDistortionUsable(const Camera& camera) {
  // Along the image border the distortion must invert, and the radial mapping
  // must be monotonic out to the farthest corner.
  const double w = camera.width, h = camera.height;
  double max_r2 = 0;
  for (double u : {-0.5, w - 0.5}) {
    for (double v : {-0.5, h - 0.5}) {
      const auto xu = camera.UndistortPixel({u, v});
      if (!xu) return "distortion does not invert at the image corner";
      max_r2 = std::max(max_r2, xu->squaredNorm());
    }
  }
  const double k1 = camera.dist[0], k2 = camera.dist[1], k3 = camera.dist[4];
  for (int i = 0; i <= 200; ++i) {
    const double r2 = max_r2 * 1.2 * i / 200.0;
    // d/dr of r * (1 + k1 r^2 + k2 r^4 + k3 r^6)
    const double derivative = 1 + 3 * k1 * r2 + 5 * k2 * r2 * r2 + 7 * k3 * r2 * r2 * r2;
    if (derivative <= 0.05) return "radial distortion folds inside the image";
  }
  return "";
}

namespace {

std::string Str(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// A focal length in pixels against the image's `size` along its axis.
void CheckFocal(const JsonNode& node, double focal, int size, const std::string& axis) {
  const double lo = kMinFocalPerPixel * size, hi = kMaxFocalPerPixel * size;
  if (!(focal >= lo && focal <= hi)) {
    node.Fail("focal length must be in [" + Str(lo) + ", " + Str(hi) + "] px (" +
              Str(kMinFocalPerPixel) + " to " + Str(kMaxFocalPerPixel) + " x the image " + axis +
              "; got " + Str(focal) + ")");
  }
}

// Three coordinates, each within +-kMaxRigCoordinateM.
Eigen::Vector3d Coordinates(const JsonNode& node) {
  const Eigen::Vector3d v = node.Vec3();
  for (int k = 0; k < 3; ++k) {
    if (std::abs(v[k]) > kMaxRigCoordinateM) {
      node[k].Fail("must be within +-" + Str(kMaxRigCoordinateM) + " m");
    }
  }
  return v;
}

}  // namespace

Rig LoadRig(const std::filesystem::path& path) {
  const JsonNode root = ParseJsonFile(path.string());
  root.CheckKeys({"format", "name", "scene", "description", "cameras"});
  if (root.GetString("format") != "irbench.rig/1") {
    root["format"].Fail("expected \"irbench.rig/1\"");
  }
  Rig rig;
  rig.source = path;
  rig.name = root.GetString("name", path.stem().string());
  rig.scene = root.GetString("scene", "");
  const JsonNode cameras = root["cameras"];
  if (cameras.Size() == 0) cameras.Fail("a rig needs at least one camera");
  std::set<std::string> names;
  for (size_t i = 0; i < cameras.Size(); ++i) {
    const JsonNode c = cameras[i];
    c.CheckKeys({"name", "width", "height", "fx", "fy", "cx", "cy", "dist", "position", "look_at",
                 "up", "fps", "exposure_ms", "sensor", "description"});
    Camera cam;
    cam.name = c.GetString("name");
    if (const std::string problem = CameraNameProblem(cam.name); !problem.empty()) {
      c["name"].Fail(problem);
    }
    if (!names.insert(cam.name).second) c["name"].Fail("duplicate camera name '" + cam.name + "'");
    cam.width = c.GetInt("width", 320);
    cam.height = c.GetInt("height", 240);
    if (cam.width < 8 || cam.width > 8192) c["width"].Fail("must be in 8..8192");
    if (cam.height < 8 || cam.height > 8192) c["height"].Fail("must be in 8..8192");
    cam.fx = c.GetDouble("fx");
    cam.fy = c.GetDouble("fy");
    cam.cx = c.GetDouble("cx");
    cam.cy = c.GetDouble("cy");
    if (cam.fx <= 0) c["fx"].Fail("focal length must be positive (got " + std::to_string(cam.fx) + ")");
    if (cam.fy <= 0) c["fy"].Fail("focal length must be positive (got " + std::to_string(cam.fy) + ")");
    CheckFocal(c["fx"], cam.fx, cam.width, "width");
    CheckFocal(c["fy"], cam.fy, cam.height, "height");
    if (cam.cx < 0 || cam.cx > cam.width - 1) c["cx"].Fail("principal point outside the image");
    if (cam.cy < 0 || cam.cy > cam.height - 1) c["cy"].Fail("principal point outside the image");
    const std::vector<double> dist = c["dist"].Numbers();
    if (dist.size() != 5) c["dist"].Fail("expected 5 numbers: k1 k2 p1 p2 k3");
    for (int k = 0; k < 5; ++k) {
      if (std::abs(dist[k]) > kMaxDistortionCoefficient) {
        c["dist"][k].Fail("|coefficient| must be at most " + Str(kMaxDistortionCoefficient));
      }
      cam.dist[k] = dist[k];
    }
    if (const std::string problem = CheckDistortionUsable(cam); !problem.empty()) {
      c["dist"].Fail(problem);
    }
    const Eigen::Vector3d position = Coordinates(c["position"]);
    const Eigen::Vector3d look_at = Coordinates(c["look_at"]);
    const Eigen::Vector3d up = c.Has("up") ? Coordinates(c["up"]) : Eigen::Vector3d(0, 0, 1);
    const auto cam_from_world = LookAt(position, look_at, up);
    if (!cam_from_world) c["look_at"].Fail("view direction is zero or parallel to 'up'");
    cam.cam_from_world = *cam_from_world;
    CameraTiming timing;
    timing.fps = c.GetDouble("fps", 30.0);
    if (timing.fps <= 0 || timing.fps > 1000) c["fps"].Fail("must be in (0, 1000]");
    timing.exposure_ms = c.GetDouble("exposure_ms", 10.0);
    if (timing.exposure_ms <= 0 || timing.exposure_ms > 1000.0 / timing.fps + 1e-9) {
      c["exposure_ms"].Fail("must be positive and at most the frame period");
    }
    rig.cameras.push_back(cam);
    rig.timing.push_back(timing);
    rig.up.push_back(up);
    rig.sensor_overrides.push_back(c.Has("sensor") ? c["sensor"].raw() : nlohmann::json());
  }
  return rig;
}

}  // namespace irbench
