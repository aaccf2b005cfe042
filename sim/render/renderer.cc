#include "sim/render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "sim/render/renderer_internal.h"
#include "sim/render/shaders.h"

namespace irbench {
namespace {

using shaders::kFragmentShader;
using shaders::kMarkFragmentShader;
using shaders::kMarkVertexShader;
using shaders::kShadowFragmentShader;
using shaders::kShadowVertexShader;
using shaders::kVertexShader;

unsigned CompileShader(const GlFunctions& gl, GLenum type, const char* source) {
  const unsigned shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    gl.GetShaderInfoLog(shader, sizeof(log), nullptr, log);
    throw RuntimeError(std::string("shader compilation failed: ") + log);
  }
  return shader;
}

unsigned LinkProgram(const GlFunctions& gl, const char* vertex, const char* fragment) {
  const unsigned vs = CompileShader(gl, GL_VERTEX_SHADER, vertex);
  const unsigned fs = CompileShader(gl, GL_FRAGMENT_SHADER, fragment);
  const unsigned program = gl.CreateProgram();
  gl.AttachShader(program, vs);
  gl.AttachShader(program, fs);
  gl.LinkProgram(program);
  GLint ok = 0;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    gl.GetProgramInfoLog(program, sizeof(log), nullptr, log);
    throw RuntimeError(std::string("shader link failed: ") + log);
  }
  gl.DeleteShader(vs);
  gl.DeleteShader(fs);
  return program;
}

// clip_from_cam for an OpenCV camera (x right, y down, z forward) whose pixel
// (u, v) centre lands on GL window pixel (u, v), rows in image order: the
// framebuffer's row 0 is the image's top row, so read-back needs no flip.
Eigen::Matrix4f ClipFromCam(const Camera& cam, double near_m, double far_m) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2 * cam.fx / cam.width;
  m(0, 2) = 2 * (cam.cx + 0.5) / cam.width - 1;
  m(1, 1) = 2 * cam.fy / cam.height;
  m(1, 2) = 2 * (cam.cy + 0.5) / cam.height - 1;
  m(2, 2) = (far_m + near_m) / (far_m - near_m);
  m(2, 3) = -2 * far_m * near_m / (far_m - near_m);
  m(3, 2) = 1;
  return m.cast<float>();
}

void SetupVertexLayout(const GlFunctions& gl) {
  const GLsizei stride = sizeof(MeshVertex);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride,
                         reinterpret_cast<void*>(offsetof(MeshVertex, position)));
  gl.EnableVertexAttribArray(1);
  gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride,
                         reinterpret_cast<void*>(offsetof(MeshVertex, normal)));
  gl.EnableVertexAttribArray(2);
  gl.VertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride,
                         reinterpret_cast<void*>(offsetof(MeshVertex, albedo)));
  gl.EnableVertexAttribArray(3);
  gl.VertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, stride,
                         reinterpret_cast<void*>(offsetof(MeshVertex, albedo_940)));
}

}  // namespace

void RenderOptions::Check() const {
  if (supersample < 1 || supersample > 4) throw InputError("", "supersample", "must be in 1..4");
  if (near_m <= 0 || far_m <= near_m) throw InputError("", "near_m", "need 0 < near < far");
  if (!(static_edge_m >= 0.05)) throw InputError("", "static_edge_m", "must be at least 0.05 m");
}


