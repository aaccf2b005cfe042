#include "sim/motion/asf_amc.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/error.h"
#include "common/text.h"

// Conventions, checked against:
// - CMU mocapPlayer (the "amc viewer", http://mocap.cs.cmu.edu/tools.php):
//   skeleton.cpp builds every bone's axis matrix as Rz(az)·Ry(ay)·Rx(ax) and
//   rot_parent_current = C_parent⁻¹·C_child; displaySkeleton.cpp DrawBone
//   applies rot_parent_current, then the AMC translations, then the AMC
//   rotations (glRotatef z, y, x: x applied first), then translates by
//   dir·length. Its world rotation of bone b's local frame is
//   W_parent·C_b·M_b, so in world axes the bone turns by W_b = W_parent·C_b·M_b·C_b⁻¹.
// - amc2bvh (amc2bvh.c: write_bvh_joint_sample, euler_to_quat): the same
//   local·motion·local⁻¹ with the Euler factors composed in the listed order
//   (q = q3·q2·q1), the root `order` and per-bone `dof` orders honoured, the
//   child OFFSET = direction·length (a joint sits at its bone's start).
// - CalciferZh/AMCParser amc_parser.py (Joint.set_motion): matrix =
//   parent.matrix·C·euler2mat(rx, ry, rz)·Cinv, coordinate = parent +
//   length·matrix·direction, with transforms3d's static-xyz euler2mat =
//   Rz·Ry·Rx.
// - CMU FAQ (http://mocap.cs.cmu.edu/faqs.php): metres = units·(1/0.45)·0.0254
//   for `:units length 0.45`.
// For CMU files (dof always a subset of "rx ry rz" in that order, axis order
// always XYZ, root order TX TY TZ RX RY RZ) all three agree. Where they differ
// for other files, this reader follows amc2bvh: the listed order of `dof` and
// `:root order` is the application order (the CMU viewer always applies x,
// then y, then z). The `axis` line's three numbers are the x, y and z angles
// and its letters their application order.

