#include "sim/body/parametric.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <unordered_map>

namespace irbench {
namespace {

using Vec3 = Eigen::Vector3d;

// Regions decide the albedo.
enum class Region { kSkin, kShirt, kPants, kShoes, kHair };

// Bone segment a primitive belongs to: the joint whose rotation moves it, the
// segment from that joint to the next along the body, and the joints its
// weights blend with at either end.
struct Segment {
  int bone = kPelvis;
  int parent = -1;  // blended in before the start (-1: none)
  int child = -1;   // blended in past the end (-1: none)
  Vec3 p0, p1;      // start (the joint) and end of the segment
  double blend0 = 0.02, blend1 = 0.02;  // half-widths of the blends, metres
};

struct Primitive {
  std::function<double(const Vec3&)> sdf;  // signed distance (approximate), metres
  int segment = 0;
  Region region = Region::kSkin;
  bool torso = false;  // weights follow height along the spine, not the segment
  Vec3 box_min, box_max;  // where the primitive can be within `reach` of the surface
  // The box as plain doubles: Sdf tests every grid point against every box,
  // and Eigen's accessors stay calls under the sanitizers (a third of a
  // body's build there).
  double lo[3] = {}, hi[3] = {};
};

double Smoothstep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Polynomial smooth minimum (blend radius k).
double SmoothMin(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * h * k / 6.0;
}

double EllipsoidSdf(const Vec3& p, const Vec3& c, const Vec3& r) {
  // Scaled-distance approximation (exact on the axes, a bound elsewhere).
  const Vec3 q = (p - c).cwiseQuotient(r);
  const double k0 = q.norm();
  const double k1 = (p - c).cwiseQuotient(r.cwiseProduct(r)).norm();
  return k1 > 1e-12 ? k0 * (k0 - 1.0) / k1 : -r.minCoeff();
}

// Capsule from a to b with radius varying linearly from ra to rb.
double ConeCapsuleSdf(const Vec3& p, const Vec3& a, const Vec3& b, double ra, double rb) {
  const Vec3 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm() - (ra + t * (rb - ra));
}

double RoundedBoxSdf(const Vec3& p, const Vec3& center, const Vec3& half, double round) {
  const Vec3 q = (p - center).cwiseAbs() - (half - Vec3::Constant(round));
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0) - round;
}

class BodyBuilder {
 public:
  BodyBuilder(const AvatarParams& params, const BodyShape& shape) : p_(params), s_(shape) {}

  Avatar Build() {
    Avatar avatar;
    avatar.params = p_;
    avatar.params.kind = "parametric";
    Skeleton(avatar);
    Primitives(avatar);
    Polygonise(avatar);
    Skin(avatar);
    TruthRadii(avatar);
    return avatar;
  }

 private:
  void Skeleton(Avatar& avatar) {
    const double h = p_.height_m;
    auto& b = avatar.skeleton.bind_position;
    const double ankle_z = 0.039 * h;
    const double hip_z = ankle_z + 0.461 * h * s_.leg_length;
    const double pelvis_z = hip_z + 0.030 * h;
    head_radius_ = Vec3(0.050, 0.060, 0.066) * h * s_.head_size;
    head_centre_ = Vec3(0, 0.004 * h, h - head_radius_.z());
    const double head_z = head_centre_.z() - 0.050 * h * s_.head_size;  // skull base (atlas)
    const double neck_z = head_z - 0.067 * h;
    b[kPelvis] = {0, 0, pelvis_z};
    b[kSpine] = {0, 0, pelvis_z + 0.243 * (neck_z - pelvis_z)};
    b[kChest] = {0, 0, pelvis_z + 0.625 * (neck_z - pelvis_z)};
    b[kNeck] = {0, 0, neck_z};
    b[kHead] = {0, 0, head_z};
    const double shoulder_z = neck_z - 0.006 * h;
    const double arm = s_.arm_length;
    for (int side : {+1, -1}) {
      const int clav = side > 0 ? kRightClavicle : kLeftClavicle;
      b[clav] = {side * 0.020 * h, 0, neck_z - 0.013 * h};
      b[clav + 1] = {side * 0.105 * h * s_.shoulder_width, 0, shoulder_z};
      b[clav + 2] = b[clav + 1] + Vec3(side * 0.172 * h * arm, 0, 0);
      b[clav + 3] = b[clav + 2] + Vec3(side * 0.157 * h * arm, 0, 0);
      const int hip = side > 0 ? kRightHip : kLeftHip;
      const double hx = 0.050 * h * s_.hip_width;
      b[hip] = {side * hx, 0, hip_z};
      b[hip + 1] = {side * (hx + 0.002 * h), 0, ankle_z + 0.534 * (hip_z - ankle_z)};
      b[hip + 2] = {side * (hx + 0.004 * h), 0, ankle_z};
    }
    hand_length_ = 0.108 * h * std::sqrt(arm);
    avatar.markers = {{"head", kHead, head_centre_ - b[kHead]},
                      {"right_hand_tip", kRightWrist, {hand_length_, 0, 0}},
                      {"left_hand_tip", kLeftWrist, {-hand_length_, 0, 0}}};
  }