Renderer::Renderer(GlContext& context, std::vector<Camera> cameras, const RenderOptions& options)
    : context_(context), gl_(context.gl()), cameras_(std::move(cameras)), options_(options) {
  options_.Check();
  const GlFunctions& gl = gl_;
  // Without shadows the shadow code is compiled out: llvmpipe would otherwise
  // pay for its loops on every fragment.
  const std::string fragment = std::string("#version 330 core\n#define SHADOWS ") +
                               (options_.shadows ? "1" : "0") + "\n" + kFragmentShader;
  program_ = LinkProgram(gl, kVertexShader, fragment.c_str());
  shadow_program_ = LinkProgram(gl, kShadowVertexShader, kShadowFragmentShader);
  mark_program_ = LinkProgram(gl, kMarkVertexShader, kMarkFragmentShader);
  gl.GenVertexArrays(1, &mark_vao_);
  gl.BindVertexArray(mark_vao_);
  gl.GenBuffers(1, &mark_vbo_);
  gl.BindBuffer(GL_ARRAY_BUFFER, mark_vbo_);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  gl.BindVertexArray(0);
  gl.UseProgram(program_);
  SetLighting({}, 1.0);
  SetBounce(IrradianceVolume{});

  const int s = options_.supersample;
  for (const Camera& cam : cameras_) {
    if (double(cam.width) * cam.height * s * s < options_.static_cache_min_pixels) options_.static_cache = false;
  }
  for (const Camera& cam : cameras_) {
    auto target = std::make_unique<Target>();
    // Extent of the undistorted image of the output border, in output pixels.
    double u_min = 1e9, u_max = -1e9, v_min = 1e9, v_max = -1e9;
    auto extend = [&](double u, double v) {
      const auto x_u = cam.UndistortPixel({u, v});
      if (!x_u) throw InputError("", "cameras." + cam.name + ".dist", "distortion does not invert");
      const Eigen::Vector2d px_undistorted = cam.NormalisedToPixel(*x_u);
      const double pu = px_undistorted.x(), pv = px_undistorted.y();
      u_min = std::min(u_min, pu), u_max = std::max(u_max, pu);
      v_min = std::min(v_min, pv), v_max = std::max(v_max, pv);
    };
    for (int u = 0; u <= cam.width; ++u) {
      extend(u - 0.5, -0.5);
      extend(u - 0.5, cam.height - 0.5);
    }
    for (int v = 0; v <= cam.height; ++v) {
      extend(-0.5, v - 0.5);
      extend(cam.width - 0.5, v - 0.5);
    }
    const double ox = std::floor(u_min) - 1, oy = std::floor(v_min) - 1;
    const int nx = static_cast<int>(std::ceil(u_max) - ox) + 2;
    const int ny = static_cast<int>(std::ceil(v_max) - oy) + 2;
    Camera& rc = target->render_camera;
    rc = cam;
    rc.dist = {0, 0, 0, 0, 0};
    rc.width = nx * s;
    rc.height = ny * s;
    rc.fx = cam.fx * s;
    rc.fy = cam.fy * s;
    rc.cx = s * (cam.cx - ox + 0.5) - 0.5;
    rc.cy = s * (cam.cy - oy + 0.5) - 0.5;
    if (rc.width > 8192 || rc.height > 8192) {
      throw InputError("", "cameras." + cam.name, "field of view too wide to render");
    }
    target->map_x.create(cam.height, cam.width, CV_32FC1);
    target->map_y.create(cam.height, cam.width, CV_32FC1);
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        const auto x_u = cam.UndistortPixel(Eigen::Vector2d(u, v));
        const Eigen::Vector2d px_render = rc.NormalisedToPixel(*x_u);
        target->map_x.at<float>(v, u) = static_cast<float>(px_render.x());
        target->map_y.at<float>(v, u) = static_cast<float>(px_render.y());
      }
    }
    target->clip_from_world = ClipFromCam(rc, options_.near_m, options_.far_m) *
                              cam.cam_from_world.matrix().cast<float>();

    gl.GenFramebuffers(1, &target->fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, target->fbo);
    auto make_texture = [&](unsigned* tex, GLint internal, GLenum format, GLenum type, GLenum slot) {
      gl.GenTextures(1, tex);
      gl.BindTexture(GL_TEXTURE_2D, *tex);
      gl.TexImage2D(GL_TEXTURE_2D, 0, internal, rc.width, rc.height, 0, format, type, nullptr);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      gl.FramebufferTexture2D(GL_FRAMEBUFFER, slot, GL_TEXTURE_2D, *tex, 0);
    };
    make_texture(&target->grey_tex, GL_RGBA16F, GL_RGBA, GL_HALF_FLOAT, GL_COLOR_ATTACHMENT0);
    make_texture(&target->mask_tex, GL_R8, GL_RED, GL_UNSIGNED_BYTE, GL_COLOR_ATTACHMENT1);
    make_texture(&target->depth_tex, GL_R32F, GL_RED, GL_FLOAT, GL_COLOR_ATTACHMENT2);
    // Depth and stencil (the stencil marks the static pixels to shade again).
    const auto make_depth = [&](unsigned* rbo) {
      gl.GenRenderbuffers(1, rbo);
      gl.BindRenderbuffer(GL_RENDERBUFFER, *rbo);
      gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, rc.width, rc.height);
      gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, *rbo);
    };
    make_depth(&target->depth_rbo);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    gl.DrawBuffers(3, buffers);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw RuntimeError("framebuffer incomplete for camera " + cam.name);
    }
    if (options_.static_cache) {
      gl.GenFramebuffers(1, &target->cache_fbo);
      gl.BindFramebuffer(GL_FRAMEBUFFER, target->cache_fbo);
      make_texture(&target->cache_tex[0], GL_RGBA16F, GL_RGBA, GL_HALF_FLOAT, GL_COLOR_ATTACHMENT0);
      make_texture(&target->cache_tex[1], GL_R8, GL_RED, GL_UNSIGNED_BYTE, GL_COLOR_ATTACHMENT1);
      make_texture(&target->cache_tex[2], GL_R32F, GL_RED, GL_FLOAT, GL_COLOR_ATTACHMENT2);
      make_texture(&target->cache_tex[3], GL_RGBA32F, GL_RGBA, GL_FLOAT, GL_COLOR_ATTACHMENT3);
      make_texture(&target->cache_tex[4], GL_RGBA32F, GL_RGBA, GL_FLOAT, GL_COLOR_ATTACHMENT4);
      make_depth(&target->cache_depth_rbo);
      const GLenum cache_buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                      GL_COLOR_ATTACHMENT3, GL_COLOR_ATTACHMENT4};
      gl.DrawBuffers(5, cache_buffers);
      if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        throw RuntimeError("static cache framebuffer incomplete for camera " + cam.name);
      }
    }
    target->raw_half.create(rc.height, rc.width, CV_16FC4);
    target->raw_mask.create(rc.height, rc.width, CV_8UC1);
    target->raw_depth.create(rc.height, rc.width, CV_32FC1);
    targets_.push_back(std::move(target));
  }
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);

  for (auto [vao, vbo, ibo] : {std::tuple{&static_vao_, &static_vbo_, &static_ibo_},
                               std::tuple{&person_vao_, &person_vbo_, &person_ibo_}}) {
    gl.GenVertexArrays(1, vao);
    gl.BindVertexArray(*vao);
    gl.GenBuffers(1, vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, *vbo);
    gl.GenBuffers(1, ibo);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, *ibo);
    SetupVertexLayout(gl);
  }
  gl.BindVertexArray(0);
  if (gl.GetError() != GL_NO_ERROR) throw RuntimeError("OpenGL error while setting up the renderer");
}

