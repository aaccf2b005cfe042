#include "sim/motion/retarget.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/logging.h"
#include "sim/motion/asf_amc.h"
#include "sim/motion/bvh.h"

namespace irbench {
namespace {

using Map = std::map<std::string, std::string>;

// Canonical names in skeleton order, then "head_top".
const std::vector<std::string>& CanonicalKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k;
    for (int j = 0; j < kJointCount; ++j) k.push_back(JointName(j));
    k.push_back("head_top");
    return k;
  }();
  return keys;
}

Map MakeMap(const std::vector<std::string>& names) {
  Map map;
  for (size_t i = 0; i < names.size(); ++i) {
    if (!names[i].empty()) map[CanonicalKeys()[i]] = names[i];
  }
  return map;
}

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b) * 180.0 / M_PI;
}

// The largest turn of any joint from frame f to frame f + 1, in degrees.
double StepDeg(const MocapClip& clip, size_t f) {
  double step = 0;
  for (size_t j = 0; j < clip.joint_names.size(); ++j) {
    step = std::max(step, AngleDeg(clip.frames[f].rotation[j], clip.frames[f + 1].rotation[j]));
  }
  return step;
}

// Drops a synthetic start (see LoadMocap).
void DropSyntheticStart(MocapClip& clip) {
  if (clip.frames.size() < 4) return;
  std::vector<double> steps;  // steps[f]: frame f to f + 1
  for (size_t f = 0; f + 1 < clip.frames.size(); ++f) steps.push_back(StepDeg(clip, f));
  const double d01 = steps[0], d12 = steps[1];
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double fast = std::max(5.0, 4.0 * sorted[sorted.size() / 2]);
  size_t drop = d01 > 10.0 && d01 > 5.0 * d12 ? 1 : 0;
  const size_t most = 1 + static_cast<size_t>(std::floor(0.1 / clip.frame_time));
  while (drop < most && drop + 3 < clip.frames.size() && steps[drop] > fast) ++drop;
  if (drop == 0) return;
  Log().info("motion: {}: a synthetic start dropped: frame 0 turns some joint {:.0f}° to frame 1 (then {:.1f}°){}",
             clip.name, d01, d12,
             drop > 1 ? fmt::format(", and frames up to {} blend into the capture (over {:.1f}° per frame, "
                                    "4x the clip's median)",
                                    drop - 1, fast)
                      : std::string());
  clip.frames.erase(clip.frames.begin(), clip.frames.begin() + drop);
}

Eigen::Matrix3d FrameFrom(const Eigen::Vector3d& right, const Eigen::Vector3d& up) {
  const Eigen::Vector3d x = right.normalized();
  const Eigen::Vector3d z = (up - x * x.dot(up)).normalized();
  Eigen::Matrix3d m;
  m.col(0) = x;
  m.col(1) = z.cross(x);
  m.col(2) = z;
  return m;
}

// A table entry may list alternatives separated by '|'.
int FindMapped(const MocapClip& clip, const std::string& names) {
  size_t start = 0;
  while (true) {
    const size_t bar = names.find('|', start);
    const int j = clip.FindJoint(names.substr(start, bar == std::string::npos ? std::string::npos : bar - start));
    if (j >= 0 || bar == std::string::npos) return j;
    start = bar + 1;
  }
}

}  // namespace

