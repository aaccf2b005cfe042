#include "sim/motion/library.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "common/atomic_file.h"
#include "common/error.h"
#include "sim/motion/arm_pose.h"
#include "sim/motion/keyframes.h"
#include "sim/motion/posture_candidates.h"

namespace irbench {
namespace {

constexpr double kDeg = M_PI / 180.0;

double Smooth(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3 - 2 * u);
}

// Deterministic uniform in [0, 1) from a 64-bit state (splitmix64).
double Uniform(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return (z >> 11) * (1.0 / 9007199254740992.0);
}

struct BodyPose {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double heading_deg = 0;
  ArmPose right, left;
  double crouch_deg = 0;   // hips and ankles flex by this, knees by twice it
  double lean_deg = 0;     // the spine leans forward
  double hip_deg[2] = {0, 0};   // walking: right, left hip flexion
  double knee_deg[2] = {0, 0};  // walking: right, left knee flexion
  double arm_swing_deg[2] = {0, 0};
};

// The skeleton pose of a body pose, feet planted: the pelvis height puts the
// lowest ankle at its bind height.
Pose ToPose(const BodyPose& b, const Skeleton& sk) {
  Pose pose;
  pose.local_rotation[kPelvis] = Eigen::AngleAxisd(b.heading_deg * kDeg, Eigen::Vector3d::UnitZ());
  pose.local_rotation[kSpine] = Eigen::AngleAxisd(-b.lean_deg * kDeg, Eigen::Vector3d::UnitX());
  const ArmPose* arms[2] = {&b.right, &b.left};
  for (int k = 0; k < 2; ++k) {
    const int side = k == 0 ? 1 : -1;
    const int sh = side > 0 ? kRightShoulder : kLeftShoulder;
    pose.local_rotation[sh] =
        Eigen::AngleAxisd(b.arm_swing_deg[k] * kDeg, Eigen::Vector3d::UnitX()) * arms[k]->shoulder;
    pose.local_rotation[sh + 1] = Eigen::AngleAxisd(arms[k]->elbow_deg * kDeg, side * Eigen::Vector3d::UnitZ());
    const int hip = side > 0 ? kRightHip : kLeftHip;
    const double hip_flex = b.crouch_deg + b.hip_deg[k];
    const double knee_flex = 2 * b.crouch_deg + b.knee_deg[k];
    pose.local_rotation[hip] = Eigen::AngleAxisd(hip_flex * kDeg, Eigen::Vector3d::UnitX());
    pose.local_rotation[hip + 1] = Eigen::AngleAxisd(-knee_flex * kDeg, Eigen::Vector3d::UnitX());
    pose.local_rotation[hip + 2] =
        Eigen::AngleAxisd((knee_flex - hip_flex) * kDeg, Eigen::Vector3d::UnitX());
  }
  const JointTransforms fk = ForwardKinematics(sk, pose);
  const double lowest = std::min(fk[kRightAnkle].translation().z(), fk[kLeftAnkle].translation().z());
  pose.root_offset = Eigen::Vector3d(b.position.x() - sk.bind_position[kPelvis].x(),
                                     b.position.y() - sk.bind_position[kPelvis].y(),
                                     sk.bind_position[kRightAnkle].z() - lowest);
  return pose;
}

// A motion given by a function of time.
class FunctionMotion : public MotionSource {
 public:
  FunctionMotion(std::string name, double duration, std::function<Pose(double)> f,
                 std::vector<MotionEvent> events = {})
      : MotionSource(std::move(name)), duration_(duration), f_(std::move(f)), events_(std::move(events)) {}
  Pose At(double t) const override { return f_(std::clamp(t, 0.0, duration_)); }
  double Duration() const override { return duration_; }
  std::vector<MotionEvent> Events() const override { return events_; }

 private:
  double duration_;
  std::function<Pose(double)> f_;
  std::vector<MotionEvent> events_;
};

// Physiological tremor on the shoulders, off while that arm holds a pointing
// pose (faded over 0.25 s) so the aim stays exact.
class TremorMotion : public MotionSource {
 public:
  TremorMotion(MotionPtr source, const MotionStyle& style)
      : MotionSource(source->name()), source_(std::move(source)), style_(style) {
    uint64_t state = style.seed ^ 0x7E3E0ull;
    for (double& p : phase_) p = 2 * M_PI * Uniform(state);
    events_ = source_->Events();
  }
  Pose At(double t) const override {
    Pose pose = source_->At(t);
    if (style_.tremor_deg <= 0) return pose;
    for (int k = 0; k < 2; ++k) {
      double gain = 1;
      for (const MotionEvent& e : events_) {
        if (e.kind != "point" || e.side != (k == 0 ? "right" : "left")) continue;
        const double d = std::max(e.start - t, t - e.end);  // < 0 inside
        gain = std::min(gain, std::clamp(d / 0.25, 0.0, 1.0));
      }
      const double w = 2 * M_PI * style_.tremor_hz * t;
      const double a = style_.tremor_deg * kDeg * gain;
      const Eigen::Quaterniond q = Eigen::AngleAxisd(a * std::sin(w + phase_[2 * k]), Eigen::Vector3d::UnitX()) *
                                   Eigen::AngleAxisd(a * std::sin(1.3 * w + phase_[2 * k + 1]), Eigen::Vector3d::UnitZ());
      const int sh = k == 0 ? kRightShoulder : kLeftShoulder;
      pose.local_rotation[sh] = q * pose.local_rotation[sh];
    }
    return pose;
  }
  double Duration() const override { return source_->Duration(); }
  std::vector<MotionEvent> Events() const override { return events_; }