namespace irbench {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

enum class Dof { kTx, kTy, kTz, kRx, kRy, kRz, kL };

bool IsRotation(Dof d) {
  return d == Dof::kRx || d == Dof::kRy || d == Dof::kRz;
}
bool IsTranslation(Dof d) {
  return d == Dof::kTx || d == Dof::kTy || d == Dof::kTz;
}
int AxisOf(Dof d) {
  return static_cast<int>(d) % 3;
}

// Rotation by `radians` about world axis 0 (x), 1 (y) or 2 (z).
Matrix3d AxisRotation(int axis, double radians) {
  return Eigen::AngleAxisd(radians, Vector3d::Unit(axis)).toRotationMatrix();
}

struct Line {
  int number = 0;  // 1-based
  std::vector<std::string> tokens;
};

// Splits text into lines of whitespace-separated tokens, dropping `#`
// comments, a UTF-8 byte-order mark, CRs and blank lines. `line_count` gets
// the number of the file's last line.
std::vector<Line> SplitLines(const std::string& text, int* line_count) {
  std::vector<Line> lines;
  size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  int number = 0;
  while (start < text.size()) {
    ++number;
    size_t stop = text.find('\n', start);
    if (stop == std::string::npos) stop = text.size();
    std::string_view content(text.data() + start, stop - start);
    const size_t hash = content.find('#');
    if (hash != std::string_view::npos) content = content.substr(0, hash);
    Line line;
    line.number = number;
    size_t i = 0;
    while (i < content.size()) {
      if (std::isspace(static_cast<unsigned char>(content[i]))) {
        ++i;
        continue;
      }
      size_t j = i;
      while (j < content.size() && !std::isspace(static_cast<unsigned char>(content[j]))) ++j;
      line.tokens.emplace_back(content.substr(i, j - i));
      i = j;
    }
    if (!line.tokens.empty()) lines.push_back(std::move(line));
    start = stop + 1;
  }
  *line_count = std::max(number, 1);
  return lines;
}

// A number in C syntax ("-1.5", "2e-3", "+4"), independent of the locale.
std::optional<double> ToDouble(std::string_view s) {
  if (s.size() > 1 && s[0] == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
  double value = 0;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (error != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

// Reads files and reports errors with the file's name and the line.
class LineReader {
 public:
  explicit LineReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(int line, const std::string& message) const {
    throw InputError(file_, "line " + std::to_string(line), message);
  }
  // A finite number, or an error naming `what`.
  double Number(const Line& line, size_t k, const std::string& what) const {
    if (k >= line.tokens.size()) Fail(line.number, what + " is missing");
    const std::string& token = line.tokens[k];
    const std::optional<double> value = ToDouble(token);
    if (!value) Fail(line.number, what + " '" + token + "' is not a number");
    if (!std::isfinite(*value)) Fail(line.number, what + " '" + token + "' is not finite");
    return *value;
  }
  // A finite number with |value| <= `limit` (`unit` names it in the message).
  double Bounded(const Line& line,
                 size_t k,
                 const std::string& what,
                 double limit,
                 const std::string& unit) const {
    const double value = Number(line, k, what);
    if (std::abs(value) > limit) {
      std::ostringstream text;
      text << what << " '" << line.tokens[k] << "' is beyond +-" << limit << " " << unit;
      Fail(line.number, text.str());
    }
    return value;
  }
  double Length(const Line& line, size_t k, const std::string& what) const {
    return Bounded(line, k, what, kMaxAsfAmcLength, "file units");
  }
  double Angle(const Line& line, size_t k, const std::string& what) const {
    return Bounded(line, k, what, kMaxAsfAmcAngleDeg, "(angle unit)");
  }
  // Exactly `count` values after the keyword.
  void ExpectValues(const Line& line, size_t count) const {
    if (line.tokens.size() != count + 1) {
      Fail(line.number, "'" + line.tokens[0] + "' takes " + std::to_string(count) + " value" +
                            (count == 1 ? "" : "s") + ", got " +
                            std::to_string(line.tokens.size() - 1));
    }
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

struct AsfBone {
  std::string name;
  int line = 0;                           // its `begin` line (0 for the root)
  Vector3d direction = Vector3d::Zero();  // unit, world rest axes
  double length = 0;
  Matrix3d axis = Matrix3d::Identity();  // C: the bone's local axes in world axes
  std::vector<Dof> dofs;
  int parent = -1;
  std::vector<int> children;
};

struct AsfSkeleton {
  std::vector<AsfBone> bones;  // [0] is the root
  Vector3d root_position = Vector3d::Zero();
  double length_unit = 0;  // `:units length`; 0 when absent
  std::unordered_map<std::string, int> index;
};

// An axis line's angles and order, kept raw until `:units angle` is known.
struct RawAxis {
  Vector3d angles = Vector3d::Zero();
  std::vector<int> order = {0, 1, 2};
};

// C = the three axis rotations, the first letter's applied first.
Matrix3d ComposeAxis(const RawAxis& axis, double to_radians) {
  Matrix3d c = Matrix3d::Identity();
  for (int a : axis.order) c = AxisRotation(a, axis.angles[a] * to_radians) * c;
  return c;
}

class AsfParser : public LineReader {
 public:
  AsfParser(const std::string& text, std::string file)
      : LineReader(std::move(file)), lines_(SplitLines(text, &line_count_)) {}

  AsfSkeleton Parse() {
    AsfBone root;
    root.name = "root";
    root.dofs = {Dof::kTx, Dof::kTy, Dof::kTz, Dof::kRx, Dof::kRy, Dof::kRz};
    skeleton_.bones.push_back(root);
    skeleton_.index["root"] = 0;
    raw_axes_.emplace_back();
    for (const Line& line : lines_) {
      if (line.tokens[0][0] == ':') {
        if (bone_open_) {
          Fail(line.number, "the bone block begun at line " + std::to_string(bone_.line) +
                                " has no 'end' before " + line.tokens[0]);
        }
        if (hierarchy_ == Hierarchy::kOpen) {
          Fail(line.number, ":hierarchy has no 'end' before " + line.tokens[0]);
        }
        StartSection(line);
        continue;
      }
      switch (section_) {
        case Section::kNone:
          Fail(line.number, "'" + line.tokens[0] + "' is outside any section");
        case Section::kIgnored:
          break;
        case Section::kUnits:
          UnitsLine(line);
          break;
        case Section::kRoot:
          RootLine(line);
          break;
        case Section::kBoneData:
          BoneLine(line);
          break;
        case Section::kHierarchy:
          HierarchyLine(line);
          break;
      }
    }
    return Finish();
  }

 private:
  enum class Section { kNone, kIgnored, kUnits, kRoot, kBoneData, kHierarchy };
  enum class Hierarchy { kAbsent, kExpectBegin, kOpen, kDone };

  void StartSection(const Line& line) {
    const std::string& key = line.tokens[0];
    section_ = Section::kNone;
    if (key == ":version" || key == ":name") {
      section_ = Section::kNone;  // the value is on the same line
    } else if (key == ":documentation" || key == ":skin") {
      section_ = Section::kIgnored;
    } else if (key == ":units") {
      section_ = Section::kUnits;
    } else if (key == ":root") {
      section_ = Section::kRoot;
    } else if (key == ":bonedata") {
      if (seen_bonedata_) Fail(line.number, "a second :bonedata section");
      seen_bonedata_ = true;
      section_ = Section::kBoneData;
    } else if (key == ":hierarchy") {
      if (hierarchy_ != Hierarchy::kAbsent) Fail(line.number, "a second :hierarchy section");
      hierarchy_ = Hierarchy::kExpectBegin;
      section_ = Section::kHierarchy;
    } else {
      Fail(line.number, "unknown ASF section '" + key + "'");
    }
    if (section_ != Section::kNone && section_ != Section::kIgnored && line.tokens.size() > 1) {
      Fail(line.number, "unexpected '" + line.tokens[1] + "' after " + key);
    }
  }

  void UnitsLine(const Line& line) {
    const std::string& key = line.tokens[0];
    if (key == "mass") {
      ExpectValues(line, 1);
      Number(line, 1, "mass");
    } else if (key == "length") {
      ExpectValues(line, 1);
      const double length = Number(line, 1, "length");
      if (!(length >= kMinAsfLengthUnit && length <= kMaxAsfLengthUnit)) {
        std::ostringstream text;
        text << "length unit must be in [" << kMinAsfLengthUnit << ", " << kMaxAsfLengthUnit
             << "], got '" << line.tokens[1] << "'";
        Fail(line.number, text.str());
      }
      skeleton_.length_unit = length;
    } else if (key == "angle") {
      ExpectValues(line, 1);
      const std::string unit = AsciiLower(line.tokens[1]);
      if (unit == "deg" || unit == "degrees") {
        to_radians_ = std::numbers::pi / 180.0;
      } else if (unit == "rad" || unit == "radians") {
        to_radians_ = 1.0;
      } else {
        Fail(line.number, "angle unit must be 'deg' or 'rad', got '" + line.tokens[1] + "'");
      }
    } else {
      Fail(line.number, "unknown unit '" + key + "' (expected mass, length or angle)");
    }
  }

  void RootLine(const Line& line) {
    const std::string& key = line.tokens[0];
    if (key == "order") {
      std::vector<Dof> dofs;
      for (size_t k = 1; k < line.tokens.size(); ++k) {
        const std::optional<Dof> d = ParseDof(line.tokens[k]);
        if (!d || *d == Dof::kL) {
          Fail(line.number,
               "unknown root channel '" + line.tokens[k] + "' (expected TX TY TZ RX RY RZ)");
        }
        if (std::find(dofs.begin(), dofs.end(), *d) != dofs.end()) {
          Fail(line.number, "root channel '" + line.tokens[k] + "' repeated");
        }
        dofs.push_back(*d);
      }
      skeleton_.bones[0].dofs = dofs;
    } else if (key == "axis") {
      ExpectValues(line, 1);
      raw_axes_[0].order = AxisOrder(line, 1);
    } else if (key == "position") {
      ExpectValues(line, 3);
      for (int k = 0; k < 3; ++k) skeleton_.root_position[k] = Length(line, k + 1, "position");
    } else if (key == "orientation") {
      ExpectValues(line, 3);
      for (int k = 0; k < 3; ++k) raw_axes_[0].angles[k] = Angle(line, k + 1, "orientation");
    } else {
      Fail(line.number,
           "unknown :root entry '" + key + "' (expected order, axis, position or orientation)");
    }
  }

  void BoneLine(const Line& line) {
    const std::string& key = line.tokens[0];
    if (!bone_open_) {
      if (key != "begin" || line.tokens.size() != 1) {
        Fail(line.number, "expected 'begin' of a bone, got '" + key + "'");
      }
      bone_open_ = true;
      bone_ = AsfBone();
      bone_.line = line.number;
      bone_axis_ = RawAxis();
      has_direction_ = has_length_ = in_limits_ = false;
      name_line_ = limits_line_ = limit_pairs_ = 0;
      return;
    }
    if (key[0] == '(') {
      if (!in_limits_) Fail(line.number, "a limit '" + key + "' outside a 'limits' entry");
      limit_pairs_ += LimitPairs(line, 0);
      return;
    }
    in_limits_ = false;
    if (key == "end") {
      if (line.tokens.size() != 1) Fail(line.number, "unexpected '" + line.tokens[1] + "'");
      EndBone();
    } else if (key == "id") {
      ExpectValues(line, 1);
    } else if (key == "name") {
      ExpectValues(line, 1);
      bone_.name = line.tokens[1];
      name_line_ = line.number;
    } else if (key == "direction") {
      ExpectValues(line, 3);
      for (int k = 0; k < 3; ++k) bone_.direction[k] = Length(line, k + 1, "direction");
      has_direction_ = true;
      direction_line_ = line.number;
    } else if (key == "length") {
      ExpectValues(line, 1);
      bone_.length = Length(line, 1, "length");
      if (bone_.length < 0) Fail(line.number, "bone length must not be negative");
      has_length_ = true;
    } else if (key == "axis") {
      ExpectValues(line, 4);
      for (int k = 0; k < 3; ++k) bone_axis_.angles[k] = Angle(line, k + 1, "axis angle");
      bone_axis_.order = AxisOrder(line, 4);
    } else if (key == "dof") {
      bone_.dofs.clear();
      for (size_t k = 1; k < line.tokens.size(); ++k) {
        const std::optional<Dof> d = ParseDof(line.tokens[k]);
        if (!d) {
          Fail(line.number, "unknown dof '" + line.tokens[k] + "' (expected rx ry rz tx ty tz l)");
        }
        if (std::find(bone_.dofs.begin(), bone_.dofs.end(), *d) != bone_.dofs.end()) {
          Fail(line.number, "dof '" + line.tokens[k] + "' repeated");
        }
        bone_.dofs.push_back(*d);
      }
    } else if (key == "limits") {
      in_limits_ = true;
      limits_line_ = line.number;
      limit_pairs_ = LimitPairs(line, 1);
    } else if (key == "bodymass" || key == "cofmass") {
      ExpectValues(line, 1);
    } else {
      Fail(line.number, "unknown bone entry '" + key + "'");
    }
  }

  void EndBone() {
    bone_open_ = false;
    if (bone_.name.empty()) Fail(bone_.line, "bone has no name");
    if (!has_direction_) Fail(bone_.line, "bone '" + bone_.name + "' has no direction");
    if (!has_length_) Fail(bone_.line, "bone '" + bone_.name + "' has no length");
    if (skeleton_.index.count(bone_.name)) {
      Fail(name_line_, "bone name '" + bone_.name + "' used twice");
    }
    const double norm = bone_.direction.norm();
    if (norm > 0) {
      bone_.direction /= norm;
    } else if (bone_.length > 0) {
      Fail(direction_line_, "bone '" + bone_.name + "' has a zero direction");
    }
    if (limits_line_ > 0 && limit_pairs_ != static_cast<int>(bone_.dofs.size())) {
      Fail(limits_line_, "bone '" + bone_.name + "' has " + std::to_string(limit_pairs_) +
                             " limits for " + std::to_string(bone_.dofs.size()) + " dofs");
    }
    skeleton_.index[bone_.name] = static_cast<int>(skeleton_.bones.size());
    skeleton_.bones.push_back(bone_);
    raw_axes_.push_back(bone_axis_);
  }

  void HierarchyLine(const Line& line) {
    const std::string& key = line.tokens[0];
    switch (hierarchy_) {
      case Hierarchy::kExpectBegin:
        if (key != "begin" || line.tokens.size() != 1) {
          Fail(line.number, "expected 'begin' of the hierarchy, got '" + key + "'");
        }
        hierarchy_ = Hierarchy::kOpen;
        return;
      case Hierarchy::kDone:
        Fail(line.number, "'" + key + "' after the hierarchy's 'end'");
      case Hierarchy::kAbsent:
      case Hierarchy::kOpen:
        break;
    }
    if (key == "end" && line.tokens.size() == 1) {
      hierarchy_ = Hierarchy::kDone;
      return;
    }
    const int parent = BoneIndex(line, key);
    for (size_t k = 1; k < line.tokens.size(); ++k) {
      const int child = BoneIndex(line, line.tokens[k]);
      if (child == 0) Fail(line.number, "root cannot be a child");
      if (skeleton_.bones[child].parent >= 0) {
        Fail(line.number, "bone '" + line.tokens[k] + "' already has parent '" +
                              skeleton_.bones[skeleton_.bones[child].parent].name + "'");
      }
      if (child == parent) Fail(line.number, "bone '" + key + "' is its own child");
      skeleton_.bones[child].parent = parent;
      skeleton_.bones[parent].children.push_back(child);
    }
  }

  int BoneIndex(const Line& line, const std::string& name) const {
    const auto it = skeleton_.index.find(name);
    if (it == skeleton_.index.end()) {
      Fail(line.number, "bone '" + name + "' in :hierarchy is not defined in :bonedata");
    }
    return it->second;
  }

  AsfSkeleton Finish() {
    if (bone_open_) {
      Fail(line_count_,
           "the file ends inside the bone block begun at line " + std::to_string(bone_.line));
    }
    if (!seen_bonedata_) Fail(line_count_, "the file has no :bonedata section");
    if (hierarchy_ == Hierarchy::kAbsent) Fail(line_count_, "the file has no :hierarchy section");
    if (hierarchy_ != Hierarchy::kDone) Fail(line_count_, "the file ends inside :hierarchy");
    // Every bone must hang from the root (this also rules out cycles).
    std::vector<bool> reached(skeleton_.bones.size(), false);
    std::vector<int> stack = {0};
    while (!stack.empty()) {
      const int b = stack.back();
      stack.pop_back();
      reached[b] = true;
      for (int c : skeleton_.bones[b].children) stack.push_back(c);
    }
    for (size_t b = 1; b < skeleton_.bones.size(); ++b) {
      if (!reached[b]) {
        Fail(skeleton_.bones[b].line,
             "bone '" + skeleton_.bones[b].name + "' is not connected to root in :hierarchy");
      }
    }
    for (size_t b = 0; b < skeleton_.bones.size(); ++b) {
      skeleton_.bones[b].axis = ComposeAxis(raw_axes_[b], to_radians_);
    }
    return std::move(skeleton_);
  }

  static std::optional<Dof> ParseDof(const std::string& token) {
    static const std::pair<const char*, Dof> kNames[] = {
        {"tx", Dof::kTx}, {"ty", Dof::kTy}, {"tz", Dof::kTz}, {"rx", Dof::kRx},
        {"ry", Dof::kRy}, {"rz", Dof::kRz}, {"l", Dof::kL}};
    const std::string lower = AsciiLower(token);
    for (const auto& [name, dof] : kNames) {
      if (lower == name) return dof;
    }
    return std::nullopt;
  }

  // An axis order such as "XYZ": each of X, Y, Z once, the first applied first.
  std::vector<int> AxisOrder(const Line& line, size_t k) const {
    const std::string& token = line.tokens[k];
    std::vector<int> order;
    for (char c : token) {
      const char upper = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      if (upper < 'X' || upper > 'Z') {
        Fail(line.number, "unknown axis order letter '" + std::string(1, c) + "' in '" + token +
                              "' (expected X, Y, Z)");
      }
      const int axis = upper - 'X';
      if (std::find(order.begin(), order.end(), axis) != order.end()) {
        Fail(line.number, "axis order '" + token + "' repeats '" + std::string(1, c) + "'");
      }
      order.push_back(axis);
    }
    if (order.size() != 3) Fail(line.number, "axis order '" + token + "' must name X, Y and Z");
    return order;
  }

  // Counts "(lo hi)" pairs in the tokens from k on; infinite bounds allowed.
  int LimitPairs(const Line& line, size_t k) const {
    std::string text;
    for (size_t i = k; i < line.tokens.size(); ++i) text += line.tokens[i] + " ";
    int pairs = 0;
    size_t i = 0;
    while (true) {
      while (i < text.size() && text[i] == ' ') ++i;
      if (i == text.size()) break;
      if (text[i] != '(') Fail(line.number, "expected '(' in limits, got '" + text.substr(i) + "'");
      const size_t close = text.find(')', i);
      if (close == std::string::npos) Fail(line.number, "limits: '(' without ')'");
      std::istringstream inner(text.substr(i + 1, close - i - 1));
      std::vector<std::string> bounds;
      for (std::string b; inner >> b;) bounds.push_back(b);
      if (bounds.size() != 2) Fail(line.number, "a limit must be '(lo hi)'");
      double values[2];
      for (int m = 0; m < 2; ++m) {
        const std::optional<double> v = ToDouble(bounds[m]);
        if (!v || std::isnan(*v)) Fail(line.number, "limit '" + bounds[m] + "' is not a number");
        values[m] = *v;
      }
      if (values[0] > values[1]) Fail(line.number, "limit lower bound exceeds upper bound");
      ++pairs;
      i = close + 1;
    }
    return pairs;
  }

  int line_count_ = 1;
  std::vector<Line> lines_;
  AsfSkeleton skeleton_;
  std::vector<RawAxis> raw_axes_;  // per bone, [0] the root's orientation
  double to_radians_ = std::numbers::pi / 180.0;
  Section section_ = Section::kNone;
  bool seen_bonedata_ = false;
  Hierarchy hierarchy_ = Hierarchy::kAbsent;
  // The bone block being read.
  bool bone_open_ = false;
  AsfBone bone_;
  RawAxis bone_axis_;
  bool has_direction_ = false;
  bool has_length_ = false;
  bool in_limits_ = false;
  int name_line_ = 0;
  int direction_line_ = 0;
  int limits_line_ = 0;
  int limit_pairs_ = 0;
};

// Per frame, per bone: the AMC values in `dofs` order, rotations in radians.
using AmcFrames = std::vector<std::vector<std::vector<double>>>;

class AmcParser : public LineReader {
 public:
  AmcParser(const std::string& text,
            std::string file,
            const AsfSkeleton& skeleton,
            std::string asf_name)
      : LineReader(std::move(file)),
        lines_(SplitLines(text, &line_count_)),
        skeleton_(skeleton),
        asf_name_(std::move(asf_name)) {}

  AmcFrames Parse() {
    AmcFrames frames;
    double to_radians = std::numbers::pi / 180.0;
    long long last_number = 0;
    std::vector<int> listed_at;  // line where each bone was listed in this frame
    for (const Line& line : lines_) {
      const std::string& key = line.tokens[0];
      if (key[0] == ':') {
        if (!frames.empty()) Fail(line.number, "'" + key + "' after the first frame");
        if (line.tokens.size() != 1) Fail(line.number, "unexpected '" + line.tokens[1] + "'");
        if (key == ":DEGREES") {
          to_radians = std::numbers::pi / 180.0;
        } else if (key == ":RADIANS") {
          to_radians = 1.0;
        } else if (key != ":FULLY-SPECIFIED") {
          Fail(line.number, "unknown AMC keyword '" + key +
                                "' (expected :FULLY-SPECIFIED, :DEGREES or :RADIANS)");
        }
        continue;
      }
      if (std::all_of(key.begin(), key.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        if (line.tokens.size() != 1) {
          Fail(line.number,
               "a frame number line holds only the number, got '" + line.tokens[1] + "' after it");
        }
        if (key.size() > 12) Fail(line.number, "frame number '" + key + "' is too large");
        const long long number = std::stoll(key);
        if (!frames.empty() && number != last_number + 1) {
          Fail(line.number,
               "frame " + key + " does not follow frame " + std::to_string(last_number));
        }
        last_number = number;
        frames.emplace_back(skeleton_.bones.size());
        for (size_t b = 0; b < skeleton_.bones.size(); ++b) {
          frames.back()[b].assign(skeleton_.bones[b].dofs.size(), 0.0);
        }
        listed_at.assign(skeleton_.bones.size(), 0);
        continue;
      }
      if (frames.empty()) Fail(line.number, "expected a frame number, got '" + key + "'");
      const auto it = skeleton_.index.find(key);
      if (it == skeleton_.index.end()) {
        Fail(line.number, "bone '" + key + "' is not in " + asf_name_);
      }
      const int b = it->second;
      if (listed_at[b] > 0) {
        Fail(line.number, "bone '" + key + "' listed twice in frame " +
                              std::to_string(last_number) + " (first at line " +
                              std::to_string(listed_at[b]) + ")");
      }
      listed_at[b] = line.number;
      const std::vector<Dof>& dofs = skeleton_.bones[b].dofs;
      if (line.tokens.size() - 1 != dofs.size()) {
        Fail(line.number, "bone '" + key + "' has " + std::to_string(line.tokens.size() - 1) +
                              " values; its dof in " + asf_name_ + " lists " +
                              std::to_string(dofs.size()));
      }
      std::vector<double>& values = frames.back()[b];
      for (size_t k = 0; k < dofs.size(); ++k) {
        if (IsRotation(dofs[k])) {
          // The limit in the file's unit: degrees, or radians for :RADIANS.
          const bool radians = to_radians == 1.0;
          const double limit =
              radians ? kMaxAsfAmcAngleDeg * std::numbers::pi / 180.0 : kMaxAsfAmcAngleDeg;
          values[k] = Bounded(line, k + 1, "rotation", limit, radians ? "radians" : "degrees");
          values[k] *= to_radians;
        } else {
          values[k] = Length(line, k + 1, "value");
        }
      }
    }
    if (frames.empty()) Fail(line_count_, "the AMC file has no frames");
    return frames;
  }

 private:
  int line_count_ = 1;
  std::vector<Line> lines_;
  const AsfSkeleton& skeleton_;
  std::string asf_name_;
};

// A clip joint: bone `bone`'s start, or its tip when `tip`.
struct JointRef {
  int bone = 0;
  bool tip = false;
};

// Forward kinematics of one frame (see asf_amc.h for the convention).
void Solve(const AsfSkeleton& skeleton,
           const std::vector<int>& bone_order,
           const std::vector<JointRef>& joints,
           const std::vector<std::vector<double>>& values,
           MocapClip::Frame* frame) {
  const size_t n = skeleton.bones.size();
  std::vector<Matrix3d> world(n);  // W_b: world delta rotation
  std::vector<Vector3d> start(n), end(n);
  for (int b : bone_order) {
    const AsfBone& bone = skeleton.bones[b];
    Matrix3d motion = Matrix3d::Identity();
    Vector3d translation = Vector3d::Zero();
    double stretch = 0;
    for (size_t k = 0; k < bone.dofs.size(); ++k) {
      const Dof d = bone.dofs[k];
      if (IsRotation(d)) {
        motion = AxisRotation(AxisOf(d), values[b][k]) * motion;  // first listed applied first
      } else if (IsTranslation(d)) {
        translation[AxisOf(d)] += values[b][k];
      } else {
        stretch += values[b][k];
      }
    }
    const Matrix3d delta = bone.axis * motion * bone.axis.transpose();
    if (bone.parent < 0) {
      world[b] = delta;
      start[b] = skeleton.root_position + translation;  // world axes
    } else {
      const Matrix3d& parent = world[bone.parent];
      world[b] = parent * delta;
      // Translation dofs are in the bone's local axes, applied before its rotation.
      start[b] = end[bone.parent] + parent * bone.axis * translation;
    }
    end[b] = start[b] + world[b] * bone.direction * (bone.length + stretch);
  }
  frame->position.resize(joints.size());
  frame->rotation.resize(joints.size());
  for (size_t j = 0; j < joints.size(); ++j) {
    const JointRef& ref = joints[j];
    frame->position[j] = ref.tip ? end[ref.bone] : start[ref.bone];
    frame->rotation[j] = Eigen::Quaterniond(world[ref.bone]).normalized();
  }
}

// The clip names a leaf bone's tip "<bone>_end": a bone already named so
// would give two joints one name.
void CheckTipNames(const AsfSkeleton& skeleton, const std::string& asf_name) {
  for (size_t b = 1; b < skeleton.bones.size(); ++b) {
    if (!skeleton.bones[b].children.empty()) continue;
    const auto it = skeleton.index.find(skeleton.bones[b].name + "_end");
    if (it == skeleton.index.end()) continue;
    throw InputError(asf_name, "line " + std::to_string(skeleton.bones[it->second].line),
                     "bone name '" + it->first + "' is also the name of bone '" +
                         skeleton.bones[b].name + "''s tip joint");
  }
}

}  // namespace

MocapClip ParseAsfAmc(const std::string& asf_text,
                      const std::string& asf_name,
                      const std::string& amc_text,
                      const std::string& amc_name,
                      double frame_time) {
  if (!(frame_time > 0) || !std::isfinite(frame_time)) {
    throw InputError(amc_name, "frame_time", "frame time must be positive");
  }
  const AsfSkeleton skeleton = AsfParser(asf_text, asf_name).Parse();
  CheckTipNames(skeleton, asf_name);
  const AmcFrames frames = AmcParser(amc_text, amc_name, skeleton, asf_name).Parse();

  MocapClip clip;
  clip.name = std::filesystem::path(amc_name).stem().string();
  clip.file = amc_name;
  clip.convention = "cmu";
  clip.frame_time = frame_time;
  clip.metres_per_unit = skeleton.length_unit > 0 ? 0.0254 / skeleton.length_unit : 0.0;

  // Depth-first from the root, children in :hierarchy order; a leaf bone's tip
  // right after the bone.
  std::vector<int> bone_order;
  std::vector<JointRef> joints;
  std::vector<int> joint_of_bone(skeleton.bones.size(), -1);
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const int b = stack.back();
    stack.pop_back();
    const AsfBone& bone = skeleton.bones[b];
    bone_order.push_back(b);
    joint_of_bone[b] = static_cast<int>(joints.size());
    joints.push_back({b, false});
    clip.joint_names.push_back(bone.name);
    clip.parent.push_back(bone.parent < 0 ? -1 : joint_of_bone[bone.parent]);
    if (b != 0 && bone.children.empty()) {
      joints.push_back({b, true});
      clip.joint_names.push_back(bone.name + "_end");
      clip.parent.push_back(joint_of_bone[b]);
    }
    for (auto it = bone.children.rbegin(); it != bone.children.rend(); ++it) stack.push_back(*it);
  }

  std::vector<std::vector<double>> rest(skeleton.bones.size());
  for (size_t b = 0; b < skeleton.bones.size(); ++b) {
    rest[b].assign(skeleton.bones[b].dofs.size(), 0.0);
  }
  MocapClip::Frame rest_frame;
  Solve(skeleton, bone_order, joints, rest, &rest_frame);
  clip.rest_position = rest_frame.position;

  clip.frames.resize(frames.size());
  for (size_t f = 0; f < frames.size(); ++f) {
    Solve(skeleton, bone_order, joints, frames[f], &clip.frames[f]);
  }
  return clip;
}

MocapClip LoadAsfAmc(const std::filesystem::path& asf,
                     const std::filesystem::path& amc,
                     double frame_time) {
  auto read = [](const std::filesystem::path& path, const char* what) {
    std::ifstream in(path, std::ios::binary);
    if (!in || std::filesystem::is_directory(path))
      throw InputError(path.string(), "file", std::string("cannot open the ") + what);
    std::stringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(path.string(), "file", std::string("cannot read the ") + what);
    return buffer.str();
  };
  const std::string asf_text = read(asf, "ASF file");
  const std::string amc_text = read(amc, "AMC file");
  return ParseAsfAmc(asf_text, asf.string(), amc_text, amc.string(), frame_time);
}

}  // namespace irbench
