// The static scene's cache (RenderOptions::static_cache, docs/sensor.md): the
// static scene drawn once per camera, summarised per tile, and per frame the
// tiles the person's shadows may reach shaded again.

#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "sim/render/renderer_internal.h"

namespace irbench {
namespace {

// Extents in a shadow map's uv (min u, min v, max u, max v): none, and all.
const Eigen::Vector4f kNoUv(2, 2, -2, -2);
const Eigen::Vector4f kAllUv(-1e9f, -1e9f, 1e9f, 1e9f);

// Grows `box` by a point in front of the light, given in its clip coordinates.
void Extend(Eigen::Vector4f& box, const Eigen::Vector4f& clip) {
  const float u = clip.x() / clip.w() * 0.5f + 0.5f, v = clip.y() / clip.w() * 0.5f + 0.5f;
  box = Eigen::Vector4f(std::min(box[0], u), std::min(box[1], v), std::max(box[2], u), std::max(box[3], v));
}

// Whether non-empty `a`, `margin` wider on every side, meets `b`.
bool Meets(const Eigen::Vector4f& a, float margin, const Eigen::Vector4f& b) {
  return a[0] <= a[2] && a[0] - margin <= b[2] && a[2] + margin >= b[0] && a[1] - margin <= b[3] &&
         a[3] + margin >= b[1];
}

}  // namespace

void Renderer::UpdatePersonExtents() {
  // The person's extent in each shadow map (for its restore and the static
  // cache): all of it when a vertex lies behind the light, none when nobody
  // is drawn.
  person_boxes_.fill(kNoUv);
  person_nearest_.fill(-1e30f);
  const bool person_drawn = person_visible_ && person_index_count_ > 0;
  for (size_t k = 0; k < shadow_maps_.size() && person_drawn; ++k) {
    Eigen::Vector4f& box = person_boxes_[k];
    if (person_positions_.size() != person_vertex_count_) {
      box = kAllUv;
      continue;
    }
    float nearest = 1e30f;
    bool behind = false;
    for (const Eigen::Vector3f& p : person_positions_) {
      nearest = std::min(nearest, (shadow_maps_[k]->cam_from_world * p.homogeneous()).z());
      const Eigen::Vector4f clip = shadow_maps_[k]->clip_from_world * p.homogeneous();
      behind = !(clip.w() > 1e-6f);
      if (behind) break;
      Extend(box, clip);
    }
    if (behind) box = kAllUv;
    person_nearest_[k] = behind ? -1e30f : nearest;
  }
}

void Renderer::UpdateStaticCache() {
  if (!options_.static_cache || !static_cache_dirty_) return;
  // The static scene alone, shaded with the static shadow maps. The scene and
  // its lights do not move: a static pixel the person neither covers nor
  // shadows (no shadow tap near the person's texels) comes out the same in
  // every frame.
  const GlFunctions& gl = gl_;
  if (!shadow_maps_.empty()) {
    gl.ActiveTexture(GL_TEXTURE1);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, static_shadow_array_);
    gl.ActiveTexture(GL_TEXTURE0);
  }
  const float zero[4] = {0, 0, 0, 0};
  const float no_surface[4] = {0, 0, 0, -1};
  const float no_taps[4] = {-1e30f, -1e30f, -1e30f, -1e30f};
  // The world points and blocker depths are needed only until they are
  // summarised per tile: attached at full size while drawing, then detached
  // (a framebuffer's extent is its smallest attachment's) and shrunk to 1x1.
  const auto size_scratch = [&](Target& t, bool full) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, t.cache_fbo);
    for (int i : {3, 4}) {
      gl.BindTexture(GL_TEXTURE_2D, t.cache_tex[i]);
      gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, full ? t.render_camera.width : 1,
                    full ? t.render_camera.height : 1, 0, GL_RGBA, GL_FLOAT, nullptr);
      gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + i, GL_TEXTURE_2D, full ? t.cache_tex[i] : 0, 0);
    }
    gl.BindTexture(GL_TEXTURE_2D, 0);
  };
  for (const auto& target : targets_) {
    size_scratch(*target, true);
    BeginCameraPass(*target);
    for (int i = 0; i < 3; ++i) gl.ClearBufferfv(GL_COLOR, i, zero);
    gl.ClearBufferfv(GL_COLOR, 3, no_surface);
    gl.ClearBufferfv(GL_COLOR, 4, no_taps);
    gl.ClearBufferfi(GL_DEPTH_STENCIL, 0, 1.0f, 0);
    DrawStatic(gl.GetUniformLocation(program_, "u_person"));
    if (!shadow_maps_.empty()) TileStaticCache(*target);
    size_scratch(*target, false);
    target->restore = Eigen::Vector4i(0, 0, target->render_camera.width, target->render_camera.height);
  }
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  if (gl.GetError() != GL_NO_ERROR) throw RuntimeError("OpenGL error while drawing the static scene's cache");
  static_cache_dirty_ = false;
}