 private:
  MotionPtr source_;
  MotionStyle style_;
  double phase_[4];
  std::vector<MotionEvent> events_;
};

// Arm keyframes: a timeline of (t, right arm, left arm) with eased
// interpolation, the body standing at one place.
struct ArmKey {
  double t;
  ArmPose right, left;
};

class Builder {
 public:
  Builder(MotionContext& ctx, std::string file, std::string where)
      : ctx_(ctx), sk_(ctx.avatar->skeleton), file_(std::move(file)), where_(std::move(where)) {}

  const MotionStyle& style() const { return ctx_.style; }
  int dom() const { return ctx_.style.handedness; }
  ArmPose Rest(int side) const { return RestArm(side, ctx_.style); }
  double T(double seconds) const { return seconds / ctx_.style.tempo; }

  // A standing motion from arm keys: the dominant arm follows `keys`; the
  // other arm follows them `asynchrony_s` later.
  // `lead` is the side whose keys are kept exactly (the pointing arm).
  MotionPtr Standing(const std::string& name, std::vector<ArmKey> keys, std::vector<MotionEvent> events,
                     int lead = 0) {
    const BodyPose base = StandingBody();
    const double lag = ctx_.style.asynchrony_s;
    auto pose_at = [base, keys](double t, int which_side) {
      // Eased interpolation between keys.
      BodyPose b = base;
      const ArmKey* a = &keys.front();
      const ArmKey* c = &keys.front();
      for (size_t i = 0; i < keys.size(); ++i) {
        if (keys[i].t <= t) a = &keys[i];
        if (keys[i].t >= t) { c = &keys[i]; break; }
        c = &keys[i];
      }
      const double u = c->t > a->t ? Smooth((t - a->t) / (c->t - a->t)) : 0.0;
      b.right = Blend(a->right, c->right, u);
      b.left = Blend(a->left, c->left, u);
      (void)which_side;
      return b;
    };
    const double end = keys.back().t + lag;
    const int lag_side = lead != 0 ? -lead : -dom();
    const Skeleton sk = sk_;
    auto f = [pose_at, lag, lag_side, sk](double t) {
      BodyPose b = pose_at(t, 0);
      const BodyPose late = pose_at(t - lag, 0);
      if (lag_side > 0) b.right = late.right; else b.left = late.left;
      return ToPose(b, sk);
    };
    return Wrap(std::make_shared<FunctionMotion>(name, end, f, std::move(events)));
  }

  BodyPose StandingBody() const {
    BodyPose b;
    b.position = ctx_.state.position;
    b.heading_deg = ctx_.state.heading_deg;
    b.right = Rest(1);
    b.left = Rest(-1);
    return b;
  }

  MotionPtr Wrap(MotionPtr m) const { return std::make_shared<TremorMotion>(std::move(m), ctx_.style); }

  // The arm aimed so the ray from the head centre through the hand tip hits
  // `point` (world), the other arm as given, the body standing.
  ArmPose AimAt(int side, const Eigen::Vector3d& point, const ArmPose& other) const {
    BodyPose b = StandingBody();
    (side > 0 ? b.left : b.right) = other;
    (side > 0 ? b.right : b.left) = ArmPose{};
    const Pose pose = ToPose(b, sk_);
    const JointTransforms fk = ForwardKinematics(sk_, pose);
    const int sh = side > 0 ? kRightShoulder : kLeftShoulder;
    const Eigen::Vector3d s = fk[sh].translation();
    Eigen::Vector3d head = Eigen::Vector3d::Zero();
    Eigen::Vector3d tip_offset = Eigen::Vector3d::Zero();
    for (const BoneMarker& m : ctx_.avatar->markers) {
      if (m.name == "head") head = fk[m.joint] * m.offset_in_joint;
      if (m.name == (side > 0 ? "right_hand_tip" : "left_hand_tip")) {
        tip_offset = sk_.bind_position[m.joint] + m.offset_in_joint;
      }
    }
    const double length = (tip_offset - sk_.bind_position[sh]).norm();
    // The far point where the ray from the head meets the sphere of the
    // straight arm's reach around the shoulder.
    const Eigen::Vector3d u = (point - head).normalized();
    const Eigen::Vector3d hs = head - s;
    const double bq = u.dot(hs), cq = hs.squaredNorm() - length * length;
    const double disc = bq * bq - cq;
    if (disc < 0) throw InputError(file_, where_, "the target cannot be reached by a straight arm");
    const Eigen::Vector3d hand = head + (-bq + std::sqrt(disc)) * u;
    const Eigen::Vector3d d_world = (hand - s).normalized();
    // Into the chest frame (the clavicle is at its bind rotation).
    const Eigen::Matrix3d chest = fk[kChest].linear();
    const Eigen::Vector3d d_chest = chest.transpose() * d_world;
    return ArmFromDirections(side, d_chest, d_chest);
  }