  int AddSegment(Segment segment) {
    segments_.push_back(segment);
    return static_cast<int>(segments_.size()) - 1;
  }

  void Add(std::function<double(const Vec3&)> sdf, int segment, Region region, const Vec3& lo,
           const Vec3& hi, bool torso = false) {
    primitives_.push_back({std::move(sdf), segment, region, torso, lo, hi, {lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}});
  }

  // The body's primitives: torso, neck and head, then each side's arm and leg.
  void Primitives(const Avatar& avatar) {
    const double h = p_.height_m;
    const bool loose = s_.clothing == "loose_shirt", jacket = s_.clothing == "jacket";
    // How much clothing stands off the body on the clothed parts.
    const double cloth = jacket ? 0.014 * h : loose ? 0.010 * h : 0.0;
    TorsoPrimitives(avatar, cloth);
    HeadPrimitives(avatar);
    for (int side : {+1, -1}) {
      ArmPrimitives(avatar, side, cloth, jacket, loose);
      LegPrimitives(avatar, side, jacket);
    }
    blend_ = 0.012 * h;
  }

  // Torso segments and primitives: the lofted torso, buttocks and belly.
  void TorsoPrimitives(const Avatar& avatar, double cloth) {
    const double h = p_.height_m, g = p_.build;
    const auto& b = avatar.skeleton.bind_position;
    const Region top = Region::kShirt;
    // Torso segments (weights by height along the spine).
    const int seg_pelvis = AddSegment({kPelvis, -1, kSpine, b[kPelvis], b[kSpine], 0, 0.035 * h});
    AddSegment({kSpine, kPelvis, kChest, b[kSpine], b[kChest], 0.035 * h, 0.04 * h});
    AddSegment({kChest, kSpine, -1, b[kChest], b[kNeck], 0.04 * h, 0});
    // The lofted torso: elliptical sections from the crotch to the base of
    // the neck, after the tube avatar's profile (fractions of height at a
    // 1.75 m average body), remapped onto this skeleton.
    struct Section {
      double f, half_width, half_depth, y;  // f: 0 pelvis .. 1 neck base; negative below the pelvis
    };
    const std::vector<Section> sections = {
        {-0.26, 0.074, 0.050, -0.004}, {-0.14, 0.092, 0.060, -0.006}, {0.0, 0.097, 0.063, -0.006},
        {0.14, 0.090, 0.058, -0.002},  {0.28, 0.084, 0.056, 0.002},  {0.42, 0.087, 0.060, 0.004},
        {0.56, 0.095, 0.064, 0.006},   {0.69, 0.101, 0.066, 0.006},  {0.83, 0.102, 0.062, 0.002},
        {0.94, 0.090, 0.052, -0.004},  {1.0, 0.062, 0.040, -0.006}};
    const double z_pelvis = b[kPelvis].z(), span = b[kNeck].z() - z_pelvis;
    auto section_z = [&](double f) { return z_pelvis + f * span; };
    const double z_bottom = section_z(sections.front().f), z_top = section_z(sections.back().f);
    const double sw = s_.shoulder_width, hw = s_.hip_width;
    auto torso = [=, this](const Vec3& p) {
      const double f = std::clamp((p.z() - z_pelvis) / span, sections.front().f, sections.back().f);
      size_t i = 1;
      while (i + 1 < sections.size() && sections[i].f < f) ++i;
      const Section& a = sections[i - 1];
      const Section& c = sections[i];
      const double u = Smoothstep(0, 1, (f - a.f) / (c.f - a.f));
      const double width_ratio = f < 0.3 ? hw : (f > 0.6 ? sw : hw + (sw - hw) * (f - 0.3) / 0.3);
      const double half_w = (a.half_width + u * (c.half_width - a.half_width)) * h * g * width_ratio;
      const double belly = f > 0.05 && f < 0.5 ? 1.0 + s_.belly * 0.35 * std::sin(M_PI * (f - 0.05) / 0.45) : 1.0;
      const double half_d = (a.half_depth + u * (c.half_depth - a.half_depth)) * h * g * belly;
      const double yo = (a.y + u * (c.y - a.y)) * h + (belly - 1.0) * half_d * 0.5;
      const double rho = std::hypot(p.x() / half_w, (p.y() - yo) / half_d);
      double d = (rho - 1.0) * std::min(half_w, half_d);
      d = std::max({d, z_bottom - p.z(), p.z() - z_top});
      return d - (f > -0.1 ? cloth : 0.0);
    };
    const Vec3 torso_lo(-0.25 * h, -0.15 * h, z_bottom - 0.05 * h), torso_hi(0.25 * h, 0.2 * h, z_top + 0.05 * h);
    Add(torso, seg_pelvis, top, torso_lo, torso_hi, true);
    // Buttocks and, with a belly, the abdomen.
    for (int side : {+1, -1}) {
      const Vec3 c(side * 0.040 * h * hw, -0.040 * h * g, b[kRightHip].z() + 0.012 * h);
      const Vec3 r = Vec3(0.052 * hw, 0.045, 0.060) * h * g;
      Add([=](const Vec3& p) { return EllipsoidSdf(p, c, r) - cloth * 0.3; }, seg_pelvis, Region::kPants,
          c - r * 1.5, c + r * 1.5, true);
    }
    if (s_.belly > 0) {
      const Vec3 c(0, 0.03 * h * g, b[kSpine].z() - 0.01 * h);
      const Vec3 r = Vec3(0.080, 0.045 + 0.04 * s_.belly, 0.075) * h * g;
      Add([=](const Vec3& p) { return EllipsoidSdf(p, c, r) - cloth; }, seg_pelvis, top, c - r * 1.5,
          c + r * 1.5, true);
    }
  }

