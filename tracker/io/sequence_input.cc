#include "tracker/io/sequence_input.h"

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "common/error.h"
#include "common/json_reader.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// Frames are numbered from 0 without gaps: the count is the first missing one.
int CountNumbered(const fs::path& folder) {
  int n = 0;
  char name[32];
  for (;; ++n) {
    std::snprintf(name, sizeof(name), "%06d.png", n);
    if (!fs::is_regular_file(folder / name)) return n;
  }
}

cv::Mat ReadMatrix(const cv::FileStorage& fs, const std::string& file, const std::string& key, int rows,
                   int cols) {
  cv::Mat m;
  try {
    const cv::FileNode node = fs[key];
    if (node.empty() || node.isNone()) throw InputError(file, key, "missing");
    if (!node.isMap()) throw InputError(file, key, "not an opencv-matrix");
    node >> m;
  } catch (const cv::Exception& e) {
    throw InputError(file, key, "not an opencv-matrix: " + e.msg);
  }
  if (m.empty()) throw InputError(file, key, "missing");
  if (m.rows * m.cols != rows * cols) {
    throw InputError(file, key, "expected " + std::to_string(rows) + "x" + std::to_string(cols) + " values");
  }
  m.convertTo(m, CV_64F);
  if (!cv::checkRange(m)) throw InputError(file, key, "holds a NaN or an infinity");
  return m.reshape(1, rows);
}

// Frames are numbered from 0 without gaps: a gap with later frames behind it
// is an error, not the end of the sequence.
void CheckNoGap(const fs::path& folder, int count) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() != 10 || entry.path().extension() != ".png") continue;
    const std::string stem = name.substr(0, 6);
    if (stem.find_first_not_of("0123456789") != std::string::npos) continue;
    if (std::stoi(stem) > count) {
      char missing[32];
      std::snprintf(missing, sizeof(missing), "%06d.png", count);
      throw InputError(folder.string(), "", std::string(missing) + " is missing while later frames exist");
    }
  }
}

// calib/screens.json (irbench.screens/1): the geometry and the targets'
// screen coordinates.
std::vector<ScreenSurface> ReadScreens(const fs::path& path) {
  const JsonNode root = ParseJsonFile(path.string());
  if (root.GetString("format") != "irbench.screens/1") root["format"].Fail("expected \"irbench.screens/1\"");
  std::vector<ScreenSurface> out;
  const JsonNode list = root["screens"];
  for (size_t i = 0; i < list.Size(); ++i) {
    const JsonNode s = list[i];
    ScreenSurface screen;
    screen.name = s.GetString("name");
    const std::string type = s.GetString("type");
    if (type == "cylinder") {
      screen.kind = ScreenSurface::Kind::kCylinder;
      screen.center_xy = s["center_xy"].Vec2();
      screen.radius = s.GetDouble("radius");
      screen.angle_left_deg = s.GetDouble("angle_left_deg");
      screen.angle_right_deg = s.GetDouble("angle_right_deg");
      const Eigen::Vector2d z = s["z"].Vec2();
      screen.z0 = z.x(), screen.z1 = z.y();
      if (!(screen.radius > 0) || screen.z1 <= screen.z0 || screen.angle_left_deg <= screen.angle_right_deg) {
        s.Fail("not a valid cylinder (radius > 0, z rising, angle_left_deg > angle_right_deg)");
      }
    } else if (type == "plane") {
      screen.kind = ScreenSurface::Kind::kPlane;
      screen.origin = s["origin"].Vec3();
      screen.right = s["right"].Vec3().normalized();
      screen.up = s["up"].Vec3().normalized();
      screen.width = s.GetDouble("width");
      screen.height = s.GetDouble("height");
      if (!(screen.width > 0 && screen.height > 0)) s.Fail("width and height must be positive");
    } else {
      s["type"].Fail("must be cylinder or plane");
    }
    if (s.Has("targets")) {
      for (const auto& [name, t] : s["targets"].raw().items()) {
        const JsonNode target = s["targets"][name];
        screen.targets[name] = target["screen"].Vec2();
      }
    }
    out.push_back(screen);
  }
  return out;
}

}  // namespace