Renderer::~Renderer() {
  const GlFunctions& gl = gl_;
  for (auto& t : targets_) {
    gl.DeleteFramebuffers(1, &t->fbo);
    gl.DeleteTextures(1, &t->grey_tex);
    gl.DeleteTextures(1, &t->mask_tex);
    gl.DeleteTextures(1, &t->depth_tex);
    gl.DeleteRenderbuffers(1, &t->depth_rbo);
    if (t->cache_fbo != 0) {
      gl.DeleteFramebuffers(1, &t->cache_fbo);
      gl.DeleteTextures(5, t->cache_tex);
      gl.DeleteRenderbuffers(1, &t->cache_depth_rbo);
    }
  }
  for (unsigned* b : {&static_vbo_, &static_ibo_, &person_vbo_, &person_ibo_}) gl.DeleteBuffers(1, b);
  if (bounce_textures_[0] != 0) gl.DeleteTextures(6, bounce_textures_);
  for (auto& m : shadow_maps_) {
    gl.DeleteFramebuffers(1, &m->fbo);
    gl.DeleteRenderbuffers(1, &m->depth_rbo);
    gl.DeleteFramebuffers(1, &m->static_fbo);
    gl.DeleteRenderbuffers(1, &m->static_depth_rbo);
  }
  if (shadow_array_ != 0) gl.DeleteTextures(1, &shadow_array_);
  if (static_shadow_array_ != 0) gl.DeleteTextures(1, &static_shadow_array_);
  gl.DeleteVertexArrays(1, &static_vao_);
  gl.DeleteVertexArrays(1, &person_vao_);
  gl.DeleteProgram(program_);
  gl.DeleteProgram(shadow_program_);
  gl.DeleteProgram(mark_program_);
  gl.DeleteVertexArrays(1, &mark_vao_);
  gl.DeleteBuffers(1, &mark_vbo_);
}

const Camera& Renderer::RenderCamera(int index) const { return targets_.at(index)->render_camera; }

void Renderer::SetScene(const Scene& scene) {
  SetStaticMesh(scene.mesh);
  SetLighting(scene.lights, scene.ambient);
  if (scene.bounce.bounces > 0) {
    BounceOptions options;
    options.bounces = scene.bounce.bounces;
    options.patch_m = scene.bounce.patch_m;
    options.grid_m = scene.bounce.grid_m;
    SetBounce(ComputeBounce(scene.mesh, scene.lights, options));
  } else {
    SetBounce(IrradianceVolume{});
  }
}

void Renderer::SetBounce(const IrradianceVolume& volume) {
  const GlFunctions& gl = gl_;
  gl.UseProgram(program_);
  if (bounce_textures_[0] == 0) gl.GenTextures(6, bounce_textures_);
  const size_t points = volume.empty() ? 0 : size_t(volume.dims.x()) * volume.dims.y() * volume.dims.z();
  for (int d = 0; d < 6; ++d) {
    gl.ActiveTexture(GL_TEXTURE2 + d);
    gl.BindTexture(GL_TEXTURE_3D, bounce_textures_[d]);
    const float zero[3] = {0, 0, 0};
    if (volume.empty()) {
      gl.TexImage3D(GL_TEXTURE_3D, 0, GL_RGB32F, 1, 1, 1, 0, GL_RGB, GL_FLOAT, zero);
    } else {
      gl.TexImage3D(GL_TEXTURE_3D, 0, GL_RGB32F, volume.dims.x(), volume.dims.y(), volume.dims.z(), 0, GL_RGB,
                    GL_FLOAT, volume.values.data() + d * points);
    }
    gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) {
      gl.TexParameteri(GL_TEXTURE_3D, wrap, GL_CLAMP_TO_EDGE);
    }
    gl.Uniform1i(gl.GetUniformLocation(program_, ("u_bounce[" + std::to_string(d) + "]").c_str()), 2 + d);
  }
  gl.ActiveTexture(GL_TEXTURE0);
  gl.Uniform1i(gl.GetUniformLocation(program_, "u_bounce_on"), volume.empty() ? 0 : 1);
  const Eigen::Vector3f origin = volume.origin.cast<float>();
  const Eigen::Vector3f dims = volume.empty() ? Eigen::Vector3f(Eigen::Vector3f::Ones()) : Eigen::Vector3f(volume.dims.cast<float>());
  gl.Uniform3fv(gl.GetUniformLocation(program_, "u_bounce_origin"), 1, origin.data());
  gl.Uniform1f(gl.GetUniformLocation(program_, "u_bounce_spacing"), static_cast<float>(volume.spacing));
  gl.Uniform3fv(gl.GetUniformLocation(program_, "u_bounce_dims"), 1, dims.data());
  static_cache_dirty_ = true;
  if (gl.GetError() != GL_NO_ERROR) throw RuntimeError("OpenGL error while uploading the bounce light");
}