std::map<std::string, std::string> JointMapFor(const std::string& convention) {
  // Order: pelvis spine chest neck head, right clavicle shoulder elbow wrist,
  // left clavicle shoulder elbow wrist, right hip knee ankle, left hip knee
  // ankle, head_top.
  if (convention == "mb") {
    return MakeMap({"Hips", "Spine", "Spine1", "Neck1", "Head", "RightShoulder", "RightArm",
                    "RightForeArm", "RightHand", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
                    "RightUpLeg", "RightLeg", "RightFoot", "LeftUpLeg", "LeftLeg", "LeftFoot",
                    "Head_end"});
  }
  if (convention == "daz") {
    return MakeMap({"hip", "abdomen", "chest", "neck", "head", "rCollar", "rShldr", "rForeArm", "rHand",
                    "lCollar", "lShldr", "lForeArm", "lHand", "rThigh", "rShin", "rFoot", "lThigh",
                    "lShin", "lFoot", ""});
  }
  if (convention == "3dsmax") {
    return MakeMap({"Hips", "Chest", "Chest2", "Neck", "Head", "RightCollar", "RightShoulder",
                    "RightElbow", "RightWrist", "LeftCollar", "LeftShoulder", "LeftElbow", "LeftWrist",
                    "RightHip", "RightKnee", "RightAnkle", "LeftHip", "LeftKnee", "LeftAnkle",
                    "Head_end"});
  }
  if (convention == "cmu") {
    // Raw CMU bone names (ASF/AMC, amc2bvh): a joint sits at its bone's start.
    return MakeMap({"root|hip", "upperback", "thorax", "upperneck", "head", "rclavicle", "rhumerus",
                    "rradius", "rwrist", "lclavicle", "lhumerus", "lradius", "lwrist", "rfemur", "rtibia",
                    "rfoot", "lfemur", "ltibia", "lfoot", "head_end"});
  }
  if (convention == "irbench") {
    std::vector<std::string> names;
    for (int j = 0; j < kJointCount; ++j) names.push_back(JointName(j));
    names.push_back("head_end");
    return MakeMap(names);
  }
  return {};
}

std::string DetectConvention(const MocapClip& clip) {
  auto has = [&](const char* name) { return clip.FindJoint(name) >= 0; };
  if (has("pelvis") && has("right_shoulder") && has("left_wrist")) return "irbench";
  if (has("lhumerus") && has("rradius")) return "cmu";
  if (has("lShldr") && has("rForeArm")) return "daz";
  if (has("LeftElbow") && has("RightWrist") && has("Chest2")) return "3dsmax";
  if (has("LeftArm") && has("RightForeArm") && has("Spine1")) return "mb";
  return "";
}

MocapClip LoadMocap(const std::filesystem::path& path, const std::filesystem::path& asf) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  MocapClip clip;
  if (ext == ".bvh") {
    clip = BvhToClip(LoadBvh(path));
  } else if (ext == ".amc") {
    std::filesystem::path skeleton = asf;
    if (skeleton.empty()) {
      const std::string stem = path.stem().string();
      const std::filesystem::path by_subject =
          path.parent_path() / (stem.substr(0, stem.find('_')) + ".asf");
      const std::filesystem::path by_stem = path.parent_path() / (stem + ".asf");
      skeleton = std::filesystem::exists(by_subject) ? by_subject : by_stem;
      if (!std::filesystem::exists(skeleton)) {
        throw InputError(path.string(), "file", "no skeleton file beside it (looked for '" +
                                                    by_subject.string() + "' and '" + by_stem.string() + "')");
      }
    }
    clip = LoadAsfAmc(skeleton, path);
  } else {
    throw InputError(path.string(), "file", "unknown motion-capture format '" + ext + "' (.bvh or .amc)");
  }
  clip.file = path;
  clip.name = path.stem().string();
  if (clip.frames.empty()) throw InputError(path.string(), "frames", "the clip has no frames");
  clip.convention = DetectConvention(clip);
  if (clip.convention == "cmu" && ext == ".bvh" && std::abs(clip.frame_time - 1.0 / 30.0) < 1e-3) {
    Log().info("motion: {}: raw amc2bvh file declaring 1/30 s per frame; CMU captured at 120 Hz, "
               "using 1/120 s", clip.name);
    clip.frame_time = 1.0 / 120.0;
  }
  DropSyntheticStart(clip);
  return clip;
}

