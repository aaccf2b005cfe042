#pragma once
// The renderer's per-camera targets and shadow maps, shared by its two
// sources (renderer.cc: set-up and the draw; static_cache.cc: the static
// scene's cache). Not part of the library's interface.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "sim/render/renderer.h"

namespace irbench {

inline constexpr int kStaticCacheTile = 8;  // pixels per side of the static cache's tiles

// Boxes of pixels or texels: x0, y0, x1, y1, ends excluded; empty when
// x0 >= x1 or y0 >= y1.
inline const Eigen::Vector4i kNoPixels(1 << 30, 1 << 30, -(1 << 30), -(1 << 30));

inline bool Empty(const Eigen::Vector4i& box) { return box[0] >= box[2] || box[1] >= box[3]; }

// The smallest box holding `a` and `b` (either kNoPixels).
inline Eigen::Vector4i Union(const Eigen::Vector4i& a, const Eigen::Vector4i& b) {
  return Eigen::Vector4i(std::min(a[0], b[0]), std::min(a[1], b[1]), std::max(a[2], b[2]), std::max(a[3], b[3]));
}

// `box` clamped to a width x height target.
inline Eigen::Vector4i Clamp(const Eigen::Vector4i& box, int width, int height) {
  return box.cwiseMax(0).cwiseMin(Eigen::Vector4i(width, height, width, height));
}

// The pixels of a width x height target that uv extent `uv` (min u, min v,
// max u, max v; 0..1 across the target; empty when min > max) touches, two
// wider for rounding; clamped first, so a far-off extent cannot overflow.
inline Eigen::Vector4i PixelsOf(const Eigen::Vector4f& uv, int width, int height) {
  if (uv[0] > uv[2] || uv[1] > uv[3]) return kNoPixels;
  const auto at = [](float u, int size) {
    return static_cast<int>(std::floor(std::clamp(u * size, -4.0f, size + 4.0f)));
  };
  return Eigen::Vector4i(at(uv[0], width) - 2, at(uv[1], height) - 2, at(uv[2], width) + 3, at(uv[3], height) + 3);
}

struct Renderer::ShadowMap {
  unsigned fbo = 0, depth_rbo = 0;
  unsigned static_fbo = 0, static_depth_rbo = 0;  // the static scene alone
  Eigen::Matrix4f clip_from_world, cam_from_world;
  // Texels that may differ from the static
  // scene's: where the person was last drawn; all of them at first.
  Eigen::Vector4i dirty{0, 0, 1 << 30, 1 << 30};
};

struct Renderer::Target {
  Camera render_camera;  // the supersampled pinhole actually rasterised
  unsigned fbo = 0, grey_tex = 0, mask_tex = 0, depth_tex = 0, depth_rbo = 0;
  // The static scene alone, drawn once (UpdateStaticCache): what fbo's three
  // images and its depth hold before the person is drawn, and, until they are
  // summarised per tile (TileStaticCache), per pixel the surface's world point
  // with its shadow taps' reach and per shadow slot the deepest depth a tap
  // compares with. cache_tex: radiance, mask, depth, world point and reach,
  // blocker depths.
  unsigned cache_fbo = 0, cache_depth_rbo = 0;
  unsigned cache_tex[5] = {0, 0, 0, 0, 0};
  // Render pixels where fbo may differ from the cache: the extent of the
  // person and of the re-shaded tiles of the last frame; all of them after
  // the cache is drawn. Only these are copied back.
  Eigen::Vector4i restore{0, 0, 1 << 30, 1 << 30};
  // Per tile of kStaticCacheTile pixels a side (row-major), for
  // ShadeShadowedPixels: per shadow slot the uv extent of its static surfaces
  // (min u, min v, max u, max v; empty when min > max), how far their taps
  // read beyond it, and the largest depth a tap compares with per slot.
  int tiles_x = 0, tiles_y = 0;
  std::vector<std::array<Eigen::Vector4f, 4>> tile_uv;
  std::vector<float> tile_reach;
  std::vector<Eigen::Vector4f> tile_blocker_depth;
  cv::Mat map_x, map_y;  // output pixel -> render pixel
  cv::Mat raw_half, raw_radiance, raw_mask, raw_depth, blurred_mask;
  Eigen::Matrix4f clip_from_world;
};

}  // namespace irbench