namespace {

// Bisects every triangle's longest edge at its midpoint until no edge exceeds
// `max_edge`, so that per-vertex lighting (the bounce light) follows the
// surface. Whether an edge is split depends only on its length, so triangles
// sharing an edge split it at the same points: no T-junctions, no cracks.
void Bisect(const MeshVertex& a, const MeshVertex& b, const MeshVertex& c, float max_edge, TriangleMesh& out) {
  const float ab = (b.position - a.position).squaredNorm(), bc = (c.position - b.position).squaredNorm(),
              ca = (a.position - c.position).squaredNorm();
  const float longest = std::max({ab, bc, ca});
  if (longest <= max_edge * max_edge) {
    const uint32_t base = static_cast<uint32_t>(out.vertices.size());
    out.vertices.insert(out.vertices.end(), {a, b, c});
    out.indices.insert(out.indices.end(), {base, base + 1, base + 2});
    return;
  }
  auto midpoint = [](const MeshVertex& p, const MeshVertex& q) {
    MeshVertex m = p;
    m.position = 0.5f * (p.position + q.position);
    m.normal = (p.normal + q.normal).normalized();
    return m;
  };
  // Keep the winding: split the longest edge, each half with the opposite vertex.
  if (longest == ab) {
    const MeshVertex m = midpoint(a, b);
    Bisect(a, m, c, max_edge, out);
    Bisect(m, b, c, max_edge, out);
  } else if (longest == bc) {
    const MeshVertex m = midpoint(b, c);
    Bisect(a, b, m, max_edge, out);
    Bisect(a, m, c, max_edge, out);
  } else {
    const MeshVertex m = midpoint(c, a);
    Bisect(a, b, m, max_edge, out);
    Bisect(m, b, c, max_edge, out);
  }
}

TriangleMesh Tessellated(const TriangleMesh& mesh, double max_edge) {
  TriangleMesh out;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    Bisect(mesh.vertices[mesh.indices[t]], mesh.vertices[mesh.indices[t + 1]], mesh.vertices[mesh.indices[t + 2]],
           static_cast<float>(max_edge), out);
  }
  return out;
}

}  // namespace

void Renderer::SetStaticMesh(const TriangleMesh& input) {
  const TriangleMesh mesh = Tessellated(input, options_.static_edge_m);
  const GlFunctions& gl = gl_;
  gl.BindVertexArray(static_vao_);
  gl.BindBuffer(GL_ARRAY_BUFFER, static_vbo_);
  gl.BufferData(GL_ARRAY_BUFFER, mesh.vertices.size() * sizeof(MeshVertex), mesh.vertices.data(),
                GL_STATIC_DRAW);
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, mesh.indices.size() * sizeof(uint32_t), mesh.indices.data(),
                GL_STATIC_DRAW);
  static_index_count_ = static_cast<int>(mesh.indices.size());
  gl.BindVertexArray(0);
  shadows_dirty_ = true;
  static_shadows_dirty_ = true;
  static_cache_dirty_ = true;
}

