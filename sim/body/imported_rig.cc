// What the format loaders share: prop names, base-colour textures (decoded by
// tinygltf's stb decoder, also for assimp's textures), albedo, transforms.

#include "sim/body/internal/imported_rig.h"

// tinygltf: the Debian shared library (TinyGLTF::TinyGLTF, built with stb and
// nlohmann json), as gltf_export.cc uses it; no TINYGLTF_IMPLEMENTATION here.
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>

#include "common/text.h"
#include "sim/body/internal/joint_naming.h"

namespace irbench::import_internal {

using Eigen::Matrix4d;
using Eigen::Vector3d;

// Whether a node, mesh or joint name looks like a prop (weapon, staff, ...).
bool IsProp(const std::string& name) {
  const std::string s = AsciiLower(name);
  for (const char* word : {"weapon", "staff", "sword", "shield", "prop", "gun", "tool"}) {
    if (s.find(word) != std::string::npos) return true;
  }
  return false;
}

// sRGB-encoded channel in [0, 1] -> linear.
float SrgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// A decoded tinygltf image (1..4 components, 8 or 16 bits, sRGB) -> linear RGB.
Texture MakeTexture(const tinygltf::Image& image) {
  Texture t;
  const int comp = image.component, bytes = image.bits / 8;
  if (image.width < 1 || image.height < 1 || comp < 1 || comp > 4 || (bytes != 1 && bytes != 2) ||
      image.image.size() < static_cast<size_t>(image.width) * image.height * comp * bytes) {
    return t;
  }
  t.width = image.width;
  t.height = image.height;
  t.linear.resize(static_cast<size_t>(t.width) * t.height);
  std::vector<float> lut(bytes == 1 ? 256 : 65536);
  for (size_t i = 0; i < lut.size(); ++i)
    lut[i] = SrgbToLinear(static_cast<float>(i) / (lut.size() - 1));
  for (size_t p = 0; p < t.linear.size(); ++p) {
    auto channel = [&](int c) {
      const unsigned char* q = &image.image[(p * comp + c) * bytes];
      return bytes == 1 ? lut[*q] : lut[q[0] | (q[1] << 8)];
    };
    const float r = channel(0);
    t.linear[p] = comp >= 3 ? Eigen::Vector3f(r, channel(1), channel(2)) : Eigen::Vector3f(r, r, r);
  }
  return t;
}

// Decodes PNG/JPEG bytes with tinygltf's stb decoder; empty when it cannot.
Texture DecodeTexture(const unsigned char* bytes, int size) {
  tinygltf::Image image;
  std::string err, warn;
  if (size <= 0 || !tinygltf::LoadImageData(&image, 0, &err, &warn, 0, 0, bytes, size, nullptr))
    return {};
  return MakeTexture(image);
}

// Bilinear, repeating; (u, v) with v = 0 at the top row.
Eigen::Vector3f Sample(const Texture& t, double u, double v) {
  const int w = t.width, h = t.height;
  const double x = (u - std::floor(u)) * w - 0.5, y = (v - std::floor(v)) * h - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  auto at = [&](int xi, int yi) {
    return t.linear[static_cast<size_t>(((yi % h) + h) % h) * w + ((xi % w) + w) % w];
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// 0.8 x Rec. 709 luminance of a linear RGB colour, clamped to [0, 1].
float AlbedoOf(const Eigen::Vector3f& linear_rgb) {
  const float y = 0.2126f * linear_rgb.x() + 0.7152f * linear_rgb.y() + 0.0722f * linear_rgb.z();
  return std::clamp(0.8f * y, 0.0f, 1.0f);
}

// The affine 4x4 `m` applied to the point `p`.
Vector3d Apply(const Matrix4d& m, const Vector3d& p) {
  return m.block<3, 3>(0, 0) * p + m.block<3, 1>(0, 3);
}

}  // namespace irbench::import_internal
