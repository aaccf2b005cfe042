#include "sim/motion/bvh.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <unordered_map>

#include "common/error.h"
#include "sim/body/avatar.h"

namespace irbench {
namespace {

struct Token {
  std::string text;
  int line = 0;
};

// Splits the text into whitespace-separated tokens (spaces, tabs, CR), each
// with its 1-based line number.
std::vector<Token> Tokenize(const std::string& text) {
  std::vector<Token> tokens;
  int line = 1;
  size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++i;
    } else {
      size_t j = i;
      while (j < text.size() && !std::isspace(static_cast<unsigned char>(text[j]))) ++j;
      tokens.push_back({text.substr(i, j - i), line});
      i = j;
    }
  }
  return tokens;
}

class Parser {
 public:
  Parser(const std::string& text, std::string file) : tokens_(Tokenize(text)), file_(std::move(file)) {}

  BvhFile Parse() {
    BvhFile bvh;
    Expect("HIERARCHY");
    const Token root = Next("ROOT");
    if (root.text != "ROOT") Fail(root.line, "expected ROOT, got '" + root.text + "'");
    ParseJoint(bvh, -1, 1);
    const Token motion = Next("MOTION");
    if (motion.text != "MOTION") {
      Fail(motion.line, "expected MOTION after the hierarchy, got '" + motion.text + "'");
    }
    const Token frames_key = Next("Frames:");
    if (frames_key.text != "Frames:") Fail(frames_key.line, "expected 'Frames:'");
    const Token count = Next("a frame count");
    const double n = Number(count);
    if (n < 0 || n != std::floor(n) || n > 1e8) Fail(count.line, "bad frame count '" + count.text + "'");
    const Token frame_key = Next("Frame Time:");
    const Token time_key = Next("Frame Time:");
    if (frame_key.text != "Frame" || time_key.text != "Time:") Fail(frame_key.line, "expected 'Frame Time:'");
    const Token time = Next("a frame time");
    bvh.frame_time = Number(time);
    if (!(bvh.frame_time >= kMinBvhFrameTime && bvh.frame_time <= kMaxBvhFrameTime)) {
      Fail(time.line, "frame time must be in [" + Str(kMinBvhFrameTime) + ", " +
                          Str(kMaxBvhFrameTime) + "] s, got '" + time.text + "'");
    }
    const std::vector<BvhChannel> kinds = ChannelKinds(bvh);
    // Frame lines: each must hold exactly channel_count values. The count
    // claimed by 'Frames:' reserves no more than the file can hold.
    const size_t frames = static_cast<size_t>(n);
    bvh.frames.reserve(std::min(frames, tokens_.size() - pos_));
    while (pos_ < tokens_.size()) {
      const int line = tokens_[pos_].line;
      std::vector<double> values;
      values.reserve(bvh.channel_count);
      while (pos_ < tokens_.size() && tokens_[pos_].line == line) {
        const Token& t = tokens_[pos_++];
        const double v = Number(t);
        if (values.size() < kinds.size()) CheckChannelValue(t, kinds[values.size()], v);
        values.push_back(v);
      }
      if (static_cast<int>(values.size()) != bvh.channel_count) {
        Fail(line, "frame " + std::to_string(bvh.frames.size()) + " has " + std::to_string(values.size()) +
                       " values; the hierarchy has " + std::to_string(bvh.channel_count) + " channels");
      }
      if (bvh.frames.size() == frames) {
        Fail(line, "more frame lines than 'Frames: " + std::to_string(frames) + "'");
      }
      bvh.frames.push_back(std::move(values));
    }
    if (bvh.frames.size() != frames) {
      Fail(tokens_.empty() ? 1 : tokens_.back().line,
           "the file ends after " + std::to_string(bvh.frames.size()) + " of " + std::to_string(frames) +
               " frames");
    }
    return bvh;
  }