void Renderer::TileStaticCache(Target& t) {
  // The cache's world points and reach, read back once, summarised per tile.
  const GlFunctions& gl = gl_;
  const Camera& rc = t.render_camera;
  cv::Mat world(rc.height, rc.width, CV_32FC4);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT3);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadPixels(0, 0, rc.width, rc.height, GL_RGBA, GL_FLOAT, world.data);
  cv::Mat blocker_depth(rc.height, rc.width, CV_32FC4);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT4);
  gl.ReadPixels(0, 0, rc.width, rc.height, GL_RGBA, GL_FLOAT, blocker_depth.data);
  t.tiles_x = (rc.width + kStaticCacheTile - 1) / kStaticCacheTile;
  t.tiles_y = (rc.height + kStaticCacheTile - 1) / kStaticCacheTile;
  t.tile_uv.assign(size_t(t.tiles_x) * t.tiles_y, {kNoUv, kNoUv, kNoUv, kNoUv});
  t.tile_reach.assign(t.tile_uv.size(), 0.0f);
  t.tile_blocker_depth.assign(t.tile_uv.size(), Eigen::Vector4f::Constant(-1e30f));
  for (int y = 0; y < rc.height; ++y) {
    for (int x = 0; x < rc.width; ++x) {
      const cv::Vec4f& w = world.at<cv::Vec4f>(y, x);
      if (w[3] < 0) continue;  // no static surface
      const size_t tile = size_t(y / kStaticCacheTile) * t.tiles_x + x / kStaticCacheTile;
      t.tile_reach[tile] = std::max(t.tile_reach[tile], w[3]);
      const cv::Vec4f& z = blocker_depth.at<cv::Vec4f>(y, x);
      t.tile_blocker_depth[tile] = t.tile_blocker_depth[tile].cwiseMax(Eigen::Vector4f(z[0], z[1], z[2], z[3]));
      for (size_t k = 0; k < shadow_maps_.size(); ++k) {
        const Eigen::Vector4f clip = shadow_maps_[k]->clip_from_world * Eigen::Vector4f(w[0], w[1], w[2], 1.0f);
        if (clip.w() > 0) Extend(t.tile_uv[tile][k], clip);  // behind the light: no taps
      }
    }
  }
}

void Renderer::ShadeShadowedPixels(Target& t) {
  // Stencil 0 -> 1 on the static pixels (not the person's) of every tile
  // whose shadow taps may come within two texels of the person's extent in a
  // shadow map (the mark pass writes no colour), then the static scene drawn
  // again where it is the surface seen (equal depth) and marked: the first
  // fragment at that depth, as in a full draw (1 -> 2).
  const GlFunctions& gl = gl_;
  const Camera& rc = t.render_camera;
  const float texel = 1.0f / options_.shadow_map_size;
  std::vector<float> quads;
  Eigen::Vector4i marked = kNoPixels;  // their pixels' extent
  for (int ty = 0; ty < t.tiles_y; ++ty) {
    for (int tx = 0; tx < t.tiles_x; ++tx) {
      const size_t tile = size_t(ty) * t.tiles_x + tx;
      const float margin = t.tile_reach[tile] + 2 * texel;
      bool near = false;
      for (size_t k = 0; k < shadow_maps_.size() && !near; ++k) {
        // The person's texels are no nearer to the light than its nearest
        // vertex; one at least as far as every tap's comparison is no blocker
        // (1 cm of slack for rounding).
        near = t.tile_blocker_depth[tile][k] + 0.01f > person_nearest_[k] &&
               Meets(t.tile_uv[tile][k], margin, person_boxes_[k]);
      }
      if (!near) continue;
      marked = Union(marked, Eigen::Vector4i(tx * kStaticCacheTile, ty * kStaticCacheTile,
                                             std::min((tx + 1) * kStaticCacheTile, rc.width),
                                             std::min((ty + 1) * kStaticCacheTile, rc.height)));
      // The tile's pixels in normalised device coordinates.
      const auto ndc = [](int pixel, int size) { return 2.0f * std::min(pixel, size) / size - 1; };
      const float x0 = ndc(tx * kStaticCacheTile, rc.width), x1 = ndc((tx + 1) * kStaticCacheTile, rc.width);
      const float y0 = ndc(ty * kStaticCacheTile, rc.height), y1 = ndc((ty + 1) * kStaticCacheTile, rc.height);
      quads.insert(quads.end(), {x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1});
    }
  }
  if (quads.empty()) return;
  t.restore = Union(t.restore, marked);
  // Nothing outside the marked tiles is drawn: llvmpipe then skips the rest of
  // the frame's bins instead of testing the static scene's fragments there.
  gl.Enable(GL_SCISSOR_TEST);
  gl.Scissor(marked[0], marked[1], marked[2] - marked[0], marked[3] - marked[1]);
  gl.StencilFunc(GL_EQUAL, 0, 0xFF);
  gl.StencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  gl.Disable(GL_DEPTH_TEST);
  const GLenum none[] = {GL_NONE};
  gl.DrawBuffers(1, none);
  gl.UseProgram(mark_program_);
  gl.BindVertexArray(mark_vao_);
  gl.BindBuffer(GL_ARRAY_BUFFER, mark_vbo_);
  gl.BufferData(GL_ARRAY_BUFFER, quads.size() * sizeof(float), quads.data(), GL_STREAM_DRAW);
  gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(quads.size() / 2));
  gl.BindVertexArray(0);
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
  gl.DrawBuffers(3, buffers);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_EQUAL);
  gl.DepthMask(GL_FALSE);
  gl.StencilFunc(GL_EQUAL, 1, 0xFF);
  gl.StencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  gl.UseProgram(program_);
  DrawStatic(gl.GetUniformLocation(program_, "u_person"));
  gl.DepthMask(GL_TRUE);
  gl.DepthFunc(GL_LESS);
  gl.Disable(GL_SCISSOR_TEST);
}

}  // namespace irbench