  Eigen::Vector3d TargetPoint(const std::string& target) const {
    if (ctx_.scene) {
      for (const ScreenSurface& screen : ctx_.scene->screens) {
        const auto it = screen.targets.find(target);
        if (it != screen.targets.end()) return screen.PointAt(it->second);
      }
    }
    std::string names;
    if (ctx_.scene) {
      for (const ScreenSurface& screen : ctx_.scene->screens) {
        for (const auto& [n, st] : screen.targets) names += (names.empty() ? "" : ", ") + n;
      }
    }
    throw InputError(file_, where_ + ".target",
                     "unknown screen target '" + target + "'" +
                         (names.empty() ? std::string(" (the scene has no targets)") : " (known: " + names + ")"));
  }

  [[noreturn]] void Fail(const std::string& field, const std::string& message) const {
    throw InputError(file_, where_ + (field.empty() ? "" : "." + field), message);
  }

  MotionContext& ctx_;
  const Skeleton& sk_;
  std::string file_, where_;
};

double Param(const nlohmann::json& params, const char* key, double fallback, Builder& b, double lo, double hi) {
  if (!params.is_object() || !params.contains(key) || params[key].is_null()) return fallback;
  if (!params[key].is_number()) b.Fail(key, "must be a number");
  const double v = params[key].get<double>();
  if (!std::isfinite(v) || v < lo || v > hi) {
    b.Fail(key, "must be in " + std::to_string(lo) + ".." + std::to_string(hi));
  }
  return v;
}

std::string StringParam(const nlohmann::json& params, const char* key, const std::string& fallback, Builder& b) {
  if (!params.is_object() || !params.contains(key) || params[key].is_null()) return fallback;
  if (!params[key].is_string()) b.Fail(key, "must be a string");
  return params[key].get<std::string>();
}

int SideParam(const nlohmann::json& params, Builder& b) {
  const std::string side = StringParam(params, "side", "dominant", b);
  if (side == "dominant") return b.dom();
  if (side == "other") return -b.dom();
  if (side == "right") return 1;
  if (side == "left") return -1;
  b.Fail("side", "must be right, left, dominant or other (got '" + side + "')");
}

const char* SideName(int side) { return side > 0 ? "right" : "left"; }

void CheckKeys(const nlohmann::json& params, const std::vector<std::string>& allowed, Builder& b) {
  if (params.is_null()) return;
  if (!params.is_object()) b.Fail("", "parameters must be an object");
  for (const auto& [key, value] : params.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      b.Fail(key, "unknown parameter (allowed: " + (list.empty() ? std::string("none") : list) + ")");
    }
  }
}

// Flapping keys for the arms in `sides` starting at t0.
double AddFlaps(std::vector<ArmKey>& keys, double t0, int cycles, double period, double amplitude,
                bool right, bool left, const MotionStyle& style) {
  double t = t0;
  for (int c = 0; c < cycles; ++c) {
    for (double el : {-30.0 * amplitude, 25.0 * amplitude}) {
      t += period / 2;
      ArmKey k = keys.back();
      k.t = t;
      if (right) k.right = ArmAngles(1, 0, el, 5);
      if (left) k.left = ArmAngles(-1, 0, el, 5);
      keys.push_back(k);
    }
  }
  return t;
}

MotionPtr Gesture(int id, const nlohmann::json& params, Builder& b) {
  const MotionStyle& st = b.style();
  const int d = SideParam(params, b);
  const int o = -d;
  auto arm = [](ArmKey& k, int side) -> ArmPose& { return side > 0 ? k.right : k.left; };
  std::vector<ArmKey> keys = {{0.0, b.Rest(1), b.Rest(-1)}};
  auto key = [&](double dt) {
    ArmKey k = keys.back();
    k.t += b.T(dt);
    keys.push_back(k);
    return &keys.back();
  };
  const double amp = st.amplitude;
  const double hold = Param(params, "hold_s", 1.5, b, 0.0, 60.0);
  std::vector<MotionEvent> events;
  std::string target = StringParam(params, "target", "", b);
  double az = Param(params, "azimuth_deg", 30, b, -60, 120);
  switch (id) {
    case 1: {  // one arm rises and points horizontally
      ArmKey* k = key(1.0);
      if (!target.empty()) {
        arm(*k, d) = b.AimAt(d, b.TargetPoint(target), arm(*k, o));
      } else {
        arm(*k, d) = ArmAngles(d, az, 0);
      }
      const double t_hold = k->t;
      key(hold);
      if (!target.empty()) events.push_back({"point", target, SideName(d), t_hold, keys.back().t});
      arm(*key(1.0), d) = b.Rest(d);
      break;
    }
    case 2:  // both arms flap like wings
    case 5: {  // one arm flaps
      const bool both = id == 2;
      ArmKey* k = key(0.8);
      arm(*k, d) = ArmAngles(d, 0, 10, 5);
      if (both) arm(*k, o) = ArmAngles(o, 0, 10, 5);
      const int cycles = static_cast<int>(Param(params, "cycles", 3, b, 1, 20));
      AddFlaps(keys, keys.back().t, cycles, b.T(0.8), amp, both || d > 0, both || d < 0, st);
      ArmKey* end = key(0.8);
      arm(*end, d) = b.Rest(d);
      arm(*end, o) = b.Rest(o);
      break;
    }
    case 3: {  // directing traffic: one arm points, the other waves
      ArmKey* k = key(0.8);
      if (!target.empty()) {
        arm(*k, d) = b.AimAt(d, b.TargetPoint(target), arm(*k, o));
      } else {
        arm(*k, d) = ArmAngles(d, 0, 0);
      }
      arm(*k, o) = ArmAngles(o, 60, 0, 30);
      const double t_hold = k->t;
      const int cycles = static_cast<int>(Param(params, "cycles", 3, b, 1, 20));
      for (int c = 0; c < cycles; ++c) {
        arm(*key(0.35), o) = ArmAngles(o, 60, 0, 30 + 70 * amp);
        arm(*key(0.35), o) = ArmAngles(o, 60, 0, 30);
      }
      if (!target.empty()) events.push_back({"point", target, SideName(d), t_hold, keys.back().t});
      ArmKey* end = key(0.8);
      arm(*end, d) = b.Rest(d);
      arm(*end, o) = b.Rest(o);
      break;
    }
    case 4: {  // one arm raised overhead
      arm(*key(1.2), d) = Atom(2, d, st);
      key(hold);
      arm(*key(1.0), d) = b.Rest(d);
      break;
    }
    case 6: {  // both arms point diagonally, one up-out, the other down-out
      ArmKey* k = key(1.0);
      arm(*k, d) = Atom(3, d, st);
      arm(*k, o) = Atom(4, o, st);
      key(hold);
      ArmKey* end = key(1.0);
      arm(*end, d) = b.Rest(d);
      arm(*end, o) = b.Rest(o);
      break;
    }
  }
  events.insert(events.begin(), MotionEvent{"gesture", GestureNames()[id - 1], "", 0.0,
                                            keys.back().t + st.asynchrony_s});
  return b.Standing(GestureNames()[id - 1], keys, events, d);
}

}  // namespace