 private:
  // Joint at nesting level `depth` (the root is 1); recursion is bounded by
  // kMaxBvhDepth.
  void ParseJoint(BvhFile& bvh, int parent, int depth) {
    const Token name = Next("a joint name");
    if (depth > kMaxBvhDepth) {
      Fail(name.line, "joint '" + name.text + "' is nested deeper than " +
                          std::to_string(kMaxBvhDepth) + " levels");
    }
    BvhJoint joint;
    joint.name = name.text;
    joint.parent = parent;
    AddName(name.text, name.line);
    Expect("{");
    Expect("OFFSET");
    ReadOffset(joint.offset);
    const Token channels = Next("CHANNELS");
    if (channels.text != "CHANNELS") {
      Fail(channels.line, "joint '" + joint.name + "' has no CHANNELS line (got '" + channels.text + "')");
    }
    const Token count = Next("a channel count");
    const double n = Number(count);
    if (n < 0 || n > 6 || n != std::floor(n)) Fail(count.line, "channel count must be 0..6");
    bool seen[6] = {false, false, false, false, false, false};
    for (int k = 0; k < static_cast<int>(n); ++k) {
      const Token c = Next("a channel name");
      static const char* kNames[6] = {"Xposition", "Yposition", "Zposition",
                                      "Xrotation", "Yrotation", "Zrotation"};
      int which = -1;
      for (int m = 0; m < 6; ++m) {
        if (c.text == kNames[m]) which = m;
      }
      if (which < 0) {
        Fail(c.line, "unknown channel '" + c.text + "' (rotation order must use Xrotation, Yrotation, "
                     "Zrotation; positions Xposition, Yposition, Zposition)");
      }
      if (seen[which]) Fail(c.line, "channel '" + c.text + "' repeated: not a valid rotation order");
      seen[which] = true;
      joint.channels.push_back(static_cast<BvhChannel>(which));
    }
    joint.first_channel = bvh.channel_count;
    bvh.channel_count += static_cast<int>(n);
    const int index = static_cast<int>(bvh.joints.size());
    bvh.joints.push_back(joint);
    while (true) {
      const Token t = Next("'}'");
      if (t.text == "}") break;
      if (t.text == "JOINT") {
        ParseJoint(bvh, index, depth + 1);
      } else if (t.text == "End") {
        const Token site = Next("Site");
        if (site.text != "Site") Fail(site.line, "expected 'End Site'");
        BvhJoint end;
        end.name = joint.name + "_end";
        end.parent = index;
        end.end_site = true;
        end.first_channel = bvh.channel_count;
        AddName(end.name, site.line);
        Expect("{");
        Expect("OFFSET");
        ReadOffset(end.offset);
        Expect("}");
        bvh.joints.push_back(end);
      } else {
        Fail(t.line, "expected JOINT, End Site or '}' in joint '" + joint.name + "', got '" + t.text + "'");
      }
    }
  }

  Token Next(const std::string& what) {
    if (pos_ >= tokens_.size()) {
      Fail(tokens_.empty() ? 1 : tokens_.back().line, "the file ends where " + what + " was expected");
    }
    return tokens_[pos_++];
  }
  void Expect(const std::string& text) {
    const Token t = Next("'" + text + "'");
    if (t.text != text) Fail(t.line, "expected '" + text + "', got '" + t.text + "'");
  }
  double Number(const Token& t) {
    char* end = nullptr;
    const double v = std::strtod(t.text.c_str(), &end);
    if (end == t.text.c_str() || *end != '\0') Fail(t.line, "'" + t.text + "' is not a number");
    if (!std::isfinite(v)) Fail(t.line, "value '" + t.text + "' is not finite");
    return v;
  }
  [[noreturn]] void Fail(int line, const std::string& message) const {
    throw InputError(file_, "line " + std::to_string(line), message);
  }
  static std::string Str(double v) {
    std::ostringstream out;
    out << v;
    return out.str();
  }

