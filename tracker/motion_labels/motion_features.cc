#include "tracker/motion_labels/motion_features.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "tracker/pose/rest_state.h"

namespace irbench {
namespace {

std::optional<Eigen::Vector3d> Joint(const nlohmann::json& joints, const char* name) {
  const auto it = joints.find(name);
  if (it == joints.end() || !it->is_array() || it->size() != 3) return std::nullopt;
  for (const auto& v : *it) {
    if (!v.is_number()) return std::nullopt;
  }
  return Eigen::Vector3d((*it)[0].get<double>(), (*it)[1].get<double>(), (*it)[2].get<double>());
}

// Rows: the upper-body frame's axes in world coordinates.
Eigen::Matrix3d UpperBodyFromWorld(const MotionObservation& o) {
  const Eigen::Vector3d z = (o.neck - o.waist).normalized();
  Eigen::Vector3d x = o.shoulder[0] - o.shoulder[1];
  x = (x - x.dot(z) * z).normalized();
  Eigen::Matrix3d m;
  m.row(0) = x;
  m.row(1) = z.cross(x);
  m.row(2) = z;
  return m;
}

// Positions: x, y, z / height, then rho / height and theta.
void PutPosition(const Eigen::Vector3d& p, double height_m, MotionFeatures* f, int at) {
  f->segment<3>(at) = p / height_m;
  (*f)(at + 3) = std::hypot(p.x(), p.y()) / height_m;
  (*f)(at + 4) = std::atan2(p.x(), p.y());
}

// Velocity `v` at position `p` (m/s): unit direction, cylindrical unit
// direction (d rho, rho d theta, dz), speed.
void PutVelocity(const Eigen::Vector3d& p, const Eigen::Vector3d& v, MotionFeatures* f, int at) {
  const double speed = v.norm();
  const double scale = 1.0 / std::max(speed, kDirectionSpeed);
  f->segment<3>(at) = v * scale;
  const double rho = std::hypot(p.x(), p.y());
  Eigen::Vector3d cyl(0, 0, v.z());
  if (rho > 1e-9) {
    const Eigen::Vector2d radial(p.x() / rho, p.y() / rho);  // d rho along it
    const Eigen::Vector2d tangential(radial.y(), -radial.x());  // increasing theta = atan2(x, y)
    cyl.x() = radial.dot(v.head<2>());
    cyl.y() = tangential.dot(v.head<2>());
  }
  f->segment<3>(at + 3) = cyl * scale;
  (*f)(at + 6) = speed;
}

}  // namespace

const std::vector<std::string>& MotionFeatureNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const char* joint : {"elbow", "wrist"}) {
      for (const char* p : {"x", "y", "z", "rho", "theta"}) n.push_back(std::string(joint) + "_" + p);
    }
    for (const char* joint : {"elbow", "wrist"}) {
      for (const char* v : {"dir_x", "dir_y", "dir_z", "dir_rho", "dir_theta", "dir_z_cyl", "speed"}) {
        n.push_back(std::string(joint) + "_" + v);
      }
    }
    for (const char* v : {"wrist_long_dir_x", "wrist_long_dir_y", "wrist_long_dir_z", "wrist_long_speed",
                          "elbow_long_speed"}) {
      n.push_back(v);
    }
    n.push_back("rest_margin");
    return n;
  }();
  return names;
}

