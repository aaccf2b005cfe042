#include "sim/motion/motion_source.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace irbench {
namespace {

double Smoothstep(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3 - 2 * u);
}

int MirrorJoint(int j) {
  switch (j) {
    case kRightClavicle: return kLeftClavicle;
    case kRightShoulder: return kLeftShoulder;
    case kRightElbow: return kLeftElbow;
    case kRightWrist: return kLeftWrist;
    case kLeftClavicle: return kRightClavicle;
    case kLeftShoulder: return kRightShoulder;
    case kLeftElbow: return kRightElbow;
    case kLeftWrist: return kRightWrist;
    case kRightHip: return kLeftHip;
    case kRightKnee: return kLeftKnee;
    case kRightAnkle: return kLeftAnkle;
    case kLeftHip: return kRightHip;
    case kLeftKnee: return kRightKnee;
    case kLeftAnkle: return kRightAnkle;
    default: return j;
  }
}

std::vector<MotionEvent> Shifted(std::vector<MotionEvent> events, double dt) {
  for (MotionEvent& e : events) {
    e.start += dt;
    e.end += dt;
  }
  return events;
}

void SortEvents(std::vector<MotionEvent>& events) {
  std::stable_sort(events.begin(), events.end(),
                   [](const MotionEvent& a, const MotionEvent& b) { return a.start < b.start; });
}

}  // namespace

Pose BlendPoses(const Pose& a, const Pose& b, double w) {
  Pose out;
  out.root_offset = a.root_offset + w * (b.root_offset - a.root_offset);
  for (int j = 0; j < kJointCount; ++j) {
    out.local_rotation[j] = a.local_rotation[j].slerp(w, b.local_rotation[j]);
  }
  return out;
}

Pose MirrorPose(const Pose& pose) {
  Pose out;
  out.root_offset = {-pose.root_offset.x(), pose.root_offset.y(), pose.root_offset.z()};
  for (int j = 0; j < kJointCount; ++j) {
    const Eigen::Quaterniond& q = pose.local_rotation[j];
    // Reflection M = diag(-1, 1, 1): M R M has quaternion (w, x, -y, -z).
    out.local_rotation[MirrorJoint(j)] = Eigen::Quaterniond(q.w(), q.x(), -q.y(), -q.z());
  }
  return out;
}

std::vector<int> ArmJoints(int side) {
  if (side > 0) return {kRightClavicle, kRightShoulder, kRightElbow, kRightWrist};
  return {kLeftClavicle, kLeftShoulder, kLeftElbow, kLeftWrist};
}

SequenceMotion::SequenceMotion(std::string name, std::vector<Item> items)
    : MotionSource(std::move(name)), items_(std::move(items)) {
  if (items_.empty()) throw std::invalid_argument("SequenceMotion needs at least one item");
  double t = 0;
  for (size_t k = 0; k < items_.size(); ++k) {
    Item& item = items_[k];
    if (k == 0) item.crossfade_s = 0;
    const double previous = k == 0 ? 0.0 : items_[k - 1].source->Duration();
    item.crossfade_s = std::clamp(item.crossfade_s, 0.0,
                                  std::min(previous, item.source->Duration()));
    t -= item.crossfade_s;
    start_.push_back(t);
    t += item.source->Duration();
  }
  duration_ = t;
}

Pose SequenceMotion::At(double t) const {
  // The last item that has started; blend with its predecessor during its
  // crossfade.
  size_t k = 0;
  while (k + 1 < items_.size() && t >= start_[k + 1]) ++k;
  const Pose current = items_[k].source->At(t - start_[k]);
  const double fade = items_[k].crossfade_s;
  if (k == 0 || fade <= 0 || t >= start_[k] + fade) return current;
  const Pose previous = items_[k - 1].source->At(t - start_[k - 1]);
  return BlendPoses(previous, current, Smoothstep((t - start_[k]) / fade));
}

