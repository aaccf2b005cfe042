#include "sequence_format/calibration.h"

#include <cmath>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// The FileStorage keys of one camera.
std::string KKey(const std::string& cam) {
  return "K_" + cam;
}
std::string DistKey(const std::string& cam) {
  return "dist_" + cam;
}
std::string RvecKey(const std::string& cam) {
  return "R_" + cam;
}
std::string RotKey(const std::string& cam) {
  return "Rot_" + cam;
}
std::string TKey(const std::string& cam) {
  return "T_" + cam;
}
constexpr char kNamesKey[] = "names";

cv::Mat ToCv(const Eigen::MatrixXd& m) {
  cv::Mat out(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_64F);
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) out.at<double>(r, c) = m(r, c);
  }
  return out;
}

void WriteNames(cv::FileStorage& fs, const std::vector<Camera>& cameras) {
  fs << kNamesKey << "[";
  for (const Camera& cam : cameras) fs << cam.name;
  fs << "]";
}

// A rows x cols matrix of finite doubles under `key`; InputError otherwise.
cv::Mat ReadMatrix(const cv::FileStorage& fs,
                   const std::string& file,
                   const std::string& key,
                   int rows,
                   int cols) {
  cv::Mat m;
  try {
    const cv::FileNode node = fs[key];
    if (node.empty() || node.isNone()) throw InputError(file, key, "missing");
    if (!node.isMap()) throw InputError(file, key, "not an opencv-matrix");
    // The declared size is checked before OpenCV allocates it (a garbage
    // `cols` asked for 48 GiB: found by fuzz/calibration_fuzz).
    const cv::FileNode node_rows = node["rows"], node_cols = node["cols"], data = node["data"];
    const int n = rows * cols;
    const int r = node_rows.isInt() ? static_cast<int>(node_rows) : 0;
    const int c = node_cols.isInt() ? static_cast<int>(node_cols) : 0;
    if (r < 1 || c < 1 || r > n || c > n || r * c != n) {
      throw InputError(file, key, "expected rows: " + std::to_string(rows) + ", cols: " + std::to_string(cols));
    }
    if (!data.isSeq() || data.size() != static_cast<size_t>(rows * cols)) {
      throw InputError(file, key, "expected " + std::to_string(rows * cols) + " values in data");
    }
    node >> m;
  } catch (const cv::Exception& e) {
    throw InputError(file, key, "not an opencv-matrix: " + e.msg);
  }
  if (m.empty()) throw InputError(file, key, "missing");
  if (m.rows * m.cols != rows * cols) {
    throw InputError(file, key,
                     "expected " + std::to_string(rows) + "x" + std::to_string(cols) + " values");
  }
  m.convertTo(m, CV_64F);
  if (!cv::checkRange(m)) throw InputError(file, key, "holds a NaN or an infinity");
  return m.reshape(1, rows);
}

