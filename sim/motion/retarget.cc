#include "sim/motion/retarget.h"

#include <algorithm>
#include <cmath>

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

// Drops a synthetic first frame (see LoadMocap).
void DropSyntheticFirstFrame(MocapClip& clip) {
  if (clip.frames.size() < 4) return;
  double d01 = 0, d12 = 0;
  for (size_t j = 0; j < clip.joint_names.size(); ++j) {
    d01 = std::max(d01, AngleDeg(clip.frames[0].rotation[j], clip.frames[1].rotation[j]));
    d12 = std::max(d12, AngleDeg(clip.frames[1].rotation[j], clip.frames[2].rotation[j]));
  }
  if (d01 > 10.0 && d01 > 5.0 * d12) {
    Log().info("motion: {}: frame 0 jumps {:.0f}° to frame 1 (then {:.1f}°): a synthetic first "
               "frame, dropped", clip.name, d01, d12);
    clip.frames.erase(clip.frames.begin());
  }
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
  DropSyntheticFirstFrame(clip);
  return clip;
}

Eigen::Matrix3d WorldFromSource(const MocapClip& clip, const Map& map) {
  auto rest = [&](const char* key) { return clip.rest_position[FindMapped(clip, map.at(key))]; };
  const Eigen::Vector3d up = (rest("head") - rest("pelvis")).normalized();
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
  const Eigen::Matrix3d r = heading * WorldFromSource(clip, map);
  const Eigen::Quaterniond rq(r);
  const auto& bind = skeleton.bind_position;
  auto src_len = [&](int a, int b) { return (clip.rest_position[src[a]] - clip.rest_position[src[b]]).norm(); };
  const double src_leg = src_len(kRightHip, kRightKnee) + src_len(kRightKnee, kRightAnkle) +
                         src_len(kLeftHip, kLeftKnee) + src_len(kLeftKnee, kLeftAnkle);
  const double our_leg = (bind[kRightHip] - bind[kRightKnee]).norm() +
                         (bind[kRightKnee] - bind[kRightAnkle]).norm() +
                         (bind[kLeftHip] - bind[kLeftKnee]).norm() + (bind[kLeftKnee] - bind[kLeftAnkle]).norm();
  if (!(src_leg > 0)) throw InputError(file, "joints", "the legs have zero length in the rest pose");
  const double scale = our_leg / src_leg;

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