  // Neck, skull and jaw, with the neck and head segments.
  void HeadPrimitives(const Avatar& avatar) {
    const double h = p_.height_m, g = p_.build;
    const auto& b = avatar.skeleton.bind_position;
    // Neck, skull and jaw.
    const int seg_neck = AddSegment({kNeck, kChest, kHead, b[kNeck], b[kHead], 0.015 * h, 0.015 * h});
    const int seg_head = AddSegment({kHead, kNeck, -1, b[kHead], Vec3(0, 0, h), 0.015 * h, 0});
    {
      const Vec3 a = b[kNeck] - Vec3(0, 0.004 * h, 0.02 * h), c = b[kHead] + Vec3(0, 0.004 * h, 0.01 * h);
      const double r = 0.033 * h * std::sqrt(g);
      Add([=](const Vec3& p) { return ConeCapsuleSdf(p, a, c, r, r * 0.95); }, seg_neck, Region::kSkin,
          a.cwiseMin(c) - Vec3::Constant(2 * r), a.cwiseMax(c) + Vec3::Constant(2 * r));
      const Vec3 hc = head_centre_, hr = head_radius_;
      Add([=](const Vec3& p) { return EllipsoidSdf(p, hc, hr); }, seg_head, Region::kSkin, hc - hr * 1.5,
          hc + hr * 1.5);
      const Vec3 jc = hc + Vec3(0, 0.018 * h, -0.045 * h) * s_.head_size;
      const Vec3 jr = Vec3(0.036, 0.042, 0.036) * h * s_.head_size;
      Add([=](const Vec3& p) { return EllipsoidSdf(p, jc, jr); }, seg_head, Region::kSkin, jc - jr * 1.5,
          jc + jr * 1.5);
    }
  }