namespace {

int ParseAtom(const std::string& name, Builder& b, const std::string& field) {
  const int atom = PostureAtomIndex(name);
  if (atom < 0) b.Fail(field, "unknown atom '" + name + "' (" + kPostureAtomNames + ")");
  return atom;
}

// One arm of `posture`: an atom's name, or atoms' weights {"A1": 0.5,
// "A3": 0.5} (AtomBlend).
ArmPose PostureArm(const nlohmann::json& params, const char* field, int side, Builder& b) {
  if (!params.is_object() || !params.contains(field) || params[field].is_null()) return Atom(0, side, b.style());
  const nlohmann::json& v = params[field];
  if (v.is_string()) return Atom(ParseAtom(v.get<std::string>(), b, field), side, b.style());
  if (!v.is_object() || v.empty()) b.Fail(field, "must be an atom (A0..A4) or an object of atoms' weights");
  std::array<double, 5> weights{};
  for (const auto& [name, w] : v.items()) {
    const int atom = ParseAtom(name, b, std::string(field) + "." + name);
    if (!w.is_number() || !std::isfinite(w.get<double>()) || w.get<double>() < 0 || w.get<double>() > 1) {
      b.Fail(std::string(field) + "." + name, "a weight must be a number in 0..1");
    }
    weights[atom] += w.get<double>();
  }
  return AtomBlend(weights, side, b.style());
}

MotionPtr Posture(const nlohmann::json& params, Builder& b) {
  const ArmPose right = PostureArm(params, "right", 1, b), left = PostureArm(params, "left", -1, b);
  const double move = Param(params, "move_s", 1.0, b, 0.1, 60.0);
  const double hold = Param(params, "hold_s", 1.5, b, 0.0, 60.0);
  std::vector<ArmKey> keys = {{0.0, b.Rest(1), b.Rest(-1)}};
  keys.push_back({b.T(move), right, left});
  keys.push_back({keys.back().t + b.T(hold), keys.back().right, keys.back().left});
  keys.push_back({keys.back().t + b.T(1.0), b.Rest(1), b.Rest(-1)});
  return b.Standing("posture", keys, {});
}

// Every two-arm atom combination (C(5,2) + 5 = 15), one after the other.
MotionPtr AtomTour(const nlohmann::json& params, Builder& b) {
  const double hold = Param(params, "hold_s", 1.0, b, 0.0, 60.0);
  std::vector<ArmKey> keys = {{0.0, b.Rest(1), b.Rest(-1)}};
  for (int p = 0; p <= 4; ++p) {
    for (int s = p; s <= 4; ++s) {
      if (p == 0 && s == 0) continue;
      keys.push_back({keys.back().t + b.T(0.9), Atom(s, 1, b.style()), Atom(p, -1, b.style())});
      keys.push_back({keys.back().t + b.T(hold), keys.back().right, keys.back().left});
    }
  }
  keys.push_back({keys.back().t + b.T(0.9), b.Rest(1), b.Rest(-1)});
  keys.push_back({keys.back().t + b.T(hold), b.Rest(1), b.Rest(-1)});
  return b.Standing("atom_tour", keys, {});
}

// The thesis's 30 candidate postures for selecting the atoms (5.1.2), one
// arm in each in turn (posture_candidates.h); each hold a
// `posture_candidate` event.
MotionPtr PostureCandidateTour(const nlohmann::json& params, Builder& b) {
  const int d = SideParam(params, b);
  const double hold = Param(params, "hold_s", 0.8, b, 0.1, 60.0);
  std::vector<ArmKey> keys = {{0.0, b.Rest(1), b.Rest(-1)}};
  std::vector<MotionEvent> events;
  const auto& arms = PostureCandidateArms();
  for (size_t c = 0; c < arms.size(); ++c) {
    const CandidateArm& a = arms[c];
    ArmKey k{keys.back().t + b.T(0.7), b.Rest(1), b.Rest(-1)};
    (d > 0 ? k.right : k.left) = ArmAngles(d, a.az, a.el, a.elbow, a.bend);
    keys.push_back(k);
    k.t += b.T(hold);
    keys.push_back(k);
    const std::string name = (c + 1 < 10 ? "C0" : "C") + std::to_string(c + 1);
    events.push_back({"posture_candidate", name, SideName(d), keys[keys.size() - 2].t, k.t});
  }
  keys.push_back({keys.back().t + b.T(0.9), b.Rest(1), b.Rest(-1)});
  keys.push_back({keys.back().t + b.T(0.5), b.Rest(1), b.Rest(-1)});
  return b.Standing("posture_candidates", keys, events, d);
}

// The self-occluding poses of thesis Fig. 6.10 and their kin, held: the
// `side` arm (default the dominant one) and, where the pose takes both, the
// other. Wrist targets relative to the shoulder, chest frame (x = the
// person's right, y forward, z up).
MotionPtr Occlusion(const nlohmann::json& params, Builder& b) {
  const std::string pose = StringParam(params, "pose", "arm_across", b);
  const int d = SideParam(params, b), o = -d;
  const double hold = Param(params, "hold_s", 2.0, b, 0.0, 60.0);
  const Skeleton& sk = b.sk_;
  ArmKey held{b.T(1.0), b.Rest(1), b.Rest(-1)};
  ArmPose& lead = d > 0 ? held.right : held.left;
  ArmPose& other = d > 0 ? held.left : held.right;
  const auto pole = [](int side) { return Eigen::Vector3d(0.6 * side, -0.3, -1.0); };
  if (pose == "arm_across") {
    // Fig. 6.10, left: the arm level across the chest, the hand in front of
    // the other shoulder: over the torso in the frontal views.
    lead = ArmReach(d, sk, Eigen::Vector3d(-0.24 * d, 0.30, -0.05), pole(d));
  } else if (pose == "arms_crossed") {
    // Fig. 6.10, right: the forearms cross in front of the chest, the
    // `side` arm in front of the other.
    lead = ArmReach(d, sk, Eigen::Vector3d(-0.42 * d, 0.38, -0.12), pole(d));
    other = ArmReach(o, sk, Eigen::Vector3d(-0.40 * o, 0.24, -0.20), pole(o));
  } else if (pose == "hands_together") {
    lead = ArmReach(d, sk, Eigen::Vector3d(-0.17 * d, 0.33, -0.12), pole(d));
    other = ArmReach(o, sk, Eigen::Vector3d(-0.17 * o, 0.33, -0.12), pole(o));
  } else if (pose == "arm_behind") {
    // The hand at the small of the back: hidden from the frontal cameras.
    lead = ArmReach(d, sk, Eigen::Vector3d(-0.16 * d, -0.20, -0.42), Eigen::Vector3d(1.0 * d, -0.5, 0.0));
  } else {
    b.Fail("pose", "unknown pose '" + pose + "' (arm_across, arms_crossed, hands_together, arm_behind)");
  }
  std::vector<ArmKey> keys = {{0.0, b.Rest(1), b.Rest(-1)}, held};
  keys.push_back({held.t + b.T(hold), held.right, held.left});
  keys.push_back({keys.back().t + b.T(1.0), b.Rest(1), b.Rest(-1)});
  return b.Standing("occlusion_" + pose, keys, {}, d);
}

MotionPtr PointAt(const nlohmann::json& params, Builder& b) {
  const int d = SideParam(params, b);
  const std::string target = StringParam(params, "target", "", b);
  if (target.empty()) b.Fail("target", "required: a named screen target");
  const double hold = Param(params, "hold_s", 1.5, b, 0.0, 60.0);
  std::vector<ArmKey> keys = {{0.0, b.Rest(1), b.Rest(-1)}};
  ArmKey aim = keys.back();
  aim.t = b.T(1.0);
  (d > 0 ? aim.right : aim.left) = b.AimAt(d, b.TargetPoint(target), d > 0 ? aim.left : aim.right);
  keys.push_back(aim);
  keys.push_back({aim.t + b.T(hold), aim.right, aim.left});
  keys.push_back({keys.back().t + b.T(1.0), b.Rest(1), b.Rest(-1)});
  return b.Standing("point_" + target, keys, {{"point", target, SideName(d), aim.t, aim.t + b.T(hold)}}, d);
}

MotionPtr Rest(const nlohmann::json& params, Builder& b) {
  const double seconds = Param(params, "seconds", 2.0, b, 0.0, 3600.0);
  return b.Standing("rest", {{0.0, b.Rest(1), b.Rest(-1)}, {seconds, b.Rest(1), b.Rest(-1)}}, {});
}

MotionPtr Crouch(const nlohmann::json& params, Builder& b) {
  const double depth = Param(params, "depth_deg", 50, b, 0, 80);
  const double hold = Param(params, "hold_s", 1.5, b, 0, 60);
  const BodyPose base = b.StandingBody();
  const double down = b.T(1.0), t_hold = b.T(hold), up = b.T(1.0);
  const Skeleton sk = b.sk_;
  auto f = [=](double t) {
    BodyPose body = base;
    const double u = t < down ? Smooth(t / down) : t < down + t_hold ? 1.0 : 1.0 - Smooth((t - down - t_hold) / up);
    body.crouch_deg = depth * u;
    body.lean_deg = 0.5 * depth * u;
    return ToPose(body, sk);
  };
  return b.Wrap(std::make_shared<FunctionMotion>("crouch", down + t_hold + up, f));
}

// Walks from the current position to `to`, facing the way it goes, and
// (optionally) turns to `end_heading_deg` at the end.
MotionPtr Walk(const std::string& name, const Eigen::Vector2d& to, std::optional<double> end_heading,
               Builder& b, double speed) {
  const MotionStyle st = b.style();
  const Eigen::Vector2d from = b.ctx_.state.position;
  const double start_heading = b.ctx_.state.heading_deg;
  const Eigen::Vector2d delta = to - from;
  const double distance = delta.norm();
  // Heading 0 faces +y; facing direction (x, y) has heading atan2(-x, y).
  const double walk_heading = distance > 1e-6 ? std::atan2(-delta.x(), delta.y()) / kDeg : start_heading;
  auto turn_time = [&](double a, double c) {
    double diff = std::remainder(c - a, 360.0);
    return std::pair<double, double>{diff, std::abs(diff) / 90.0 * 0.8 / st.tempo};
  };
  const auto [turn1, t_turn1] = turn_time(start_heading, walk_heading);
  const double v = speed * st.tempo;
  const double t_walk = distance / v;
  const double final_heading = end_heading.value_or(walk_heading);
  const auto [turn2, t_turn2] = turn_time(walk_heading, final_heading);
  const BodyPose base = b.StandingBody();
  const Skeleton sk = b.sk_;
  const double stride = 1.25 * sk.bind_position[kPelvis].z() / 0.93;  // metres per gait cycle
  const double total = t_turn1 + t_walk + t_turn2;
  auto f = [=, turn1 = turn1, t_turn1 = t_turn1, turn2 = turn2, t_turn2 = t_turn2](double t) {
    BodyPose body = base;
    double progress = 0;  // distance walked
    if (t < t_turn1) {
      body.heading_deg = start_heading + turn1 * Smooth(t / std::max(t_turn1, 1e-9));
    } else if (t < t_turn1 + t_walk) {
      body.heading_deg = walk_heading;
      // Accelerate over the first and last 0.5 s (a trapezoidal speed profile).
      const double tw = t - t_turn1;
      const double ramp = std::min(0.5, t_walk / 2);
      const double cruise = distance / (t_walk - ramp);
      if (tw < ramp) progress = cruise * tw * tw / (2 * ramp);
      else if (tw > t_walk - ramp) progress = distance - cruise * (t_walk - tw) * (t_walk - tw) / (2 * ramp);
      else progress = cruise * (tw - ramp / 2);
      const double phase = 2 * M_PI * progress / stride;
      const double gait = std::min({1.0, tw / 0.4, (t_walk - tw) / 0.4});
      for (int k = 0; k < 2; ++k) {
        const double ph = phase + (k == 0 ? 0.0 : M_PI);
        body.hip_deg[k] = gait * 22.0 * std::sin(ph);
        body.knee_deg[k] = gait * (8.0 + 40.0 * std::max(0.0, std::sin(ph + 0.6 * M_PI)));
        body.arm_swing_deg[k] = -gait * 14.0 * st.amplitude * std::sin(ph);
      }
    } else {
      progress = distance;
      body.heading_deg = walk_heading + turn2 * Smooth((t - t_turn1 - t_walk) / std::max(t_turn2, 1e-9));
    }
    body.position = from + (distance > 1e-9 ? Eigen::Vector2d(delta * (progress / distance)) : Eigen::Vector2d::Zero());
    return ToPose(body, sk);
  };
  b.ctx_.state.position = to;
  b.ctx_.state.heading_deg = final_heading;
  return b.Wrap(std::make_shared<FunctionMotion>(name, std::max(total, 1e-3), f));
}

Eigen::Vector2d PointParam(const nlohmann::json& params, const char* key, const Eigen::Vector2d& fallback,
                           Builder& b) {
  if (!params.is_object() || !params.contains(key) || params[key].is_null()) return fallback;
  const auto& v = params[key];
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number()) b.Fail(key, "must be [x, y] metres");
  return {v[0].get<double>(), v[1].get<double>()};
}

