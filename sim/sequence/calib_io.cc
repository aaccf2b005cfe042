#include "sim/sequence/calib_io.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace irbench {
namespace {

cv::Mat ToCv(const Eigen::MatrixXd& m) {
  cv::Mat out(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_64F);
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) out.at<double>(r, c) = m(r, c);
  }
  return out;
}

void WriteNames(cv::FileStorage& fs, const std::vector<Camera>& cameras) {
  fs << "names" << "[";
  for (const Camera& cam : cameras) fs << cam.name;
  fs << "]";
}

}  // namespace

std::string IntriYaml(const std::vector<Camera>& cameras) {
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  WriteNames(fs, cameras);
  for (const Camera& cam : cameras) {
    fs << "K_" + cam.name << ToCv(cam.K());
    cv::Mat dist(1, 5, CV_64F);
    for (int k = 0; k < 5; ++k) dist.at<double>(0, k) = cam.dist[k];
    fs << "dist_" + cam.name << dist;
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
    fs << "R_" + cam.name << rvec;
    fs << "Rot_" + cam.name << rot;
    fs << "T_" + cam.name << ToCv(cam.cam_from_world.translation());
  }
  return fs.releaseAndGetString();
}

nlohmann::json CamerasJson(const std::vector<Camera>& cameras, const std::vector<SensorSetup>& sensors) {
  nlohmann::json j;
  j["format"] = "irbench.cameras/1";
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
    c["R"] = {{r(0, 0), r(0, 1), r(0, 2)}, {r(1, 0), r(1, 1), r(1, 2)}, {r(2, 0), r(2, 1), r(2, 2)}};
    const Eigen::Vector3d t = cam.cam_from_world.translation();
    c["T"] = {t.x(), t.y(), t.z()};
    const Eigen::Vector3d center = cam.CenterInWorld();
    c["center_in_world"] = {center.x(), center.y(), center.z()};
    c["fps"] = cam.fps;
    c["exposure_ms"] = cam.exposure_ms;
    c["sensor"] = {{"preset", sensors[i].preset},
                   {"emva1288", sensors[i].sensor.ToJson()},
                   {"flicker", sensors[i].flicker.ToJson()},
                   {"optics", OpticsToJson(sensors[i].optics)},
                   {"capture", CaptureToJson(sensors[i].capture)}};
    j["cameras"].push_back(c);
  }
  return j;
}

}  // namespace irbench