  // One side's (+1 right, -1 left) arm segments and primitives: shoulder
  // girdle, upper arm, forearm and hand.
  void ArmPrimitives(const Avatar& avatar, int side, double cloth, bool jacket, bool loose) {
    const double h = p_.height_m, g = p_.build;
    const auto& b = avatar.skeleton.bind_position;
    const Region top = Region::kShirt;
    const int clav = side > 0 ? kRightClavicle : kLeftClavicle;
    const int sh = clav + 1, el = clav + 2, wr = clav + 3;
    const Vec3 x(side, 0, 0);
    const int seg_clav = AddSegment({clav, kChest, sh, b[clav], b[sh], 0.02 * h, 0.025 * h});
    const int seg_upper = AddSegment({sh, clav, el, b[sh], b[el], 0.025 * h, 0.022 * h});
    const int seg_fore = AddSegment({el, sh, wr, b[el], b[wr], 0.022 * h, 0.012 * h});
    const int seg_hand = AddSegment({wr, el, -1, b[wr], b[wr] + x * hand_length_, 0.012 * h, 0});
    const double sleeve = jacket ? cloth : loose ? cloth : 0.0;
    const Region arm_region = s_.clothing == "tight" ? Region::kShirt : top;
    // Trapezius and shoulder girdle.
    {
      const Vec3 a = b[clav] + Vec3(0, -0.004 * h, 0.004 * h), c = b[sh] + Vec3(0, -0.004 * h, 0.006 * h);
      const double r0 = 0.038 * h * g, r1 = 0.036 * h * g;
      Add([=](const Vec3& p) { return ConeCapsuleSdf(p, a, c, r0, r1) - cloth; }, seg_clav, top,
          a.cwiseMin(c) - Vec3::Constant(2 * r0), a.cwiseMax(c) + Vec3::Constant(2 * r0));
      // Deltoid.
      const Vec3 dc = b[sh] + Vec3(side * 0.012 * h, 0, 0.002 * h);
      const Vec3 dr = Vec3(0.050, 0.040, 0.038) * h * g;
      Add([=](const Vec3& p) { return EllipsoidSdf(p, dc, dr) - sleeve; }, seg_upper, arm_region,
          dc - dr * 1.5, dc + dr * 1.5);
    }
    // Upper arm with a biceps bulge, forearm with its muscle near the elbow.
    {
      const Vec3 a = b[sh], c = b[el];
      const double r0 = 0.031 * h * g, r1 = 0.022 * h * g;
      Add([=](const Vec3& p) { return ConeCapsuleSdf(p, a, c, r0, r1) - sleeve; }, seg_upper, arm_region,
          a.cwiseMin(c) - Vec3::Constant(2 * r0), a.cwiseMax(c) + Vec3::Constant(2 * r0));
      const Vec3 bc = a + 0.45 * (c - a) + Vec3(0, 0.008 * h, 0), br = Vec3(0.060, 0.028, 0.026) * h * g;
      Add([=](const Vec3& p) { return EllipsoidSdf(p, bc, br) - sleeve; }, seg_upper, arm_region,
          bc - br * 1.5, bc + br * 1.5);
    }
    {
      const Vec3 a = b[el], c = b[wr];
      const double r0 = 0.022 * h * std::sqrt(g), r1 = 0.0145 * h;
      const double fs = jacket ? cloth : 0.0;
      const Region fore_region = jacket ? top : Region::kSkin;
      Add([=](const Vec3& p) { return ConeCapsuleSdf(p, a, c, r0, r1) - fs; }, seg_fore, fore_region,
          a.cwiseMin(c) - Vec3::Constant(2 * r0), a.cwiseMax(c) + Vec3::Constant(2 * r0));
      const Vec3 mc = a + 0.25 * (c - a), mr = Vec3(0.055, 0.024, 0.025) * h * std::sqrt(g);
      Add([=](const Vec3& p) { return EllipsoidSdf(p, mc, mr) - fs; }, seg_fore, fore_region, mc - mr * 1.5,
          mc + mr * 1.5);
    }
    // Hand, palm down: palm, fingers to the tip, and a thumb pointing forward.
    {
      const double L = hand_length_;
      const Vec3 palm_c = b[wr] + x * (0.28 * L), palm_h(0.24 * L, 0.022 * h, 0.0085 * h);
      const Vec3 fing_c = b[wr] + x * (0.745 * L) + Vec3(0, 0, -0.001 * h);
      const Vec3 fing_h(0.255 * L, 0.020 * h, 0.0060 * h);
      const Vec3 t0 = b[wr] + x * (0.18 * L) + Vec3(0, 0.016 * h, -0.003 * h);
      const Vec3 t1 = b[wr] + x * (0.55 * L) + Vec3(0, 0.042 * h, -0.004 * h);
      const double tr = 0.0062 * h;
      Add([=](const Vec3& p) {
            const double palm = RoundedBoxSdf(p, palm_c, palm_h, 0.007 * h);
            const double fingers = RoundedBoxSdf(p, fing_c, fing_h, 0.0055 * h);
            const double thumb = ConeCapsuleSdf(p, t0, t1, tr * 1.2, tr);
            return std::min({palm, fingers, thumb});
          },
          seg_hand, Region::kSkin, b[wr].cwiseMin(b[wr] + x * L) - Vec3::Constant(0.06 * h),
          b[wr].cwiseMax(b[wr] + x * L) + Vec3::Constant(0.06 * h));
    }
  }