Eigen::Matrix3d WorldFromSource(const MocapClip& clip, const Map& map) {
  auto rest = [&](const char* key) { return clip.rest_position[FindMapped(clip, map.at(key))]; };
  // Up is the file's coordinate axis nearest the rest pose's pelvis-to-head
  // line: a capture volume's axes are levelled to gravity, but a rest
  // skeleton's spine leans (1-2 degrees forward in CMU's), and that lean taken
  // as up tilts the floor, so a subject who walks 3 m rises or sinks 10 cm. A
  // spine more than 20 degrees from every axis is taken as it is.
  const Eigen::Vector3d spine = (rest("head") - rest("pelvis")).normalized();
  Eigen::Index axis = 0;
  spine.cwiseAbs().maxCoeff(&axis);
  Eigen::Vector3d up = Eigen::Vector3d::Unit(axis) * (spine[axis] < 0 ? -1.0 : 1.0);
  if (up.dot(spine) < std::cos(20 * M_PI / 180)) up = spine;
  Eigen::Vector3d left = rest("left_hip") - rest("right_hip");
  left = (left - up * up.dot(left)).normalized();
  const Eigen::Vector3d forward = left.cross(up);
  Eigen::Matrix3d source, world;
  source << left, forward, up;
  world << -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ();
  return world * source.transpose();
}

RetargetedMotion::RetargetedMotion(std::string name, double frame_time, std::vector<Pose> poses)
    : MotionSource(std::move(name)), frame_time_(frame_time), poses_(std::move(poses)) {}

Pose RetargetedMotion::At(double t) const {
  const double x = std::clamp(t / frame_time_, 0.0, static_cast<double>(poses_.size() - 1));
  const size_t i = std::min(static_cast<size_t>(x), poses_.size() - 1);
  if (i + 1 >= poses_.size()) return poses_.back();
  const double u = x - i;
  Pose out;
  out.root_offset = (1 - u) * poses_[i].root_offset + u * poses_[i + 1].root_offset;
  for (int j = 0; j < kJointCount; ++j) {
    out.local_rotation[j] = poses_[i].local_rotation[j].slerp(u, poses_[i + 1].local_rotation[j]);
  }
  return out;
}