std::vector<MotionEvent> SequenceMotion::Events() const {
  // Each item owns the time from the middle of its crossfade in to the middle
  // of its crossfade out (where the blend weight is 1/2); its events are
  // clipped to that window.
  std::vector<MotionEvent> all;
  for (size_t k = 0; k < items_.size(); ++k) {
    const double from = k == 0 ? -1e300 : start_[k] + items_[k].crossfade_s / 2;
    const double to = k + 1 == items_.size() ? 1e300 : start_[k + 1] + items_[k + 1].crossfade_s / 2;
    for (MotionEvent e : Shifted(items_[k].source->Events(), start_[k])) {
      e.start = std::max(e.start, from);
      e.end = std::min(e.end, to);
      if (e.end > e.start) all.push_back(e);
    }
  }
  SortEvents(all);
  return all;
}

MotionPtr LoopMotion(MotionPtr source, int count, double crossfade_s) {
  std::vector<SequenceMotion::Item> items;
  for (int i = 0; i < std::max(count, 1); ++i) items.push_back({source, crossfade_s});
  return std::make_shared<SequenceMotion>(source->name(), std::move(items));
}

MirrorMotion::MirrorMotion(MotionPtr source)
    : MotionSource(source->name() + "_mirrored"), source_(std::move(source)) {}

std::vector<MotionEvent> MirrorMotion::Events() const {
  std::vector<MotionEvent> events = source_->Events();
  for (MotionEvent& e : events) {
    if (e.side == "left") e.side = "right"; else if (e.side == "right") e.side = "left";
  }
  return events;
}

TimeWarpMotion::TimeWarpMotion(MotionPtr source, std::vector<std::pair<double, double>> points)
    : MotionSource(source->name()), source_(std::move(source)), points_(std::move(points)) {
  if (points_.size() < 2) throw std::invalid_argument("TimeWarpMotion needs two points");
  for (size_t i = 1; i < points_.size(); ++i) {
    if (!(points_[i].first > points_[i - 1].first) || !(points_[i].second > points_[i - 1].second)) {
      throw std::invalid_argument("TimeWarpMotion points must increase");
    }
  }
}

MotionPtr TimeWarpMotion::Speed(MotionPtr source, double speed) {
  const double d = source->Duration();
  return std::make_shared<TimeWarpMotion>(
      source, std::vector<std::pair<double, double>>{{0.0, 0.0}, {d / speed, d}});
}

namespace {
double Piecewise(const std::vector<std::pair<double, double>>& p, double x, bool forward) {
  auto in = [&](size_t i) { return forward ? p[i].first : p[i].second; };
  auto out = [&](size_t i) { return forward ? p[i].second : p[i].first; };
  size_t i = 1;
  while (i + 1 < p.size() && x > in(i)) ++i;
  const double u = (x - in(i - 1)) / (in(i) - in(i - 1));
  return out(i - 1) + u * (out(i) - out(i - 1));  // extrapolates linearly outside
}
}  // namespace

double TimeWarpMotion::SourceTime(double t) const { return Piecewise(points_, t, true); }
double TimeWarpMotion::OutputTime(double source_t) const { return Piecewise(points_, source_t, false); }

std::vector<MotionEvent> TimeWarpMotion::Events() const {
  std::vector<MotionEvent> events = source_->Events();
  for (MotionEvent& e : events) {
    e.start = OutputTime(e.start);
    e.end = OutputTime(e.end);
  }
  return events;
}

LayerMotion::LayerMotion(MotionPtr base, MotionPtr overlay, std::vector<int> joints)
    : MotionSource(base->name() + "+" + overlay->name()),
      base_(std::move(base)),
      overlay_(std::move(overlay)),
      joints_(std::move(joints)) {}

Pose LayerMotion::At(double t) const {
  Pose pose = base_->At(t);
  const Pose over = overlay_->At(t);
  for (int j : joints_) pose.local_rotation[j] = over.local_rotation[j];
  return pose;
}

std::vector<MotionEvent> LayerMotion::Events() const {
  std::vector<MotionEvent> all = base_->Events();
  for (const MotionEvent& e : overlay_->Events()) all.push_back(e);
  SortEvents(all);
  return all;
}

std::vector<MotionEvent> DelayMotion::Events() const { return Shifted(source_->Events(), delay_); }

}  // namespace irbench