  // One side's (+1 right, -1 left) leg segments and primitives: thigh, shin
  // and foot.
  void LegPrimitives(const Avatar& avatar, int side, bool jacket) {
    const double h = p_.height_m, g = p_.build;
    const auto& b = avatar.skeleton.bind_position;
    // Legs.
    const int hip = side > 0 ? kRightHip : kLeftHip;
    const int kn = hip + 1, an = hip + 2;
    const int seg_thigh = AddSegment({hip, kPelvis, kn, b[hip], b[kn], 0.03 * h, 0.025 * h});
    const int seg_shin = AddSegment({kn, hip, an, b[kn], b[an], 0.025 * h, 0.015 * h});
    const int seg_foot = AddSegment({an, kn, -1, b[an], b[an] + Vec3(0, 0.13 * h, -b[an].z()), 0.0, 0});
    const double trousers = jacket ? 0.004 * h : 0.002 * h;
    {
      const Vec3 a = b[hip] + Vec3(side * 0.004 * h, 0, 0.015 * h), c = b[kn];
      const double r0 = 0.055 * h * g, r1 = 0.033 * h * g;
      Add([=](const Vec3& p) { return ConeCapsuleSdf(p, a, c, r0, r1) - trousers; }, seg_thigh,
          Region::kPants, a.cwiseMin(c) - Vec3::Constant(2 * r0), a.cwiseMax(c) + Vec3::Constant(2 * r0));
    }
    {
      const Vec3 a = b[kn], c = b[an];
      const double r0 = 0.033 * h * g, r1 = 0.020 * h;
      Add([=](const Vec3& p) { return ConeCapsuleSdf(p, a, c, r0, r1) - trousers; }, seg_shin, Region::kPants,
          a.cwiseMin(c) - Vec3::Constant(2 * r0), a.cwiseMax(c) + Vec3::Constant(2 * r0));
      const Vec3 cc = a + 0.3 * (c - a) + Vec3(0, -0.012 * h, 0), cr = Vec3(0.030, 0.033, 0.075) * h * g;
      Add([=](const Vec3& p) { return EllipsoidSdf(p, cc, cr) - trousers; }, seg_shin, Region::kPants,
          cc - cr * 1.5, cc + cr * 1.5);
    }
    {
      // Foot: a rounded box from the heel to the toes, its sole on the floor.
      const Vec3 fc(b[an].x(), 0.045 * h, 0.024 * h), fh(0.026 * h, 0.083 * h, 0.024 * h);
      const Vec3 ac = b[an];
      const double ar = 0.021 * h;
      Add([=](const Vec3& p) {
            return std::min(RoundedBoxSdf(p, fc, fh, 0.012 * h), ConeCapsuleSdf(p, ac, ac + Vec3(0, 0.01 * h, -0.01 * h), ar, ar));
          },
          seg_foot, Region::kShoes, fc - fh - Vec3::Constant(0.05 * h), fc + fh + Vec3::Constant(0.05 * h));
    }
  }

  // The body's signed distance and the primitive that owns the point.
  double Sdf(const Vec3& p, int* owner = nullptr) const {
    double d = 1e9, best = 1e9;
    const double x = p.x(), y = p.y(), z = p.z();
    for (size_t i = 0; i < primitives_.size(); ++i) {
      const Primitive& prim = primitives_[i];
      if (x < prim.lo[0] || y < prim.lo[1] || z < prim.lo[2] || x > prim.hi[0] || y > prim.hi[1] || z > prim.hi[2]) {
        continue;
      }
      const double di = prim.sdf(p);
      d = d > 1e8 ? di : SmoothMin(d, di, blend_);
      if (di < best) {
        best = di;
        if (owner) *owner = static_cast<int>(i);
      }
    }
    return d;
  }