namespace {

// The rotation that levels the floor the clip's feet stand on, in the world
// `r` puts the source in (scaled to metres by `scale`). A capture's floor can
// lean a degree or two from its file's axes (CMU's walks rise or sink 2-6 cm
// over 3 m); the feet say where it is. In each half second the lower ankle's
// lowest point is a contact; a plane is fitted to the contacts by least squares,
// leaving out those more than 2 cm above it (jumps, tiptoe) and refitting, and
// kept level along a direction the contacts do not cover. Identity when there
// are fewer than 4 contacts or the plane leans more than 5 degrees (then the
// floor is not what the feet show).
Eigen::Matrix3d FloorTilt(const MocapClip& clip, const std::array<int, kJointCount>& src, const Eigen::Matrix3d& r,
                          double scale) {
  std::vector<Eigen::Vector3d> contacts;
  const size_t window = std::max<size_t>(1, static_cast<size_t>(std::lround(0.5 / clip.frame_time)));
  for (size_t start = 0; start + window <= clip.frames.size(); start += window) {
    Eigen::Vector3d low(0, 0, std::numeric_limits<double>::infinity());
    for (size_t f = start; f < start + window; ++f) {
      for (int ankle : {kRightAnkle, kLeftAnkle}) {
        const Eigen::Vector3d p = scale * (r * clip.frames[f].position[src[ankle]]);
        if (p.z() < low.z()) low = p;
      }
    }
    contacts.push_back(low);
  }
  if (contacts.size() < 4) return Eigen::Matrix3d::Identity();
  // The plane z = c + g . (xy - mean), fitted along each principal direction
  // of the contacts' spread that they cover (standard deviation 0.25 m or more)
  // and level along one they do not.
  Eigen::Vector2d slope = Eigen::Vector2d::Zero();
  std::vector<bool> use(contacts.size(), true);
  for (int pass = 0; pass < 4; ++pass) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    double mean_z = 0;
    int n = 0;
    for (size_t i = 0; i < contacts.size(); ++i) {
      if (!use[i]) continue;
      mean += contacts[i].head<2>();
      mean_z += contacts[i].z();
      ++n;
    }
    if (n < 4) return Eigen::Matrix3d::Identity();
    mean /= n;
    mean_z /= n;
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (size_t i = 0; i < contacts.size(); ++i) {
      if (use[i]) cov += (contacts[i].head<2>() - mean) * (contacts[i].head<2>() - mean).transpose() / n;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    slope.setZero();
    for (int k = 0; k < 2; ++k) {
      if (eig.eigenvalues()(k) < 0.25 * 0.25) continue;
      const Eigen::Vector2d dir = eig.eigenvectors().col(k);
      double uz = 0;
      for (size_t i = 0; i < contacts.size(); ++i) {
        if (use[i]) uz += dir.dot(contacts[i].head<2>() - mean) * (contacts[i].z() - mean_z) / n;
      }
      slope += dir * (uz / eig.eigenvalues()(k));
    }
    for (size_t i = 0; i < contacts.size(); ++i) {
      use[i] = contacts[i].z() - (mean_z + slope.dot(contacts[i].head<2>() - mean)) < 0.02;
    }
  }
  const Eigen::Vector3d up = Eigen::Vector3d(-slope.x(), -slope.y(), 1).normalized();
  if (up.z() < std::cos(5 * M_PI / 180)) {
    Log().warn("motion: {}: the feet's floor leans {:.1f}° from the file's up; not levelled", clip.name,
               std::acos(up.z()) * 180 / M_PI);
    return Eigen::Matrix3d::Identity();
  }
  if (up.z() < std::cos(0.2 * M_PI / 180)) {
    Log().info("motion: {}: the feet's floor leans {:.1f}° from the file's up; levelled", clip.name,
               std::acos(up.z()) * 180 / M_PI);
  }
  return Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

std::shared_ptr<RetargetedMotion> Retarget(const MocapClip& clip, const Skeleton& skeleton,
                                           const RetargetOptions& options) {
  Map map = JointMapFor(clip.convention);
  for (const auto& [key, value] : options.joint_map_overrides) map[key] = value;
  const std::string file = clip.file.string();
  // Source index per canonical joint (-1: absent, allowed for clavicles and head_top).
  std::array<int, kJointCount> src;
  std::string missing;
  for (int j = 0; j < kJointCount; ++j) {
    const auto it = map.find(JointName(j));
    src[j] = it == map.end() ? -1 : FindMapped(clip, it->second);
    const bool optional = j == kRightClavicle || j == kLeftClavicle;
    if (src[j] < 0 && !optional) {
      missing += std::string(missing.empty() ? "" : ", ") + JointName(j) +
                 (it == map.end() ? std::string(" (no name in the table)") : " (expected '" + it->second + "')");
    }
  }
  if (!missing.empty()) {
    throw InputError(file, "joints",
                     "cannot map the skeleton (convention '" +
                         (clip.convention.empty() ? std::string("unknown") : clip.convention) +
                         "'): missing " + missing);
  }
  const auto top_it = map.find("head_top");
  const int head_top = top_it == map.end() ? -1 : FindMapped(clip, top_it->second);

  const Eigen::Matrix3d heading =
      Eigen::AngleAxisd(options.heading_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d unlevelled = heading * WorldFromSource(clip, map);
  const auto& bind = skeleton.bind_position;
  auto src_len = [&](int a, int b) { return (clip.rest_position[src[a]] - clip.rest_position[src[b]]).norm(); };
  const double src_leg = src_len(kRightHip, kRightKnee) + src_len(kRightKnee, kRightAnkle) +
                         src_len(kLeftHip, kLeftKnee) + src_len(kLeftKnee, kLeftAnkle);
  const double our_leg = (bind[kRightHip] - bind[kRightKnee]).norm() +
                         (bind[kRightKnee] - bind[kRightAnkle]).norm() +
                         (bind[kLeftHip] - bind[kLeftKnee]).norm() + (bind[kLeftKnee] - bind[kLeftAnkle]).norm();
  if (!(src_leg > 0)) throw InputError(file, "joints", "the legs have zero length in the rest pose");
  const double scale = our_leg / src_leg;
  const Eigen::Matrix3d r = FloorTilt(clip, src, unlevelled, scale) * unlevelled;
  const Eigen::Quaterniond rq(r);

  std::vector<Pose> poses(clip.frames.size());
  for (size_t f = 0; f < clip.frames.size(); ++f) {
    const MocapClip::Frame& frame = clip.frames[f];
    auto p = [&](int j) -> Eigen::Vector3d { return r * frame.position[src[j]]; };
    auto d = [&](int j) -> Eigen::Quaterniond { return rq * frame.rotation[src[j]] * rq.conjugate(); };
    std::array<Eigen::Quaterniond, kJointCount> g;
    // Aims joint j's bone (bind direction to `child`) along `target`, keeping
    // the source's twist.
    auto aim = [&](int j, const Eigen::Vector3d& bind_dir, const Eigen::Vector3d& target) {
      const Eigen::Quaterniond twist = d(j);
      const Eigen::Vector3d predicted = twist * bind_dir.normalized();
      if (target.norm() < 1e-9) return twist;
      return Eigen::Quaterniond::FromTwoVectors(predicted, target.normalized()) * twist;
    };
    // The source's rotation of j relative to `parent_src`, on top of our parent.
    auto relative = [&](int j, int parent_src, int parent) {
      return g[parent] * (d(parent_src).conjugate() * d(j));
    };
    g[kPelvis] = Eigen::Quaterniond(FrameFrom(p(kRightHip) - p(kLeftHip), p(kChest) - p(kPelvis)));
    g[kSpine] = aim(kSpine, bind[kChest] - bind[kSpine], p(kChest) - p(kSpine));
    g[kChest] = Eigen::Quaterniond(FrameFrom(p(kRightShoulder) - p(kLeftShoulder), p(kNeck) - p(kChest)));
    g[kNeck] = aim(kNeck, bind[kHead] - bind[kNeck], p(kHead) - p(kNeck));
    if (head_top >= 0) {
      g[kHead] = aim(kHead, Eigen::Vector3d::UnitZ(), r * frame.position[head_top] - p(kHead));
    } else {
      g[kHead] = relative(kHead, kNeck, kNeck);
    }
    for (int side : {0, 1}) {
      const int clav = side == 0 ? kRightClavicle : kLeftClavicle;
      g[clav] = src[clav] >= 0 ? relative(clav, kChest, kChest) : g[kChest];
      g[clav + 1] = aim(clav + 1, bind[clav + 2] - bind[clav + 1], p(clav + 2) - p(clav + 1));
      g[clav + 2] = aim(clav + 2, bind[clav + 3] - bind[clav + 2], p(clav + 3) - p(clav + 2));
      g[clav + 3] = relative(clav + 3, clav + 2, clav + 2);
      const int hip = side == 0 ? kRightHip : kLeftHip;
      g[hip] = aim(hip, bind[hip + 1] - bind[hip], p(hip + 1) - p(hip));
      g[hip + 1] = aim(hip + 1, bind[hip + 2] - bind[hip + 1], p(hip + 2) - p(hip + 1));
      g[hip + 2] = relative(hip + 2, hip + 1, hip + 1);
    }
    Pose& pose = poses[f];
    for (int j = 0; j < kJointCount; ++j) {
      const int parent = JointParent(j);
      pose.local_rotation[j] = (parent < 0 ? g[j] : g[parent].conjugate() * g[j]).normalized();
    }
    pose.root_offset = scale * p(kPelvis) - bind[kPelvis];
  }
  // Place frame 0 over `place_at`; put the lowest ankle of the clip at the
  // bind pose's ankle height.
  Eigen::Vector3d shift(options.place_at.x() - (poses[0].root_offset.x() + bind[kPelvis].x()),
                        options.place_at.y() - (poses[0].root_offset.y() + bind[kPelvis].y()), 0);
  double lowest = std::numeric_limits<double>::infinity();
  for (const Pose& pose : poses) {
    const JointTransforms fk = ForwardKinematics(skeleton, pose);
    lowest = std::min({lowest, fk[kRightAnkle].translation().z(), fk[kLeftAnkle].translation().z()});
  }
  shift.z() = bind[kRightAnkle].z() - lowest;
  for (Pose& pose : poses) pose.root_offset += shift;
  auto motion = std::make_shared<RetargetedMotion>(clip.name, clip.frame_time, std::move(poses));
  motion->world_from_source = r;
  motion->scale = scale;
  motion->translation = shift;
  motion->source_joint = src;
  return motion;
}

}  // namespace irbench
