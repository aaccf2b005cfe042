#pragma once
// The off-screen renderer: every camera into its own framebuffer, in one pass
// with three targets (radiance per light source, person mask, camera depth), at a
// supersampled pinhole resolution wide enough to cover the distorted image,
// then resampled through the camera's exact Brown–Conrady distortion on the
// CPU (docs/truth.md). The person mesh is uploaded once per frame and drawn by every camera.

#include <Eigen/Core>
#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "geometry/camera.h"
#include "sim/gl/gl_context.h"
#include "sim/lighting/bounce.h"
#include "sim/scene/mesh.h"
#include "sim/scene/scene.h"

namespace irbench {

struct RenderOptions {
  int supersample = 2;   // pinhole pixels per output pixel, per axis
  double near_m = 0.05;  // clip planes
  double far_m = 80.0;
  // Soft shadows of the scene's lights (up to 4 lights with `casts_shadows`),
  // penumbrae from each light's size (percentage-closer soft shadows).
  bool shadows = false;
  int shadow_map_size = 1024;
  // The static scene drawn once per camera and copied under the person each
  // frame; only the static pixels the person's shadows may change are shaded
  // again. The same pixels as without (off: everything drawn every frame).
  // Used only where every camera renders at least static_cache_min_pixels
  // (output pixels times supersample squared): on llvmpipe with two threads
  // the cache made 320x240 renders at supersample 1 twice as slow (4.4
  // frame-sets/s against 9.8 without, theater4, thesis preset) while it
  // speeds up 640x480 and larger render targets by half (docs/sensor.md).
  bool static_cache = true;
  int static_cache_min_pixels = 640 * 480;
  // The bounce light is read per vertex (it varies slowly); static meshes are
  // cut into triangles no longer than this for it. Finer costs llvmpipe more
  // partly covered pixel blocks than it gains.
  double static_edge_m = 2.0;