  // Registers a joint name; a second joint with it is an error (it would make
  // the skeleton ambiguous: a retarget could put a knee above the hip).
  void AddName(const std::string& name, int line) {
    const auto [it, inserted] = name_line_.emplace(name, line);
    if (!inserted) {
      Fail(line, "joint name '" + name + "' is used twice (first at line " +
                     std::to_string(it->second) + ")");
    }
  }
  void ReadOffset(Eigen::Vector3d& offset) {
    for (int k = 0; k < 3; ++k) {
      const Token t = Next("an OFFSET value");
      offset[k] = Number(t);
      if (std::abs(offset[k]) > kMaxBvhPosition) {
        Fail(t.line,
             "OFFSET value '" + t.text + "' is beyond +-" + Str(kMaxBvhPosition) + " (file units)");
      }
    }
  }
  // Each channel's kind, in frame-line order.
  static std::vector<BvhChannel> ChannelKinds(const BvhFile& bvh) {
    std::vector<BvhChannel> kinds;
    kinds.reserve(bvh.channel_count);
    for (const BvhJoint& j : bvh.joints)
      kinds.insert(kinds.end(), j.channels.begin(), j.channels.end());
    return kinds;
  }
  void CheckChannelValue(const Token& t, BvhChannel kind, double v) const {
    if (kind >= BvhChannel::kXrotation) {
      if (std::abs(v) > kMaxBvhRotationDeg) {
        Fail(t.line,
             "rotation '" + t.text + "' is beyond +-" + Str(kMaxBvhRotationDeg) + " degrees");
      }
    } else if (std::abs(v) > kMaxBvhPosition) {
      Fail(t.line,
           "position '" + t.text + "' is beyond +-" + Str(kMaxBvhPosition) + " (file units)");
    }
  }

  std::vector<Token> tokens_;
  size_t pos_ = 0;
  std::string file_;
  std::unordered_map<std::string, int> name_line_;  // joint name -> its line
};

Eigen::Matrix3d AxisRotation(BvhChannel c, double degrees) {
  const double r = degrees * M_PI / 180.0;
  switch (c) {
    case BvhChannel::kXrotation: return Eigen::AngleAxisd(r, Eigen::Vector3d::UnitX()).toRotationMatrix();
    case BvhChannel::kYrotation: return Eigen::AngleAxisd(r, Eigen::Vector3d::UnitY()).toRotationMatrix();
    case BvhChannel::kZrotation: return Eigen::AngleAxisd(r, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    default: return Eigen::Matrix3d::Identity();
  }
}

bool IsRotation(BvhChannel c) { return c >= BvhChannel::kXrotation; }
int AxisOf(BvhChannel c) { return static_cast<int>(c) % 3; }

const char* ChannelName(BvhChannel c) {
  static const char* kNames[6] = {"Xposition", "Yposition", "Zposition",
                                  "Xrotation", "Yrotation", "Zrotation"};
  return kNames[static_cast<int>(c)];
}

}  // namespace

BvhFile ParseBvh(const std::string& text, const std::string& file_name) {
  BvhFile bvh = Parser(text, file_name).Parse();
  bvh.name = std::filesystem::path(file_name).stem().string();
  return bvh;
}

BvhFile LoadBvh(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "file", "cannot open the BVH file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseBvh(buffer.str(), path.string());
}