std::optional<MotionObservation> MotionObservationFromTrackLine(const nlohmann::json& line, const RestClassifier* rest) {
  if (!line.is_object() || line.value("state", "") != "tracking") return std::nullopt;
  const auto joints = line.find("joints3d");
  const auto height = line.find("height_m");
  const auto t = line.find("t");
  if (joints == line.end() || !joints->is_object() || height == line.end() || !height->is_number() ||
      t == line.end() || !t->is_number()) {
    return std::nullopt;
  }
  MotionObservation o;
  o.t = t->get<double>();
  o.height_m = height->get<double>();
  if (!(o.height_m > 0.5)) return std::nullopt;
  const auto waist = Joint(*joints, "waist"), neck = Joint(*joints, "neck");
  if (!waist || !neck) return std::nullopt;
  o.waist = *waist;
  o.neck = *neck;
  const char* names[2][3] = {{"right_shoulder", "right_elbow", "right_wrist"},
                             {"left_shoulder", "left_elbow", "left_wrist"}};
  for (int a = 0; a < 2; ++a) {
    const auto s = Joint(*joints, names[a][0]), e = Joint(*joints, names[a][1]), w = Joint(*joints, names[a][2]);
    if (!s || !e || !w) return std::nullopt;
    o.shoulder[a] = *s;
    o.elbow[a] = *e;
    o.wrist[a] = *w;
  }
  if ((o.neck - o.waist).norm() < 1e-6 || (o.shoulder[0] - o.shoulder[1]).norm() < 1e-6) return std::nullopt;
  if (rest && !rest->empty()) {
    for (int a = 0; a < 2; ++a) {
      o.rest_margin[a] = rest->Margin(RestFeatures(o.waist, o.neck, o.shoulder[0], o.shoulder[1], o.elbow[a],
                                                   o.wrist[a], o.height_m, a == 1));
    }
  }
  return o;
}

std::string MirrorMotionLabel(const std::string& label) {
  if (label == "LEFT") return "RIGHT";
  if (label == "RIGHT") return "LEFT";
  return label;
}

std::optional<std::array<MotionFeatures, 2>> MotionFeatureExtractor::Update(
    const std::optional<MotionObservation>& observation) {
  if (!observation) {
    for (auto& h : history_) h.clear();
    return std::nullopt;
  }
  const MotionObservation& o = *observation;
  const Eigen::Matrix3d upper_from_world = UpperBodyFromWorld(o);
  std::array<MotionFeatures, 2> out;
  // Into the upper-body frame, the left arm mirrored.
  for (int a = 0; a < 2; ++a) {
    Eigen::Matrix3d to_body = upper_from_world;
    if (a == 1) to_body.row(0) = -to_body.row(0);
    const ArmSample s{o.t, o.elbow[a] - o.shoulder[a], o.wrist[a] - o.shoulder[a]};
    std::deque<ArmSample>& h = history_[a];
    h.push_back(s);
    while (h.size() > static_cast<size_t>(kLongVelocityFrames + 1)) h.pop_front();
    // Velocities from the sample `frames` back (or the oldest there is).
    auto velocities = [&](int frames, Eigen::Vector3d* elbow, Eigen::Vector3d* wrist) {
      const ArmSample& before = h[h.size() - 1 - std::min<size_t>(frames, h.size() - 1)];
      const double dt = s.t - before.t;
      *elbow = dt > 0 ? Eigen::Vector3d(to_body * (s.elbow - before.elbow) / dt) : Eigen::Vector3d::Zero();
      *wrist = dt > 0 ? Eigen::Vector3d(to_body * (s.wrist - before.wrist) / dt) : Eigen::Vector3d::Zero();
    };
    Eigen::Vector3d v_elbow, v_wrist, v_elbow_long, v_wrist_long;
    velocities(kVelocityFrames, &v_elbow, &v_wrist);
    velocities(kLongVelocityFrames, &v_elbow_long, &v_wrist_long);
    MotionFeatures& f = out[a];
    const Eigen::Vector3d elbow = to_body * s.elbow, wrist = to_body * s.wrist;
    PutPosition(elbow, o.height_m, &f, 0);
    PutPosition(wrist, o.height_m, &f, 5);
    PutVelocity(elbow, v_elbow, &f, 10);
    PutVelocity(wrist, v_wrist, &f, 17);
    const double long_speed = v_wrist_long.norm();
    f.segment<3>(24) = v_wrist_long / std::max(long_speed, kDirectionSpeed);
    f(27) = long_speed;
    f(28) = v_elbow_long.norm();
    f(29) = o.rest_margin[a];
  }
  return out;
}

}  // namespace irbench