void Renderer::SetLighting(const std::vector<IrLight>& lights, double ambient) {
  const GlFunctions& gl = gl_;
  gl.UseProgram(program_);
  const int n = static_cast<int>(std::min<size_t>(lights.size(), 8));
  gl.Uniform1f(gl.GetUniformLocation(program_, "u_ambient"), static_cast<float>(ambient));
  gl.Uniform1i(gl.GetUniformLocation(program_, "u_light_count"), n);
  std::vector<float> pos(24, 0), dir(24, 0), cos_half(8, 1), power(8, 0);
  std::vector<int> slot(8, -1), band(8, 0);
  std::vector<float> size_uv(4, 0), texel(4, 1);
  std::vector<Eigen::Matrix4f> shadow_clip(4, Eigen::Matrix4f::Identity()),
      shadow_cam(4, Eigen::Matrix4f::Identity());
  for (auto& m : shadow_maps_) {
    gl.DeleteFramebuffers(1, &m->fbo);
    gl.DeleteRenderbuffers(1, &m->depth_rbo);
    gl.DeleteFramebuffers(1, &m->static_fbo);
    gl.DeleteRenderbuffers(1, &m->static_depth_rbo);
  }
  shadow_maps_.clear();
  const int layers = static_cast<int>(std::clamp<long>(
      std::count_if(lights.begin(), lights.begin() + n, [](const IrLight& l) { return l.casts_shadows; }), 1, 4));
  if (options_.shadows && layers != shadow_layers_) {
    // A layer of camera-frame z per shadowing light (up to four; one when
    // none), and the same for the static scene alone.
    shadow_layers_ = layers;
    for (unsigned* array : {&shadow_array_, &static_shadow_array_}) {
      if (*array == 0) gl.GenTextures(1, array);
      gl.BindTexture(GL_TEXTURE_2D_ARRAY, *array);
      gl.TexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_R32F, options_.shadow_map_size, options_.shadow_map_size, layers,
                    0, GL_RED, GL_FLOAT, nullptr);
      gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
  }
  for (int i = 0; i < n; ++i) {
    const IrLight& light = lights[i];
    for (int k = 0; k < 3; ++k) {
      pos[3 * i + k] = static_cast<float>(light.position[k]);
      dir[3 * i + k] = static_cast<float>(light.direction[k]);
    }
    cos_half[i] = static_cast<float>(std::cos(light.cone_deg * M_PI / 360.0));
    power[i] = static_cast<float>(light.power);
    band[i] = light.wavelength_nm == 940.0 ? 1 : 0;
    if (!options_.shadows || !light.casts_shadows || shadow_maps_.size() >= 4) continue;
    // A pinhole "camera" at the light covering its cone.
    const double fov = std::min(light.cone_deg + 10.0, 150.0) * M_PI / 180.0;
    const int size = options_.shadow_map_size;
    Camera view;
    view.width = view.height = size;
    view.fx = view.fy = 0.5 * size / std::tan(fov / 2);
    view.cx = view.cy = 0.5 * (size - 1);
    const Eigen::Vector3d up =
        std::abs(light.direction.z()) > 0.9 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
    view.cam_from_world = *LookAt(light.position, light.position + light.direction, up);
    auto map = std::make_unique<ShadowMap>();
    map->cam_from_world = view.cam_from_world.matrix().cast<float>();
    map->clip_from_world = ClipFromCam(view, options_.near_m, options_.far_m) * map->cam_from_world;
    const auto make_target = [&](unsigned array, unsigned* fbo, unsigned* depth_rbo) {
      gl.GenFramebuffers(1, fbo);
      gl.BindFramebuffer(GL_FRAMEBUFFER, *fbo);
      gl.FramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, array, 0,
                                 static_cast<GLint>(shadow_maps_.size()));
      gl.GenRenderbuffers(1, depth_rbo);
      gl.BindRenderbuffer(GL_RENDERBUFFER, *depth_rbo);
      gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, size, size);
      gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, *depth_rbo);
      const GLenum buffers[] = {GL_COLOR_ATTACHMENT0};
      gl.DrawBuffers(1, buffers);
      gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
      if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        throw RuntimeError("shadow framebuffer incomplete");
      }
    };
    make_target(shadow_array_, &map->fbo, &map->depth_rbo);
    make_target(static_shadow_array_, &map->static_fbo, &map->static_depth_rbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    const int s = static_cast<int>(shadow_maps_.size());
    slot[i] = s;
    size_uv[s] = static_cast<float>(light.size_m / (2 * std::tan(fov / 2)));
    texel[s] = 1.0f / size;
    shadow_clip[s] = map->clip_from_world;
    shadow_cam[s] = map->cam_from_world;
    shadow_maps_.push_back(std::move(map));
  }
  gl.UseProgram(program_);
  gl.Uniform3fv(gl.GetUniformLocation(program_, "u_light_position"), 8, pos.data());
  gl.Uniform3fv(gl.GetUniformLocation(program_, "u_light_direction"), 8, dir.data());
  gl.Uniform1fv(gl.GetUniformLocation(program_, "u_light_cos_half"), 8, cos_half.data());
  gl.Uniform1fv(gl.GetUniformLocation(program_, "u_light_power"), 8, power.data());
  gl.Uniform1iv(gl.GetUniformLocation(program_, "u_light_band"), 8, band.data());
  for (int i = 0; i < 8; ++i) {
    gl.Uniform1i(gl.GetUniformLocation(program_, ("u_light_shadow_slot[" + std::to_string(i) + "]").c_str()),
                 slot[i]);
  }
  for (int k = 0; k < 4; ++k) {
    const std::string index = "[" + std::to_string(k) + "]";
    gl.UniformMatrix4fv(gl.GetUniformLocation(program_, ("u_shadow_clip_from_world" + index).c_str()), 1,
                        GL_FALSE, shadow_clip[k].data());
    gl.UniformMatrix4fv(gl.GetUniformLocation(program_, ("u_shadow_cam_from_world" + index).c_str()), 1,
                        GL_FALSE, shadow_cam[k].data());
  }
  gl.Uniform1i(gl.GetUniformLocation(program_, "u_shadow_maps"), 1);
  gl.Uniform1fv(gl.GetUniformLocation(program_, "u_shadow_size_uv"), 4, size_uv.data());
  gl.Uniform1fv(gl.GetUniformLocation(program_, "u_shadow_texel"), 4, texel.data());
  shadows_dirty_ = true;
  static_shadows_dirty_ = true;
  static_cache_dirty_ = true;
}

void Renderer::DrawPerson(int person_flag_location) {
  // A location of -1 (the shadow pass) makes Uniform1f a no-op.
  const GlFunctions& gl = gl_;
  if (person_visible_ && person_index_count_ > 0) {
    gl.Uniform1f(person_flag_location, 1.0f);
    gl.BindVertexArray(person_vao_);
    gl.DrawElements(GL_TRIANGLES, person_index_count_, GL_UNSIGNED_INT, nullptr);
  }
  gl.BindVertexArray(0);
}