  // Marching tetrahedra over a regular grid (six tetrahedra per cube sharing
  // its main diagonal, a conforming subdivision), vertices shared on grid edges.
  void Polygonise(Avatar& avatar) {
    const double h = p_.height_m;
    const double cell = s_.cell_m > 0 ? s_.cell_m : h / 115.0;
    Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
    for (const Primitive& prim : primitives_) {
      lo = lo.cwiseMin(prim.box_min);
      hi = hi.cwiseMax(prim.box_max);
    }
    lo.z() = -2.5 * cell;  // half-cell offset: no grid plane on the floor
    const Eigen::Vector3i n = ((hi - lo) / cell).array().ceil().cast<int>() + 1;
    auto index = [&](int i, int j, int k) { return (int64_t(k) * n.y() + j) * n.x() + i; };
    std::vector<float> value(size_t(n.x()) * n.y() * n.z());
    for (int k = 0; k < n.z(); ++k) {
      for (int j = 0; j < n.y(); ++j) {
        for (int i = 0; i < n.x(); ++i) {
          double d = Sdf(lo + cell * Vec3(i, j, k));
          if (d == 0.0) d = 1e-9;  // no vertex exactly on the surface
          value[index(i, j, k)] = static_cast<float>(d);
        }
      }
    }
    auto position = [&](int64_t id) {
      const int i = int(id % n.x()), j = int((id / n.x()) % n.y()), k = int(id / (int64_t(n.x()) * n.y()));
      return Vec3(lo + cell * Vec3(i, j, k));
    };
    std::unordered_map<uint64_t, uint32_t> edge_vertex;
    auto vertex_on = [&](int64_t a, int64_t b) -> uint32_t {
      if (a > b) std::swap(a, b);
      const uint64_t key = uint64_t(a) * 0x9E3779B97F4A7C15ull ^ uint64_t(b);
      const auto it = edge_vertex.find(key);
      if (it != edge_vertex.end()) return it->second;
      const double va = value[a], vb = value[b];
      const Vec3 pa = position(a), pb = position(b);
      // Linear interpolation, then two secant steps on the true distance.
      double t = va / (va - vb);
      double fa = va, fb = vb, ta = 0, tb = 1;
      for (int it2 = 0; it2 < 2; ++it2) {
        const double f = Sdf(pa + t * (pb - pa));
        if ((f < 0) == (fa < 0)) { ta = t; fa = f; } else { tb = t; fb = f; }
        t = ta + (tb - ta) * fa / (fa - fb);
      }
      MeshVertex v;
      v.position = (pa + t * (pb - pa)).cast<float>();
      avatar.bind_vertices.push_back(v);
      const uint32_t id = static_cast<uint32_t>(avatar.bind_vertices.size() - 1);
      edge_vertex.emplace(key, id);
      return id;
    };
    auto emit = [&](uint32_t a, uint32_t b, uint32_t c, const Vec3& outward) {
      const auto& V = avatar.bind_vertices;
      const Eigen::Vector3f nrm = (V[b].position - V[a].position).cross(V[c].position - V[a].position);
      if (nrm.cast<double>().dot(outward) < 0) std::swap(b, c);
      avatar.indices.insert(avatar.indices.end(), {a, b, c});
    };
    static const int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                    {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
    for (int k = 0; k + 1 < n.z(); ++k) {
      for (int j = 0; j + 1 < n.y(); ++j) {
        for (int i = 0; i + 1 < n.x(); ++i) {
          int64_t corner[8];
          bool any_in = false, any_out = false;
          for (int c = 0; c < 8; ++c) {
            corner[c] = index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
            (value[corner[c]] < 0 ? any_in : any_out) = true;
          }
          if (!any_in || !any_out) continue;
          for (const auto& tet : kTets) {
            int64_t in[4], out[4];
            int n_in = 0, n_out = 0;
            for (int c : tet) (value[corner[c]] < 0 ? in[n_in++] : out[n_out++]) = corner[c];
            if (n_in == 0 || n_out == 0) continue;
            Vec3 cin = Vec3::Zero(), cout = Vec3::Zero();
            for (int m = 0; m < n_in; ++m) cin += position(in[m]) / n_in;
            for (int m = 0; m < n_out; ++m) cout += position(out[m]) / n_out;
            const Vec3 outward = cout - cin;
            if (n_in == 1 || n_out == 1) {
              const bool single_in = n_in == 1;
              const int64_t s = single_in ? in[0] : out[0];
              const int64_t* o = single_in ? out : in;
              emit(vertex_on(s, o[0]), vertex_on(s, o[1]), vertex_on(s, o[2]), outward);
            } else {
              const uint32_t a = vertex_on(in[0], out[0]), b = vertex_on(in[0], out[1]);
              const uint32_t c = vertex_on(in[1], out[1]), d = vertex_on(in[1], out[0]);
              emit(a, b, c, outward);
              emit(a, c, d, outward);
            }
          }
        }
      }
    }
    Simplify(avatar, 0.4 * cell);
    // Normals from the distance field's gradient; regions from the owner.
    const double e = 0.25 * cell;
    owner_.resize(avatar.bind_vertices.size());
    for (size_t v = 0; v < avatar.bind_vertices.size(); ++v) {
      MeshVertex& mv = avatar.bind_vertices[v];
      const Vec3 p = mv.position.cast<double>();
      Vec3 grad(Sdf(p + Vec3(e, 0, 0)) - Sdf(p - Vec3(e, 0, 0)), Sdf(p + Vec3(0, e, 0)) - Sdf(p - Vec3(0, e, 0)),
                Sdf(p + Vec3(0, 0, e)) - Sdf(p - Vec3(0, 0, e)));
      mv.normal = grad.normalized().cast<float>();
      int owner = 0;
      Sdf(p, &owner);
      owner_[v] = owner;
      mv.SetReflectance(Albedo(primitives_[owner].region, p));
      mv.emissive = 0.0f;
    }
  }

  // Collapses edges shorter than `min_length` (marching tetrahedra leaves many
  // where the surface passes near a grid point), shortest first, keeping the
  // mesh a closed manifold: an edge collapses only if the link condition holds
  // (the two ends share exactly the two opposite vertices), both ends keep a
  // valence above 3, and no surrounding triangle flips or degenerates. The
  // merged vertex is put back on the surface.
  void Simplify(Avatar& avatar, double min_length) {
    auto& V = avatar.bind_vertices;
    auto& F = avatar.indices;
    const size_t nf = F.size() / 3;
    std::vector<std::vector<uint32_t>> faces_of(V.size());
    for (size_t f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) faces_of[F[3 * f + k]].push_back(static_cast<uint32_t>(f));
    }
    std::vector<bool> face_alive(nf, true);
    std::vector<std::pair<float, std::pair<uint32_t, uint32_t>>> edges;
    for (size_t f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = F[3 * f + k], b = F[3 * f + (k + 1) % 3];
        if (a < b) {
          const float len = (V[a].position - V[b].position).norm();
          if (len < min_length) edges.push_back({len, {a, b}});
        }
      }
    }
    std::sort(edges.begin(), edges.end());
    auto neighbours = [&](uint32_t v) {
      std::vector<uint32_t> out;
      for (uint32_t f : faces_of[v]) {
        if (!face_alive[f]) continue;
        for (int k = 0; k < 3; ++k) {
          if (F[3 * f + k] != v) out.push_back(F[3 * f + k]);
        }
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
      return out;
    };
    auto normal = [&](uint32_t a, uint32_t b, uint32_t c, const Eigen::Vector3f& pa, const Eigen::Vector3f& pb,
                      const Eigen::Vector3f& pc) { return Eigen::Vector3f((pb - pa).cross(pc - pa)); };
    std::vector<bool> vertex_alive(V.size(), true);
    for (const auto& [len, edge] : edges) {
      const uint32_t a = edge.first, b = edge.second;
      if (!vertex_alive[a] || !vertex_alive[b]) continue;
      const auto na = neighbours(a), nb = neighbours(b);
      if (!std::binary_search(na.begin(), na.end(), b)) continue;  // no longer an edge
      if ((V[a].position - V[b].position).norm() >= min_length) continue;
      if (na.size() <= 3 || nb.size() <= 3) continue;
      std::vector<uint32_t> common;
      std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(common));
      if (common.size() != 2) continue;  // link condition
      // The merged point, on the surface.
      Vec3 p = 0.5 * (V[a].position + V[b].position).cast<double>();
      for (int it = 0; it < 2; ++it) {
        const double d = Sdf(p), e = 1e-4;
        const Vec3 g(Sdf(p + Vec3(e, 0, 0)) - d, Sdf(p + Vec3(0, e, 0)) - d, Sdf(p + Vec3(0, 0, e)) - d);
        if (g.norm() > 0) p -= d * g / g.squaredNorm() * e;
      }
      const Eigen::Vector3f pf = p.cast<float>();
      // No flipped or degenerate triangle around either end.
      bool ok = true;
      for (uint32_t v : {a, b}) {
        for (uint32_t f : faces_of[v]) {
          if (!face_alive[f]) continue;
          const uint32_t* t = &F[3 * f];
          const bool shared = (t[0] == a || t[1] == a || t[2] == a) && (t[0] == b || t[1] == b || t[2] == b);
          if (shared) continue;
          Eigen::Vector3f q[3];
          for (int k = 0; k < 3; ++k) q[k] = (t[k] == a || t[k] == b) ? pf : V[t[k]].position;
          const Eigen::Vector3f before = normal(t[0], t[1], t[2], V[t[0]].position, V[t[1]].position, V[t[2]].position);
          const Eigen::Vector3f after = normal(t[0], t[1], t[2], q[0], q[1], q[2]);
          if (after.norm() < 1e-12f || before.dot(after) <= 0.3f * before.norm() * after.norm()) ok = false;
        }
      }
      if (!ok) continue;
      // Collapse b into a.
      V[a].position = pf;
      for (uint32_t f : faces_of[b]) {
        if (!face_alive[f]) continue;
        uint32_t* t = &F[3 * f];
        if (t[0] == a || t[1] == a || t[2] == a) {
          face_alive[f] = false;  // one of the two faces on the edge
          continue;
        }
        for (int k = 0; k < 3; ++k) {
          if (t[k] == b) t[k] = a;
        }
        faces_of[a].push_back(f);
      }
      vertex_alive[b] = false;
    }
    // Compact.
    std::vector<uint32_t> remap(V.size(), UINT32_MAX);
    std::vector<MeshVertex> kept;
    for (size_t v = 0; v < V.size(); ++v) {
      if (!vertex_alive[v]) continue;
      remap[v] = static_cast<uint32_t>(kept.size());
      kept.push_back(V[v]);
    }
    std::vector<uint32_t> indices;
    for (size_t f = 0; f < nf; ++f) {
      if (!face_alive[f]) continue;
      for (int k = 0; k < 3; ++k) indices.push_back(remap[F[3 * f + k]]);
    }
    V = std::move(kept);
    F = std::move(indices);
  }