std::string WriteBvh(const BvhFile& bvh) {
  std::string out = "HIERARCHY\n";
  char buf[128];
  // Children of each joint, in order.
  std::vector<std::vector<int>> children(bvh.joints.size());
  for (size_t j = 0; j < bvh.joints.size(); ++j) {
    if (bvh.joints[j].parent >= 0) children[bvh.joints[j].parent].push_back(static_cast<int>(j));
  }
  std::function<void(int, int)> write = [&](int j, int depth) {
    const BvhJoint& joint = bvh.joints[j];
    const std::string indent(depth, '\t');
    if (joint.end_site) {
      out += indent + "End Site\n";
    } else {
      out += indent + (joint.parent < 0 ? "ROOT " : "JOINT ") + joint.name + "\n";
    }
    out += indent + "{\n";
    std::snprintf(buf, sizeof(buf), "%s\tOFFSET %.6f %.6f %.6f\n", indent.c_str(), joint.offset.x(),
                  joint.offset.y(), joint.offset.z());
    out += buf;
    if (!joint.end_site) {
      out += indent + "\tCHANNELS " + std::to_string(joint.channels.size());
      for (BvhChannel c : joint.channels) out += std::string(" ") + ChannelName(c);
      out += "\n";
    }
    for (int c : children[j]) write(c, depth + 1);
    out += indent + "}\n";
  };
  write(0, 0);
  out += "MOTION\nFrames: " + std::to_string(bvh.frames.size()) + "\n";
  std::snprintf(buf, sizeof(buf), "Frame Time: %.8f\n", bvh.frame_time);
  out += buf;
  for (const auto& frame : bvh.frames) {
    for (size_t k = 0; k < frame.size(); ++k) {
      std::snprintf(buf, sizeof(buf), k == 0 ? "%.6f" : " %.6f", frame[k]);
      out += buf;
    }
    out += "\n";
  }
  return out;
}

MocapClip BvhToClip(const BvhFile& bvh) {
  MocapClip clip;
  clip.name = bvh.name;
  clip.frame_time = bvh.frame_time;
  const size_t n = bvh.joints.size();
  for (const BvhJoint& j : bvh.joints) {
    clip.joint_names.push_back(j.name);
    clip.parent.push_back(j.parent);
  }
  clip.rest_position.resize(n);
  for (size_t j = 0; j < n; ++j) {
    const int p = bvh.joints[j].parent;
    clip.rest_position[j] = (p < 0 ? Eigen::Vector3d::Zero() : clip.rest_position[p]) + bvh.joints[j].offset;
  }
  clip.frames.resize(bvh.frames.size());
  std::vector<Eigen::Matrix3d> world(n);
  for (size_t f = 0; f < bvh.frames.size(); ++f) {
    const std::vector<double>& values = bvh.frames[f];
    MocapClip::Frame& frame = clip.frames[f];
    frame.position.resize(n);
    frame.rotation.resize(n);
    for (size_t j = 0; j < n; ++j) {
      const BvhJoint& joint = bvh.joints[j];
      Eigen::Vector3d translation = joint.offset;
      Eigen::Matrix3d local = Eigen::Matrix3d::Identity();
      for (size_t k = 0; k < joint.channels.size(); ++k) {
        const double v = values[joint.first_channel + k];
        if (IsRotation(joint.channels[k])) {
          local = local * AxisRotation(joint.channels[k], v);
        } else {
          translation[AxisOf(joint.channels[k])] += v;
        }
      }
      if (joint.parent < 0) {
        world[j] = local;
        frame.position[j] = translation;
      } else {
        world[j] = world[joint.parent] * local;
        frame.position[j] = frame.position[joint.parent] + world[joint.parent] * translation;
      }
      frame.rotation[j] = Eigen::Quaterniond(world[j]);
    }
  }
  return clip;
}

Eigen::Vector3d EulerDegrees(const Eigen::Quaterniond& q, const std::vector<BvhChannel>& order) {
  // R = A(a)·B(b)·C(c) for axes (i, j, k) in listed order. Solved generally by
  // mapping to the ZXY case through an axis permutation.
  std::vector<int> axes;
  for (BvhChannel c : order) {
    if (IsRotation(c)) axes.push_back(AxisOf(c));
  }
  if (axes.size() != 3) throw std::invalid_argument("EulerDegrees needs three rotation channels");
  const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
  const int i = axes[0], j = axes[1], k = axes[2];
  // Parity: +1 when (i, j, k) is a cyclic permutation of (0, 1, 2). For
  // R = Ri(a)·Rj(b)·Rk(c): R(i, k) = s·sin b, R(j, k) = -s·sin a·cos b,
  // R(k, k) = cos a·cos b, R(i, j) = -s·cos b·sin c, R(i, i) = cos b·cos c.
  const double s = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;
  const double b = std::asin(std::clamp(s * r(i, k), -1.0, 1.0));
  const double a = std::atan2(-s * r(j, k), r(k, k));
  const double c = std::atan2(-s * r(i, j), r(i, i));
  Eigen::Vector3d out(a, b, c);
  return out * 180.0 / M_PI;
}