// Natural story-telling hand motions: a sequence of straight wrist moves in
// front of the body that covers the nine motion labels of thesis 7.1.
MotionPtr Story(const nlohmann::json& params, Builder& b) {
  const int d = SideParam(params, b);
  const MotionStyle st = b.style();
  const Skeleton sk = b.sk_;
  const double a = st.amplitude;
  // Wrist targets relative to the shoulder, chest frame (x = person's right,
  // mirrored for the left arm; y forward; z up), and move times.
  struct Move { Eigen::Vector3d to; double seconds; };
  const double s = d;
  const Eigen::Vector3d low(0.10 * s, 0.30, -0.36), mid(0.08 * s, 0.32, -0.02);
  const std::vector<Move> moves = {
      {low, 0.6},                                         // from rest: OTHER
      {mid, 0.6},                                         // UP
      {mid, 0.6},                                         // PAUSE
      {mid + Eigen::Vector3d(-0.25 * a, 0, 0), 0.5},      // LEFT
      {mid + Eigen::Vector3d(0.12 * a, 0, 0), 0.6},       // RIGHT
      {mid + Eigen::Vector3d(0.12 * a, 0.20 * a, 0), 0.5},  // FORWARD
      {mid + Eigen::Vector3d(0.12 * a, -0.08 * a, 0), 0.5},  // BACKWARD
      {mid + Eigen::Vector3d(0.12 * a, -0.08 * a, 0), 0.5},  // PAUSE
      {mid + Eigen::Vector3d(0.12 * a, -0.08 * a, -0.28 * a), 0.5},  // DOWN
      {mid + Eigen::Vector3d(-0.06 * a, 0.10 * a, -0.10 * a), 0.5},  // OTHER (diagonal)
  };
  const BodyPose base = b.StandingBody();
  const ArmPose rest = b.Rest(d);
  const Eigen::Vector3d pole(0.6 * s, -0.3, -1.0);
  std::vector<double> start;
  double t = 0;
  for (const Move& m : moves) {
    start.push_back(t);
    t += m.seconds / st.tempo;
  }
  const double t_moves = t, t_back = 0.8 / st.tempo;
  auto f = [=](double time) {
    BodyPose body = base;
    ArmPose& arm = d > 0 ? body.right : body.left;
    if (time >= t_moves) {
      const ArmPose last = ArmReach(d, sk, moves.back().to, pole);
      arm = Blend(last, rest, Smooth((time - t_moves) / t_back));
      return ToPose(body, sk);
    }
    size_t k = 0;
    while (k + 1 < moves.size() && time >= start[k + 1]) ++k;
    const double u = Smooth((time - start[k]) / (moves[k].seconds / st.tempo));
    if (k == 0) {
      arm = Blend(rest, ArmReach(d, sk, moves[0].to, pole), u);
    } else {
      const Eigen::Vector3d p = moves[k - 1].to + u * (moves[k].to - moves[k - 1].to);
      arm = ArmReach(d, sk, p, pole);
    }
    return ToPose(body, sk);
  };
  return b.Wrap(std::make_shared<FunctionMotion>("story", t_moves + t_back, f));
}

}  // namespace