  NirReflectance Albedo(Region region, const Vec3& p) const {
    switch (region) {
      case Region::kShirt: return p_.shirt_albedo;
      case Region::kPants: return p_.pants_albedo;
      case Region::kShoes: return p_.shoe_albedo;
      case Region::kHair: return p_.hair_albedo;
      default: break;
    }
    // Hair: the skull above the brow and behind the face.
    const Vec3 q = p - head_centre_;
    if (q.z() > -0.2 * head_radius_.z() && (q.z() > 0.35 * head_radius_.z() || q.y() < 0.2 * head_radius_.y()) &&
        p.z() > head_centre_.z() - 0.5 * head_radius_.z()) {
      return p_.hair_albedo;
    }
    return p_.skin_albedo;
  }

  void Skin(Avatar& avatar) {
    const size_t nv = avatar.bind_vertices.size();
    avatar.bone_index.assign(nv, {0, 0, 0, 0});
    avatar.bone_weight.assign(nv, {1, 0, 0, 0});
    for (size_t v = 0; v < nv; ++v) {
      const Vec3 p = avatar.bind_vertices[v].position.cast<double>();
      const Primitive& prim = primitives_[owner_[v]];
      int seg_id = prim.segment;
      if (prim.torso) {
        // Torso parts: the spine segment at this height.
        seg_id = 0;
        for (int s = 0; s < 3; ++s) {
          if (p.z() >= segments_[s].p0.z()) seg_id = s;
        }
      }
      const Segment& s = segments_[seg_id];
      const Vec3 axis = (s.p1 - s.p0).normalized();
      const double len = (s.p1 - s.p0).norm();
      const double along = (p - s.p0).dot(axis);
      std::array<std::pair<int, double>, 3> w = {{{s.bone, 1.0}, {s.parent, 0.0}, {s.child, 0.0}}};
      if (s.parent >= 0 && s.blend0 > 0) {
        const double in = Smoothstep(-s.blend0, s.blend0, along);
        w[1].second = 1.0 - in;
        w[0].second = in;
      }
      if (s.child >= 0 && s.blend1 > 0) {
        const double past = Smoothstep(-s.blend1, s.blend1, along - len);
        w[2].second = past * w[0].second;
        w[0].second *= 1.0 - past;
      }
      if (s.bone == kRightAnkle || s.bone == kLeftAnkle) {
        // The top of the foot blends into the shin.
        const double up = 0.5 * Smoothstep(s.p0.z() - 0.015 * p_.height_m, s.p0.z() + 0.02 * p_.height_m, p.z());
        w[1].second = up;
        w[0].second = 1.0 - up;
      }
      double total = 0;
      for (const auto& [bone, weight] : w) total += bone >= 0 ? weight : 0.0;
      int slot = 0;
      for (const auto& [bone, weight] : w) {
        if (bone < 0 || weight <= 0) continue;
        avatar.bone_index[v][slot] = static_cast<uint8_t>(bone);
        avatar.bone_weight[v][slot] = static_cast<float>(weight / total);
        ++slot;
      }
    }
  }