void Renderer::DrawStatic(int person_flag_location) {
  const GlFunctions& gl = gl_;
  if (static_index_count_ > 0) {
    gl.Uniform1f(person_flag_location, 0.0f);
    gl.BindVertexArray(static_vao_);
    gl.DrawElements(GL_TRIANGLES, static_index_count_, GL_UNSIGNED_INT, nullptr);
  }
  gl.BindVertexArray(0);
}

void Renderer::UpdateShadows() {
  if (shadow_maps_.empty() || !shadows_dirty_) return;
  const GlFunctions& gl = gl_;
  gl.UseProgram(shadow_program_);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  const float far_value[4] = {1e9f, 0, 0, 0};
  const float one = 1.0f;
  const int size = options_.shadow_map_size;
  const auto set_view = [&](const ShadowMap& map) {
    gl.UniformMatrix4fv(gl.GetUniformLocation(shadow_program_, "u_clip_from_world"), 1, GL_FALSE,
                        map.clip_from_world.data());
    gl.UniformMatrix4fv(gl.GetUniformLocation(shadow_program_, "u_cam_from_world"), 1, GL_FALSE,
                        map.cam_from_world.data());
  };
  gl.Viewport(0, 0, size, size);
  if (static_shadows_dirty_) {
    for (const auto& map : shadow_maps_) {
      map->dirty = Eigen::Vector4i(0, 0, size, size);
      gl.BindFramebuffer(GL_FRAMEBUFFER, map->static_fbo);
      gl.ClearBufferfv(GL_COLOR, 0, far_value);
      gl.ClearBufferfv(GL_DEPTH, 0, &one);
      set_view(*map);
      DrawStatic(-1);
    }
    static_shadows_dirty_ = false;
  }
  UpdatePersonExtents();
  // Each frame: the static scene's z and depth copied where the person was
  // drawn last (the rest still holds them), then the person drawn over them
  // (ties between the person's and the scene's 24-bit depth, below 0.1 mm,
  // keep the scene).
  for (size_t k = 0; k < shadow_maps_.size(); ++k) {
    ShadowMap& map = *shadow_maps_[k];
    const Eigen::Vector4i r = Clamp(map.dirty, size, size);
    if (!Empty(r)) {
      gl.BindFramebuffer(GL_READ_FRAMEBUFFER, map.static_fbo);
      gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, map.fbo);
      gl.BlitFramebuffer(r[0], r[1], r[2], r[3], r[0], r[1], r[2], r[3], GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT,
                         GL_NEAREST);
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, map.fbo);
    set_view(map);
    DrawPerson(-1);
    // The texels drawn: those whose centres the person's projection covers,
    // inside its extent (two texels wider for rounding).
    map.dirty = PixelsOf(person_boxes_[k], size, size);
  }
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  shadows_dirty_ = false;
}

void Renderer::SetPersonTopology(const std::vector<uint32_t>& indices, size_t vertex_count) {
  const GlFunctions& gl = gl_;
  gl.BindVertexArray(person_vao_);
  gl.BindBuffer(GL_ARRAY_BUFFER, person_vbo_);
  gl.BufferData(GL_ARRAY_BUFFER, vertex_count * sizeof(MeshVertex), nullptr, GL_DYNAMIC_DRAW);
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, indices.size() * sizeof(uint32_t), indices.data(),
                GL_STATIC_DRAW);
  gl.BindVertexArray(0);
  person_index_count_ = static_cast<int>(indices.size());
  person_vertex_count_ = vertex_count;
}

void Renderer::UpdatePerson(const std::vector<MeshVertex>& vertices) {
  if (vertices.size() != person_vertex_count_) {
    throw RuntimeError("person vertex count differs from its topology");
  }
  const GlFunctions& gl = gl_;
  gl.BindBuffer(GL_ARRAY_BUFFER, person_vbo_);
  gl.BufferSubData(GL_ARRAY_BUFFER, 0, vertices.size() * sizeof(MeshVertex), vertices.data());
  person_positions_.resize(vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i) person_positions_[i] = vertices[i].position;
  shadows_dirty_ = true;
}

void Renderer::Render(int index, CameraImages* out, bool want_depth) {
  UpdateShadows();
  UpdateStaticCache();
  Draw(index);
  ReadBack(index);
  Resample(index, out, want_depth);
}

void Renderer::RenderAll(std::vector<CameraImages>* out, bool want_depth) {
  // Issue every camera's draw first: llvmpipe rasterises a framebuffer's scene
  // on its worker threads once the next framebuffer is bound, so the read-back
  // and resampling of one camera overlap the rasterisation of the others. The
  // GL calls stay on this thread; each camera's resampling (its own buffers,
  // its own output) runs on a thread of its own as soon as its pixels are back,
  // which on a GPU, where drawing is quick, is most of a frame-set's time.
  // (Reading back through pixel buffer objects was 20 % slower on an NVIDIA
  // H200 and no faster on llvmpipe.)
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  };
  out->resize(targets_.size());
  const Clock::time_point start = Clock::now();
  UpdateShadows();
  UpdateStaticCache();
  for (size_t i = 0; i < targets_.size(); ++i) Draw(static_cast<int>(i));
  const Clock::time_point drawn = Clock::now();
  std::vector<std::future<void>> resampled;
  resampled.reserve(targets_.size());
  for (size_t i = 0; i < targets_.size(); ++i) {
    ReadBack(static_cast<int>(i));
    resampled.push_back(std::async(std::launch::async, [this, i, out, want_depth] {
      Resample(static_cast<int>(i), &(*out)[i], want_depth);
    }));
  }
  const Clock::time_point read = Clock::now();
  for (std::future<void>& done : resampled) done.get();
  stage_times_.draw_s += seconds(start, drawn);
  stage_times_.read_back_s += seconds(drawn, read);
  stage_times_.resample_wait_s += seconds(read, Clock::now());
  ++stage_times_.frame_sets;
}