const std::vector<std::string>& GestureNames() {
  static const std::vector<std::string> names = {"point_horizontal", "flap_both", "direct_traffic",
                                                 "raise_overhead",   "flap_one",  "point_diagonal_both"};
  return names;
}

std::vector<std::pair<std::string, std::string>> LibraryMotions() {
  return {
      {"point_horizontal", "gesture 1: one arm rises and points horizontally (azimuth_deg, or target)"},
      {"flap_both", "gesture 2: both arms flap like wings (cycles)"},
      {"direct_traffic", "gesture 3: one arm points, the other waves (cycles, target)"},
      {"raise_overhead", "gesture 4: one arm raised overhead"},
      {"flap_one", "gesture 5: one arm flaps (cycles)"},
      {"point_diagonal_both", "gesture 6: both arms point diagonally, up-out and down-out"},
      {"point", "point at a named screen target (target, side, hold_s)"},
      {"posture", "an atom posture per arm, or a blend of atoms, held (right, left: A0..A4 or {\"A1\": w, ...}; move_s, hold_s)"},
      {"atom_tour", "every two-arm atom combination in turn (15 postures)"},
      {"posture_candidates", "one arm held in each of 30 candidate postures for atom selection (side, hold_s)"},
      {"story", "natural story-telling hand motions covering the nine motion labels"},
      {"occlusion", "a self-occluding pose held (pose: arm_across, arms_crossed, hands_together, arm_behind; side)"},
      {"rest", "stand at rest (seconds)"},
      {"crouch", "crouch down and stand up (depth_deg, hold_s)"},
      {"walk", "walk to a point on the stage (to: [x, y]; heading_deg at the end)"},
      {"turn", "turn on the spot (heading_deg)"},
      {"enter", "walk onto the stage from its left edge to a point (from, to)"},
      {"leave", "walk off the stage past its right edge (to)"},
  };
}