  void TruthRadii(Avatar& avatar) {
    // How deep each truth point lies: its distance to the surface.
    const auto& b = avatar.skeleton.bind_position;
    auto depth = [&](const Vec3& p) { return std::max(0.0, -Sdf(p)); };
    avatar.truth_radius = {{"root", 0.0},
                           {"waist", depth(b[kSpine])},
                           {"neck", depth(b[kNeck])},
                           {"head", depth(head_centre_)},
                           {"shoulder", depth(b[kRightShoulder])},
                           {"elbow", depth(b[kRightElbow])},
                           {"wrist", depth(b[kRightWrist])},
                           {"hand_tip", 0.010 * p_.height_m},
                           {"hip", depth(b[kRightHip])},
                           {"knee", depth(b[kRightKnee])},
                           {"ankle", depth(b[kRightAnkle])}};
  }

  AvatarParams p_;
  BodyShape s_;
  Vec3 head_centre_, head_radius_;
  double hand_length_ = 0;
  double blend_ = 0.02;
  std::vector<Segment> segments_;
  std::vector<Primitive> primitives_;
  std::vector<int> owner_;
};

}  // namespace

Avatar BuildParametricAvatar(const AvatarParams& params, const BodyShape& shape) {
  return BodyBuilder(params, shape).Build();
}

}  // namespace irbench