// OpenCV's YAML parser (4.6, Debian 12) never returns on some malformed
// files (fuzz/calibration_fuzz found several: a second `%YAML` directive after
// `---`; an indented first key followed by `--` and `-`). So a calibration
// file must be in the layout OpenCV itself writes, checked line by line
// before the parser sees it: `%YAML` on line 1, `---` only as line 2; no
// control characters; top-level `key:` lines at column 0 (key [A-Za-z0-9_-]); indented lines
// only under a top-level key: `- item` under a list key, `rows:`, `cols:`,
// `dt:`, `data:` under an `!!opencv-matrix`; a `[ ... ]` may run over lines of
// values. Also bounds the size (a rig of a thousand cameras is under 1 MB).
void CheckYamlLayout(const fs::path& file) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) throw InputError(file.string(), "", "unreadable");
  if (size > (8u << 20)) throw InputError(file.string(), "", "over 8 MB: not a calibration file");
  std::ifstream in(file, std::ios::binary);
  enum class Block { kNone, kList, kMatrix } block = Block::kNone;
  bool in_flow = false;  // inside a [ ... ] that runs over lines
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    auto refuse = [&](const std::string& why) {
      throw InputError(file.string(), "", "line " + std::to_string(n) + ": not OpenCV's YAML layout: " + why);
    };
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    for (unsigned char ch : line) {
      if (ch < 0x20 || ch == 0x7f) refuse("a control character");
    }
    if (n == 1) {
      if (line.rfind("%YAML", 0) != 0) refuse("expected the %YAML:1.0 directive");
      continue;
    }
    if ((n == 2 && line == "---") || line.empty()) continue;
    const size_t indent = line.find_first_not_of(' ');
    const std::string body = line.substr(indent);
    if (body[0] == '#') continue;
    if (in_flow) {
      if (body.find_first_of("[:{}%") != std::string::npos || body.rfind("--", 0) == 0) {
        refuse("expected values inside [ ]");
      }
      in_flow = body.find(']') == std::string::npos;
      continue;
    }
    const size_t colon = body.find(':');
    const std::string key = body.substr(0, colon);
    const std::string value = colon == std::string::npos ? "" : body.substr(colon + 1);
    if (indent == 0) {
      if (colon == std::string::npos || key.empty() || key.find_first_not_of(
              "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") != std::string::npos) {
        refuse("expected 'key:' at the start of the line");
      }
      block = value.empty() ? Block::kList : value == " !!opencv-matrix" ? Block::kMatrix : Block::kNone;
    } else if (block == Block::kList) {
      if (body.rfind("- ", 0) != 0 || body.size() < 3) refuse("expected '- item' under a list");
      continue;
    } else if (block == Block::kMatrix) {
      if (key != "rows" && key != "cols" && key != "dt" && key != "data") refuse("expected rows, cols, dt or data");
    } else {
      refuse("an indented line outside a list or matrix");
    }
    if (value.rfind(" [", 0) == 0) in_flow = value.find(']') == std::string::npos;
  }
  if (in_flow) throw InputError(file.string(), "", "a [ ... ] that does not close");
}

// Opens both FileStorage files for reading; InputError naming the one that fails.
void OpenYaml(const fs::path& intri_file,
              const fs::path& extri_file,
              cv::FileStorage* intri,
              cv::FileStorage* extri) {
  CheckYamlLayout(intri_file);
  CheckYamlLayout(extri_file);
  try {
    intri->open(intri_file.string(), cv::FileStorage::READ);
    extri->open(extri_file.string(), cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    throw InputError(intri->isOpened() ? extri_file.string() : intri_file.string(), "",
                     "unreadable: " + e.msg);
  }
  if (!intri->isOpened()) throw InputError(intri_file.string(), "", "unreadable");
  if (!extri->isOpened()) throw InputError(extri_file.string(), "", "unreadable");
}

// K_ and dist_ of camera `cam.name` from intri.yml.
void ReadIntrinsics(const cv::FileStorage& intri, const std::string& file, Camera& cam) {
  const cv::Mat k = ReadMatrix(intri, file, KKey(cam.name), 3, 3);
  cam.fx = k.at<double>(0, 0), cam.fy = k.at<double>(1, 1);
  cam.cx = k.at<double>(0, 2), cam.cy = k.at<double>(1, 2);
  if (!(cam.fx > 0 && cam.fy > 0))
    throw InputError(file, KKey(cam.name), "focal lengths must be > 0");
  const cv::Mat dist = ReadMatrix(intri, file, DistKey(cam.name), 1, 5);
  for (int i = 0; i < 5; ++i) cam.dist[i] = dist.at<double>(0, i);
}

// Rot_ and T_ of camera `cam.name` from extri.yml: cam_from_world.
void ReadExtrinsics(const cv::FileStorage& extri, const std::string& file, Camera& cam) {
  const cv::Mat rot = ReadMatrix(extri, file, RotKey(cam.name), 3, 3);
  const cv::Mat t = ReadMatrix(extri, file, TKey(cam.name), 3, 1);
  Eigen::Matrix3d r;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) r(a, b) = rot.at<double>(a, b);
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
      r.determinant() < 0) {
    throw InputError(file, RotKey(cam.name), "not a rotation (orthonormal, determinant +1)");
  }
  cam.cam_from_world.linear() = r;
  cam.cam_from_world.translation() =
      Eigen::Vector3d(t.at<double>(0), t.at<double>(1), t.at<double>(2));
}