void Renderer::BeginCameraPass(const Target& t) {
  const GlFunctions& gl = gl_;
  const Camera& rc = t.render_camera;
  gl.Viewport(0, 0, rc.width, rc.height);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  gl.UseProgram(program_);
  gl.UniformMatrix4fv(gl.GetUniformLocation(program_, "u_clip_from_world"), 1, GL_FALSE,
                      t.clip_from_world.data());
  const Eigen::Matrix4f cam_from_world = rc.cam_from_world.matrix().cast<float>();
  gl.UniformMatrix4fv(gl.GetUniformLocation(program_, "u_cam_from_world"), 1, GL_FALSE,
                      cam_from_world.data());
  const Eigen::Vector3f center = rc.CenterInWorld().cast<float>();
  gl.Uniform3fv(gl.GetUniformLocation(program_, "u_camera_center"), 1, center.data());
}

void Renderer::Draw(int index) {
  const GlFunctions& gl = gl_;
  Target& t = *targets_.at(index);
  if (shadow_array_ != 0) {
    gl.ActiveTexture(GL_TEXTURE1);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, shadow_array_);
    gl.ActiveTexture(GL_TEXTURE0);
  }
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
  if (t.cache_fbo == 0) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
    BeginCameraPass(t);
    const float zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < 3; ++i) gl.ClearBufferfv(GL_COLOR, i, zero);
    gl.ClearBufferfi(GL_DEPTH_STENCIL, 0, 1.0f, 0);
    // Near to far: the person, then the scene (rooms last), for early depth
    // rejection.
    const int person_flag = gl.GetUniformLocation(program_, "u_person");
    DrawPerson(person_flag);
    DrawStatic(person_flag);
    return;
  }
  // The static scene's images and depth where the last frame drew over them
  // (the rest still holds them), then the person over them.
  const Camera& rc = t.render_camera;
  gl.BindFramebuffer(GL_READ_FRAMEBUFFER, t.cache_fbo);
  gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, t.fbo);
  if (const Eigen::Vector4i r = Clamp(t.restore, rc.width, rc.height); !Empty(r)) {
    for (int i = 0; i < 3; ++i) {
      GLenum one_buffer[] = {GL_NONE, GL_NONE, GL_NONE};
      one_buffer[i] = buffers[i];
      gl.ReadBuffer(buffers[i]);
      gl.DrawBuffers(3, one_buffer);
      gl.BlitFramebuffer(r[0], r[1], r[2], r[3], r[0], r[1], r[2], r[3], GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
    gl.BlitFramebuffer(r[0], r[1], r[2], r[3], r[0], r[1], r[2], r[3], GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT,
                       GL_NEAREST);
  }
  t.restore = kNoPixels;
  gl.DrawBuffers(3, buffers);
  gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  BeginCameraPass(t);
  if (!person_visible_ || person_index_count_ == 0) return;
  t.restore = PersonPixels(t);
  // As when the person is drawn first and the scene after it, both with a
  // LESS test: the person's nearest depth wins ties with the scene (a depth
  // pass, LEQUAL, stencil 2 where the person is), then the first of its
  // fragments at that depth is shaded (EQUAL, stencil 2 -> 3).
  const int person_flag = gl.GetUniformLocation(program_, "u_person");
  gl.Enable(GL_STENCIL_TEST);
  gl.StencilMask(0xFF);
  const GLenum none[] = {GL_NONE};
  gl.DrawBuffers(1, none);
  gl.DepthFunc(GL_LEQUAL);
  gl.StencilFunc(GL_ALWAYS, 2, 0xFF);
  gl.StencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  // Depth only: the shadow maps' program, whose vertex positions are the same
  // expression of the same matrix (the shading is not paid twice).
  gl.UseProgram(shadow_program_);
  gl.UniformMatrix4fv(gl.GetUniformLocation(shadow_program_, "u_clip_from_world"), 1, GL_FALSE,
                      t.clip_from_world.data());
  DrawPerson(-1);
  gl.UseProgram(program_);
  gl.DrawBuffers(3, buffers);
  gl.DepthFunc(GL_EQUAL);
  gl.DepthMask(GL_FALSE);
  gl.StencilFunc(GL_EQUAL, 2, 0xFF);
  gl.StencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  DrawPerson(person_flag);
  gl.DepthMask(GL_TRUE);
  gl.DepthFunc(GL_LESS);
  if (!shadow_maps_.empty()) ShadeShadowedPixels(t);
  gl.Disable(GL_STENCIL_TEST);
}

Eigen::Vector4i Renderer::PersonPixels(const Target& t) const {
  const Camera& rc = t.render_camera;
  const Eigen::Vector4i all(0, 0, rc.width, rc.height);
  if (person_positions_.size() != person_vertex_count_ || person_positions_.empty()) return all;
  // A triangle's pixels lie inside its vertices' extent unless the near plane
  // clips it (clip w is the camera-frame z).
  float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
  const float near = static_cast<float>(options_.near_m) * 1.01f;
  for (const Eigen::Vector3f& p : person_positions_) {
    const Eigen::Vector4f clip = t.clip_from_world * p.homogeneous();
    if (!(clip.w() > near)) return all;
    const float x = clip.x() / clip.w(), y = clip.y() / clip.w();
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
  }
  // Normalised device coordinates to window uv.
  return PixelsOf(Eigen::Vector4f(x0, y0, x1, y1) * 0.5f + Eigen::Vector4f::Constant(0.5f), rc.width, rc.height);
}

void Renderer::ReadBack(int index) {
  const GlFunctions& gl = gl_;
  Target& t = *targets_.at(index);
  const Camera& rc = t.render_camera;
  gl.BindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl.ReadPixels(0, 0, rc.width, rc.height, GL_RGBA, GL_HALF_FLOAT, t.raw_half.data);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT1);
  gl.ReadPixels(0, 0, rc.width, rc.height, GL_RED, GL_UNSIGNED_BYTE, t.raw_mask.data);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT2);
  gl.ReadPixels(0, 0, rc.width, rc.height, GL_RED, GL_FLOAT, t.raw_depth.data);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  if (gl.GetError() != GL_NO_ERROR) throw RuntimeError("OpenGL error while rendering");
}