SequenceInput SequenceInput::Open(const fs::path& dir) {
  SequenceInput in;
  in.dir_ = dir;
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "", "no such sequence folder");
  const fs::path intri_file = dir / "calib/intri.yml", extri_file = dir / "calib/extri.yml";
  const fs::path cameras_file = dir / "calib/cameras.json";
  for (const fs::path& f : {intri_file, extri_file, cameras_file}) {
    if (!fs::is_regular_file(f)) throw InputError(f.string(), "", "missing (not a sequence folder?)");
  }
  cv::FileStorage intri, extri;
  try {
    intri.open(intri_file.string(), cv::FileStorage::READ);
    extri.open(extri_file.string(), cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    throw InputError(intri.isOpened() ? extri_file.string() : intri_file.string(), "", "unreadable: " + e.msg);
  }
  if (!intri.isOpened()) throw InputError(intri_file.string(), "", "unreadable");
  if (!extri.isOpened()) throw InputError(extri_file.string(), "", "unreadable");
  std::vector<std::string> names;
  try {
    intri["names"] >> names;
  } catch (const cv::Exception& e) {
    throw InputError(intri_file.string(), "names", "expected a list of camera names: " + e.msg);
  }
  if (names.empty()) throw InputError(intri_file.string(), "names", "missing or empty");
  const JsonNode cameras_json = ParseJsonFile(cameras_file.string());
  const JsonNode list = cameras_json["cameras"];
  for (const std::string& name : names) {
    Camera cam;
    cam.name = name;
    const cv::Mat k = ReadMatrix(intri, intri_file.string(), "K_" + name, 3, 3);
    cam.fx = k.at<double>(0, 0), cam.fy = k.at<double>(1, 1);
    cam.cx = k.at<double>(0, 2), cam.cy = k.at<double>(1, 2);
    if (!(cam.fx > 0 && cam.fy > 0)) throw InputError(intri_file.string(), "K_" + name, "focal lengths must be > 0");
    const cv::Mat dist = ReadMatrix(intri, intri_file.string(), "dist_" + name, 1, 5);
    for (int i = 0; i < 5; ++i) cam.dist[i] = dist.at<double>(0, i);
    const cv::Mat rot = ReadMatrix(extri, extri_file.string(), "Rot_" + name, 3, 3);
    const cv::Mat t = ReadMatrix(extri, extri_file.string(), "T_" + name, 3, 1);
    Eigen::Matrix3d r;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) r(a, b) = rot.at<double>(a, b);
    if ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || r.determinant() < 0) {
      throw InputError(extri_file.string(), "Rot_" + name, "not a rotation (orthonormal, determinant +1)");
    }
    cam.cam_from_world.linear() = r;
    cam.cam_from_world.translation() = Eigen::Vector3d(t.at<double>(0), t.at<double>(1), t.at<double>(2));
    bool found = false;
    for (size_t i = 0; i < list.Size(); ++i) {
      if (list[i].GetString("name") != name) continue;
      const std::string field = "cameras[" + std::to_string(i) + "]";
      cam.width = list[i].GetInt("width");
      cam.height = list[i].GetInt("height");
      if (cam.width <= 0 || cam.height <= 0) list[i]["width"].Fail("image size must be positive");
      cam.fps = list[i].GetDouble("fps");
      if (!(cam.fps > 0 && std::isfinite(cam.fps))) list[i]["fps"].Fail("must be > 0");
      cam.exposure_ms = list[i].GetDouble("exposure_ms", cam.exposure_ms);
      found = true;
    }
    if (!found) throw InputError(cameras_file.string(), "cameras", "no camera named '" + name + "'");
    in.cameras_.push_back(cam);
  }
  const fs::path screens_file = dir / "calib/screens.json";
  if (fs::is_regular_file(screens_file)) in.screens_ = ReadScreens(screens_file);
  for (size_t c = 0; c < in.cameras_.size(); ++c) {
    const int frames = CountNumbered(dir / "frames" / in.cameras_[c].name);
    const int backgrounds = CountNumbered(dir / "background" / in.cameras_[c].name);
    CheckNoGap(dir / "frames" / in.cameras_[c].name, frames);
    CheckNoGap(dir / "background" / in.cameras_[c].name, backgrounds);
    if (frames == 0) {
      throw InputError((dir / "frames" / in.cameras_[c].name).string(), "", "no frames (000000.png, ...)");
    }
    if (c == 0) {
      in.frame_count_ = frames;
      in.background_count_ = backgrounds;
    } else if (frames != in.frame_count_ || backgrounds != in.background_count_) {
      throw InputError((dir / "frames" / in.cameras_[c].name).string(), "",
                       "camera '" + in.cameras_[c].name + "' has " + std::to_string(frames) + " frames and " +
                           std::to_string(backgrounds) + " empty-stage frames; '" + in.cameras_[0].name +
                           "' has " + std::to_string(in.frame_count_) + " and " +
                           std::to_string(in.background_count_));
    }
  }
  return in;
}

fs::path SequenceInput::FramePath(int camera, int frame) const {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return dir_ / "frames" / cameras_.at(camera).name / name;
}

fs::path SequenceInput::BackgroundPath(int camera, int index) const {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return dir_ / "background" / cameras_.at(camera).name / name;
}

cv::Mat SequenceInput::Load(const fs::path& path, int camera) const {
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) throw InputError(path.string(), "", "unreadable image");
  if (image.channels() != 1) throw InputError(path.string(), "", "expected a single-channel (grey) image");
  const Camera& cam = cameras_.at(camera);
  if (image.cols != cam.width || image.rows != cam.height) {
    throw InputError(path.string(), "",
                     "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                         ", calibration says " + std::to_string(cam.width) + "x" + std::to_string(cam.height));
  }
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257.0);
  if (image.depth() != CV_8U) throw InputError(path.string(), "", "expected 8- or 16-bit pixels");
  return image;
}

cv::Mat SequenceInput::Frame(int camera, int frame) const { return Load(FramePath(camera, frame), camera); }

std::vector<cv::Mat> SequenceInput::FrameSet(int frame) const {
  std::vector<cv::Mat> out;
  for (size_t c = 0; c < cameras_.size(); ++c) out.push_back(Frame(static_cast<int>(c), frame));
  return out;
}

cv::Mat SequenceInput::Background(int camera, int index) const {
  return Load(BackgroundPath(camera, index), camera);
}

std::vector<cv::Mat> SequenceInput::Backgrounds(int camera) const {
  std::vector<cv::Mat> out;
  for (int i = 0; i < background_count_; ++i) out.push_back(Background(camera, i));
  return out;
}

}  // namespace irbench