// Image size, fps and exposure of camera `cam.name` from cameras.json's list.
void ReadTiming(const JsonNode& list, const std::string& file, Camera& cam, CameraTiming& timing) {
  bool found = false;
  for (size_t i = 0; i < list.Size(); ++i) {
    if (list[i].GetString("name") != cam.name) continue;
    cam.width = list[i].GetInt("width");
    cam.height = list[i].GetInt("height");
    if (cam.width <= 0 || cam.height <= 0) list[i]["width"].Fail("image size must be positive");
    timing.fps = list[i].GetDouble("fps");
    if (!(timing.fps > 0 && std::isfinite(timing.fps))) list[i]["fps"].Fail("must be > 0");
    timing.exposure_ms = list[i].GetDouble("exposure_ms", timing.exposure_ms);
    found = true;
  }
  if (!found) throw InputError(file, "cameras", "no camera named '" + cam.name + "'");
}

}  // namespace

std::string CameraNameProblem(const std::string& name) {
  if (name.empty()) return "a camera name must not be empty";
  if (name.size() > kMaxCameraNameLength) {
    return "a camera name has at most " + std::to_string(kMaxCameraNameLength) +
           " characters (got " + std::to_string(name.size()) + ")";
  }
  for (const char c : name) {
    const bool safe = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                      c == '_' || c == '-';
    if (!safe) return "a camera name may hold only A-Z, a-z, 0-9, '_' and '-'";
  }
  if (name[0] == '-') return "a camera name must not start with '-'";
  return "";
}

std::string IntriYaml(const std::vector<Camera>& cameras) {
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  WriteNames(fs, cameras);
  for (const Camera& cam : cameras) {
    fs << KKey(cam.name) << ToCv(cam.K());
    cv::Mat dist(1, 5, CV_64F);
    for (int k = 0; k < 5; ++k) dist.at<double>(0, k) = cam.dist[k];
    fs << DistKey(cam.name) << dist;
  }
  return fs.releaseAndGetString();
}

std::string ExtriYaml(const std::vector<Camera>& cameras) {
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  WriteNames(fs, cameras);
  for (const Camera& cam : cameras) {
    const cv::Mat rot = ToCv(cam.cam_from_world.linear());
    cv::Mat rvec;
    cv::Rodrigues(rot, rvec);
    fs << RvecKey(cam.name) << rvec;
    fs << RotKey(cam.name) << rot;
    fs << TKey(cam.name) << ToCv(cam.cam_from_world.translation());
  }
  return fs.releaseAndGetString();
}

nlohmann::json CamerasJson(const std::vector<Camera>& cameras,
                           const std::vector<CameraTiming>& timing,
                           const std::vector<nlohmann::json>& sensors) {
  nlohmann::json j;
  j["format"] = kCamerasFormat;
  j["convention"] =
      "OpenCV pinhole + Brown-Conrady (k1 k2 p1 p2 k3); pixel (0,0) is the centre of the top-left "
      "pixel; R and T are cam_from_world, world in metres, z up";
  j["cameras"] = nlohmann::json::array();
  for (size_t i = 0; i < cameras.size(); ++i) {
    const Camera& cam = cameras[i];
    nlohmann::json c;
    c["name"] = cam.name;
    c["width"] = cam.width;
    c["height"] = cam.height;
    c["K"] = {{cam.fx, 0.0, cam.cx}, {0.0, cam.fy, cam.cy}, {0.0, 0.0, 1.0}};
    c["dist"] = cam.dist;
    const Eigen::Matrix3d r = cam.cam_from_world.linear();
    c["R"] = {
        {r(0, 0), r(0, 1), r(0, 2)}, {r(1, 0), r(1, 1), r(1, 2)}, {r(2, 0), r(2, 1), r(2, 2)}};
    const Eigen::Vector3d t = cam.cam_from_world.translation();
    c["T"] = {t.x(), t.y(), t.z()};
    const Eigen::Vector3d center = cam.CenterInWorld();
    c["center_in_world"] = {center.x(), center.y(), center.z()};
    c["fps"] = timing.at(i).fps;
    c["exposure_ms"] = timing.at(i).exposure_ms;
    c["sensor"] = sensors.at(i);
    j["cameras"].push_back(c);
  }
  return j;
}