void Renderer::Resample(int index, CameraImages* out, bool want_depth) {
  Target& t = *targets_.at(index);
  // Resample through the distortion. Grey: bilinear over the supersampled
  // image (a box filter when undistorted); mask: coverage >= 50%; depth: nearest.
  // The grey image is low-passed first (a Gaussian of 0.5 output pixels, about a
  // good lens's blur) so edges fall between supersamples instead of snapping
  // to them; this keeps sub-pixel corner positions unbiased and steady.
  // Half floats (11-bit mantissa: far below the shot noise) halve the
  // read-back; the blur works in float, in place (one image fewer per camera).
  t.raw_half.convertTo(t.raw_radiance, CV_32F);
  cv::GaussianBlur(t.raw_radiance, t.raw_radiance, cv::Size(0, 0), 0.5 * options_.supersample);
  cv::remap(t.raw_radiance, out->radiance, t.map_x, t.map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  // The plain grey image: every channel at level 1, 1 = 255.
  cv::transform(out->radiance, out->grey, cv::Matx14f(255.0f, 255.0f, 255.0f, 255.0f));
  out->grey.convertTo(out->grey, CV_8U);
  // At supersample 2 a bilinear sample at an output pixel centre is exactly the
  // mean of its 2x2 block (the coverage); otherwise a symmetric Gaussian
  // prefilter makes the 50% level fall on the true edge.
  cv::Mat coverage;
  const cv::Mat* mask_source = &t.raw_mask;
  if (options_.supersample != 2) {
    cv::GaussianBlur(t.raw_mask, t.blurred_mask, cv::Size(0, 0), 0.5 * options_.supersample);
    mask_source = &t.blurred_mask;
  }
  cv::remap(*mask_source, coverage, t.map_x, t.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::threshold(coverage, out->mask, 127, 255, cv::THRESH_BINARY);
  if (want_depth) {
    cv::remap(t.raw_depth, out->depth, t.map_x, t.map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  } else {
    out->depth.release();
  }
}

Visibility Renderer::PointVisibility(int index,
                                     const Eigen::Vector3d& p_in_world,
                                     double tolerance_m,
                                     bool require_person) const {
  const Camera& cam = cameras_.at(index);
  const Target& t = *targets_.at(index);
  const Eigen::Vector3d p_in_cam = cam.cam_from_world * p_in_world;
  if (p_in_cam.z() <= options_.near_m) return kOutside;
  const Eigen::Vector2d px = cam.ProjectInCamera(p_in_cam);
  if (px.x() < 0 || px.y() < 0 || px.x() > cam.width - 1 || px.y() > cam.height - 1) return kOutside;
  const Camera& rc = t.render_camera;
  const double qx = rc.fx * p_in_cam.x() / p_in_cam.z() + rc.cx;
  const double qy = rc.fy * p_in_cam.y() / p_in_cam.z() + rc.cy;
  const int ix = static_cast<int>(std::lround(qx)), iy = static_cast<int>(std::lround(qy));
  // Seen if any pinhole pixel within one output pixel shows a surface within
  // the tolerance of the point's depth — close enough in front of it, and not
  // far behind it (that pixel sees past the body) — and it is the person, when
  // required.
  const int r = options_.supersample;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const int x = ix + dx, y = iy + dy;
      if (x < 0 || y < 0 || x >= rc.width || y >= rc.height) continue;
      if (require_person && t.raw_mask.at<uint8_t>(y, x) < 128) continue;
      const float seen_depth = t.raw_depth.at<float>(y, x);
      if (seen_depth <= 0) continue;
      if (std::abs(seen_depth - p_in_cam.z()) <= tolerance_m) return kVisible;
    }
  }
  return kOccluded;
}

}  // namespace irbench