MotionStyle StyleFor(const std::string& person, uint64_t seed, const nlohmann::json& overrides,
                     const std::string& file) {
  MotionStyle st;
  uint64_t state = Fnv1a64(person) ^ (seed * 0x9E3779B97F4A7C15ull);
  st.seed = state;
  st.tempo = 0.85 + 0.35 * Uniform(state);
  st.amplitude = 0.85 + 0.25 * Uniform(state);
  st.asynchrony_s = 0.25 * Uniform(state);
  st.tremor_deg = 0.2 + 0.6 * Uniform(state);
  st.tremor_hz = 8.0 + 4.0 * Uniform(state);
  st.handedness = Uniform(state) < 0.2 ? -1 : 1;
  st.rest_abduction_deg = 5 + 8 * Uniform(state);
  if (overrides.is_null()) return st;
  if (!overrides.is_object()) throw InputError(file, "style", "must be an object");
  for (const auto& [key, value] : overrides.items()) {
    const std::string field = "style." + key;
    if (key == "handedness") {
      if (!value.is_string() || (value != "left" && value != "right")) {
        throw InputError(file, field, "must be \"left\" or \"right\"");
      }
      st.handedness = value == "left" ? -1 : 1;
      continue;
    }
    struct Knob {
      const char* name;
      double* target;
      double lo, hi;
    };
    const Knob knobs[] = {{"tempo", &st.tempo, 0.3, 3.0},
                          {"amplitude", &st.amplitude, 0.3, 1.5},
                          {"asynchrony_s", &st.asynchrony_s, 0.0, 1.0},
                          {"tremor_deg", &st.tremor_deg, 0.0, 5.0},
                          {"tremor_hz", &st.tremor_hz, 1.0, 30.0},
                          {"rest_abduction_deg", &st.rest_abduction_deg, 0.0, 30.0}};
    const Knob* knob = nullptr;
    for (const Knob& k : knobs) {
      if (key == k.name) knob = &k;
    }
    if (!knob) {
      throw InputError(file, field, "unknown style field (tempo, amplitude, asynchrony_s, tremor_deg, "
                                    "tremor_hz, handedness, rest_abduction_deg)");
    }
    if (!value.is_number() || value.get<double>() < knob->lo || value.get<double>() > knob->hi) {
      throw InputError(file, field, "must be a number in " + std::to_string(knob->lo) + ".." +
                                        std::to_string(knob->hi));
    }
    *knob->target = value.get<double>();
  }
  return st;
}