void WriteCalibration(const fs::path& sequence_dir,
                      const std::vector<Camera>& cameras,
                      const std::vector<CameraTiming>& timing,
                      const std::vector<nlohmann::json>& sensors) {
  AtomicWriteFile(sequence_dir / kIntriFile, IntriYaml(cameras));
  AtomicWriteFile(sequence_dir / kExtriFile, ExtriYaml(cameras));
  AtomicWriteFile(sequence_dir / kCamerasFile, CamerasJson(cameras, timing, sensors).dump(2) + "\n");
}

namespace {

// The camera names of intri.yml, each checked.
std::vector<std::string> CameraNames(const cv::FileStorage& intri, const fs::path& intri_file) {
  std::vector<std::string> names;
  try {
    intri[kNamesKey] >> names;
  } catch (const cv::Exception& e) {
    throw InputError(intri_file.string(), kNamesKey, "expected a list of camera names: " + e.msg);
  }
  if (names.empty()) throw InputError(intri_file.string(), kNamesKey, "missing or empty");
  for (size_t i = 0; i < names.size(); ++i) {
    if (const std::string problem = CameraNameProblem(names[i]); !problem.empty()) {
      throw InputError(intri_file.string(), std::string(kNamesKey) + "[" + std::to_string(i) + "]",
                       problem);
    }
  }
  return names;
}

}  // namespace

Calibration ReadCalibration(const fs::path& dir) {
  const fs::path intri_file = dir / kIntriFile, extri_file = dir / kExtriFile;
  const fs::path cameras_file = dir / kCamerasFile;
  for (const fs::path& f : {intri_file, extri_file, cameras_file}) {
    if (!fs::is_regular_file(f))
      throw InputError(f.string(), "", "missing (not a sequence folder?)");
  }
  cv::FileStorage intri, extri;
  OpenYaml(intri_file, extri_file, &intri, &extri);
  const std::vector<std::string> names = CameraNames(intri, intri_file);
  const JsonNode cameras_json = ParseJsonFile(cameras_file.string());
  const JsonNode list = cameras_json["cameras"];
  Calibration calibration;
  for (const std::string& name : names) {
    Camera cam;
    cam.name = name;
    CameraTiming timing;
    ReadIntrinsics(intri, intri_file.string(), cam);
    ReadExtrinsics(extri, extri_file.string(), cam);
    ReadTiming(list, cameras_file.string(), cam, timing);
    calibration.cameras.push_back(cam);
    calibration.timing.push_back(timing);
  }
  return calibration;
}

Calibration ReadEasyMocapCalibration(const fs::path& intri_file, const fs::path& extri_file) {
  for (const fs::path& f : {intri_file, extri_file}) {
    if (!fs::is_regular_file(f)) throw InputError(f.string(), "", "missing");
  }
  cv::FileStorage intri, extri;
  OpenYaml(intri_file, extri_file, &intri, &extri);
  Calibration calibration;
  for (const std::string& name : CameraNames(intri, intri_file)) {
    Camera cam;
    cam.name = name;
    ReadIntrinsics(intri, intri_file.string(), cam);
    ReadExtrinsics(extri, extri_file.string(), cam);
    calibration.cameras.push_back(cam);
    calibration.timing.push_back(CameraTiming{});
  }
  return calibration;
}

}  // namespace irbench