Eigen::Matrix3d YUpFromWorld() {
  Eigen::Matrix3d m;
  m << -1, 0, 0, 0, 0, 1, 0, 1, 0;
  return m;
}

BvhFile MotionToBvh(const MotionSource& motion, const Skeleton& skeleton, double fps, int frames) {
  const Eigen::Matrix3d m = YUpFromWorld();
  const auto& bind = skeleton.bind_position;
  const double height = bind[kHead].z() / 0.885;
  BvhFile bvh;
  bvh.name = motion.name();
  bvh.frame_time = 1.0 / fps;
  const std::vector<BvhChannel> rot = {BvhChannel::kZrotation, BvhChannel::kXrotation,
                                       BvhChannel::kYrotation};
  std::vector<int> bvh_index(kJointCount);
  auto add = [&](BvhJoint joint) {
    joint.first_channel = bvh.channel_count;
    bvh.channel_count += static_cast<int>(joint.channels.size());
    bvh.joints.push_back(joint);
    return static_cast<int>(bvh.joints.size()) - 1;
  };
  // Depth-first so every child follows its parent's subtree order.
  std::function<void(int)> visit = [&](int j) {
    BvhJoint joint;
    joint.name = JointName(j);
    joint.parent = j == kPelvis ? -1 : bvh_index[JointParent(j)];
    joint.offset = j == kPelvis ? Eigen::Vector3d::Zero() : Eigen::Vector3d(m * (bind[j] - bind[JointParent(j)]));
    joint.channels = rot;
    if (j == kPelvis) {
      joint.channels = {BvhChannel::kXposition, BvhChannel::kYposition, BvhChannel::kZposition};
      joint.channels.insert(joint.channels.end(), rot.begin(), rot.end());
    }
    bvh_index[j] = add(joint);
    bool leaf = true;
    for (int c = j + 1; c < kJointCount; ++c) {
      if (JointParent(c) == j) {
        leaf = false;
        visit(c);
      }
    }
    if (leaf) {
      BvhJoint end;
      end.name = joint.name + "_end";
      end.parent = bvh_index[j];
      end.end_site = true;
      Eigen::Vector3d tip = Eigen::Vector3d::Zero();
      if (j == kHead) tip = {0, 0, height - bind[kHead].z()};
      if (j == kRightWrist) tip = {0.108 * height, 0, 0};
      if (j == kLeftWrist) tip = {-0.108 * height, 0, 0};
      if (j == kRightAnkle || j == kLeftAnkle) tip = {0, 0.13 * height, -bind[j].z()};
      end.offset = m * tip;
      add(end);
    }
  };
  visit(kPelvis);
  if (frames < 0) frames = static_cast<int>(std::floor(motion.Duration() * fps + 1e-9)) + 1;
  for (int f = 0; f < frames; ++f) {
    const Pose pose = motion.At(f / fps);
    std::vector<double> values;
    values.reserve(bvh.channel_count);
    for (const BvhJoint& joint : bvh.joints) {
      if (joint.end_site) continue;
      const int j = *JointFromName(joint.name);
      if (j == kPelvis) {
        const Eigen::Vector3d p = m * (bind[kPelvis] + pose.root_offset);
        values.insert(values.end(), {p.x(), p.y(), p.z()});
      }
      const Eigen::Quaterniond q(m * pose.local_rotation[j].normalized().toRotationMatrix() * m);
      const Eigen::Vector3d e = EulerDegrees(q, rot);
      values.insert(values.end(), {e.x(), e.y(), e.z()});
    }
    bvh.frames.push_back(std::move(values));
  }
  return bvh;
}

}  // namespace irbench