MotionPtr BuildLibraryMotion(const std::string& name, const nlohmann::json& params, MotionContext& ctx,
                             const std::string& file, const std::string& where) {
  if (!ctx.avatar) throw std::invalid_argument("BuildLibraryMotion needs an avatar");
  Builder b(ctx, file, where);
  const auto& gestures = GestureNames();
  const auto g = std::find(gestures.begin(), gestures.end(), name);
  if (g != gestures.end()) {
    CheckKeys(params, {"side", "hold_s", "cycles", "target", "azimuth_deg"}, b);
    return Gesture(static_cast<int>(g - gestures.begin()) + 1, params, b);
  }
  const Eigen::Vector2d stage_c = ctx.scene ? ctx.scene->stage_center : Eigen::Vector2d::Zero();
  const Eigen::Vector2d stage_s = ctx.scene ? ctx.scene->stage_size : Eigen::Vector2d(3, 3);
  if (name == "point") {
    CheckKeys(params, {"side", "hold_s", "target"}, b);
    return PointAt(params, b);
  }
  if (name == "posture") {
    CheckKeys(params, {"right", "left", "move_s", "hold_s"}, b);
    return Posture(params, b);
  }
  if (name == "atom_tour") {
    CheckKeys(params, {"hold_s"}, b);
    return AtomTour(params, b);
  }
  if (name == "posture_candidates") {
    CheckKeys(params, {"side", "hold_s"}, b);
    return PostureCandidateTour(params, b);
  }
  if (name == "story") {
    CheckKeys(params, {"side"}, b);
    return Story(params, b);
  }
  if (name == "occlusion") {
    CheckKeys(params, {"pose", "side", "hold_s"}, b);
    return Occlusion(params, b);
  }
  if (name == "rest") {
    CheckKeys(params, {"seconds"}, b);
    return Rest(params, b);
  }
  if (name == "crouch") {
    CheckKeys(params, {"depth_deg", "hold_s"}, b);
    return Crouch(params, b);
  }
  if (name == "walk") {
    CheckKeys(params, {"to", "heading_deg", "speed"}, b);
    if (!params.is_object() || !params.contains("to")) b.Fail("to", "required: [x, y] metres");
    std::optional<double> heading;
    if (params.contains("heading_deg")) heading = Param(params, "heading_deg", 0, b, -360, 360);
    return Walk("walk", PointParam(params, "to", Eigen::Vector2d::Zero(), b), heading, b, Param(params, "speed", 1.0, b, 0.2, 3.0));
  }
  if (name == "turn") {
    CheckKeys(params, {"heading_deg"}, b);
    return Walk("turn", ctx.state.position, Param(params, "heading_deg", 0, b, -360, 360), b, 1.0);
  }
  if (name == "enter") {
    CheckKeys(params, {"from", "to", "speed"}, b);
    const Eigen::Vector2d from = PointParam(
        params, "from", Eigen::Vector2d(stage_c.x() - stage_s.x() / 2 - 1.0, stage_c.y()), b);
    ctx.state.position = from;
    ctx.state.heading_deg = -90;
    ctx.state.on_stage = true;
    return Walk("enter", PointParam(params, "to", stage_c, b), 0.0, b, Param(params, "speed", 1.0, b, 0.2, 3.0));
  }
  if (name == "leave") {
    CheckKeys(params, {"to", "speed"}, b);
    const Eigen::Vector2d to = PointParam(
        params, "to", Eigen::Vector2d(stage_c.x() + stage_s.x() / 2 + 1.0, ctx.state.position.y()), b);
    MotionPtr m = Walk("leave", to, std::nullopt, b, Param(params, "speed", 1.0, b, 0.2, 3.0));
    ctx.state.on_stage = false;
    return m;
  }
  std::string names;
  for (const auto& [n, text] : LibraryMotions()) names += (names.empty() ? "" : ", ") + n;
  throw InputError(file, where, "unknown library motion '" + name + "' (known: " + names + ")");
}

}  // namespace irbench