  // Throws InputError for bad values.
  void Check() const;
};

struct CameraImages {
  // CV_32FC4, relative radiance per source (1 = white under irradiance 1):
  // [0] the illuminators' light at 850 nm, [1] at 940 nm (each times the
  // surface's reflectance there), [2] the screens' content light (emitted and
  // reflected), [3] unlit emission (calibration boards). The sensor model
  // weighs and flickers them apart (docs/sensor.md).
  cv::Mat radiance;
  cv::Mat grey;   // CV_8UC1, the plain grey shading: 255 x the channels' sum
  cv::Mat mask;   // CV_8UC1, 255 where the person is seen, 0 else
  cv::Mat depth;  // CV_32FC1, camera z in metres (0: nothing); empty unless asked
};

// Joint visibility codes of the data contract.
enum Visibility : int { kOutside = 0, kOccluded = 1, kVisible = 2 };

class Renderer {
 public:
  Renderer(GlContext& context, std::vector<Camera> cameras, const RenderOptions& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Static geometry and lighting (uploaded once); computes the scene's bounce
  // light (sim/lighting/bounce.h) unless it has none.
  void SetScene(const Scene& scene);
  // The bounce light's irradiance volume; an empty one turns it off (the
  // default).
  void SetBounce(const IrradianceVolume& volume);
  void SetStaticMesh(const TriangleMesh& mesh);
  void SetLighting(const std::vector<IrLight>& lights, double ambient);

  // Person mesh: topology once, vertices once per frame.
  void SetPersonTopology(const std::vector<uint32_t>& indices, size_t vertex_count);
  void UpdatePerson(const std::vector<MeshVertex>& vertices);
  void SetPersonVisible(bool visible) {
    shadows_dirty_ = shadows_dirty_ || visible != person_visible_;
    person_visible_ = visible;
  }

  // Where RenderAll's time went since the last ResetStageTimes (s, summed).
  struct StageTimes {
    double draw_s = 0;           // shadow maps and every camera's draw calls
    double read_back_s = 0;      // the pixels' way back (waiting for the GL drawing)
    double resample_wait_s = 0;  // resampling still running after the last read-back
    int frame_sets = 0;
  };
  const StageTimes& stage_times() const { return stage_times_; }
  void ResetStageTimes() { stage_times_ = {}; }

  // Renders camera `index`; `out->depth` is filled only when `want_depth`.
  void Render(int index, CameraImages* out, bool want_depth);
  // Renders every camera, (*out)[i] for camera i; faster than one at a time.
  void RenderAll(std::vector<CameraImages>* out, bool want_depth);

  // Visibility of a world point in camera `index`, from that camera's last
  // render: kOutside when it projects outside the image (or behind the camera);
  // kVisible when the surface seen at its pixel lies no more than
  // `tolerance_m` in front of it (and, with `require_person`, is the person);
  // kOccluded otherwise.
  Visibility PointVisibility(int index,
                             const Eigen::Vector3d& p_in_world,
                             double tolerance_m,
                             bool require_person) const;

  const std::vector<Camera>& cameras() const { return cameras_; }
  // The pinhole camera actually rasterised for camera `index` (for tests).
  const Camera& RenderCamera(int index) const;

 private:
  struct Target;
  struct ShadowMap;
  void UpdateShadows();
  void UpdatePersonExtents();
  // The render pixels camera `t`'s draw of the person can touch (x0, y0, x1,
  // y1, ends excluded); all of them when a vertex lies near or behind it.
  Eigen::Vector4i PersonPixels(const Target& t) const;
  void UpdateStaticCache();
  void BeginCameraPass(const Target& t);
  void ShadeShadowedPixels(Target& t);
  void TileStaticCache(Target& t);
  void DrawPerson(int person_flag_location);
  void DrawStatic(int person_flag_location);
  void Draw(int index);
  // Reads camera `index`'s render targets back (GL; this thread).
  void ReadBack(int index);
  // Resamples camera `index`'s read-back pixels into `out` (no GL; any thread,
  // one per camera at a time).
  void Resample(int index, CameraImages* out, bool want_depth);
  GlContext& context_;
  const GlFunctions& gl_;
  std::vector<Camera> cameras_;
  RenderOptions options_;
  std::vector<std::unique_ptr<Target>> targets_;
  StageTimes stage_times_;
  unsigned program_ = 0;
  unsigned shadow_program_ = 0;
  std::vector<std::unique_ptr<ShadowMap>> shadow_maps_;
  unsigned shadow_array_ = 0;  // GL_TEXTURE_2D_ARRAY, a layer per shadow map
  int shadow_layers_ = 0;      // its layers (and the static array's)
  // The static scene's layers, drawn once per scene and lighting; each frame
  // starts from a copy of them and draws the person only.
  unsigned static_shadow_array_ = 0;
  bool static_shadows_dirty_ = true;
  bool static_cache_dirty_ = true;
  unsigned mark_program_ = 0, mark_vao_ = 0, mark_vbo_ = 0;
  // The person's extent in each shadow map (min u, min v, max u, max v).
  std::array<Eigen::Vector4f, 4> person_boxes_;
  // Its nearest camera-frame z from each shadow-mapped light.
  std::array<float, 4> person_nearest_;
  std::vector<Eigen::Vector3f> person_positions_;  // the last UpdatePerson's
  unsigned bounce_textures_[6] = {0, 0, 0, 0, 0, 0};  // GL_TEXTURE_3D, one per axis direction
  bool shadows_dirty_ = true;
  unsigned static_vao_ = 0, static_vbo_ = 0, static_ibo_ = 0;
  int static_index_count_ = 0;
  unsigned person_vao_ = 0, person_vbo_ = 0, person_ibo_ = 0;
  int person_index_count_ = 0;
  size_t person_vertex_count_ = 0;
  bool person_visible_ = true;
};

}  // namespace irbench
