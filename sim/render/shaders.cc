#include "sim/render/shaders.h"

namespace irbench::shaders {

const char* const kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_material;  // albedo (850 nm), emissive
layout(location = 3) in vec2 a_extra;     // albedo at 940 nm (< 0: as 850), content emission
uniform mat4 u_clip_from_world;
uniform mat4 u_cam_from_world;
uniform vec3 u_camera_center;
// Bounce light (sim/lighting/bounce.h): irradiance onto +x, -x, +y, -y, +z, -z
// facing surfaces, channels 850 nm / 940 nm / screen content. It varies
// slowly, so it is read per vertex (static meshes are cut to short edges).
uniform sampler3D u_bounce[6];
uniform int u_bounce_on;
uniform vec3 u_bounce_origin;
uniform float u_bounce_spacing;
uniform vec3 u_bounce_dims;
out vec3 v_world;
out vec3 v_normal;
out vec2 v_material;
out vec2 v_extra;
out vec3 v_bounce;
out float v_depth;

vec3 Bounce(vec3 p, vec3 n) {
  vec3 uvw = ((p - u_bounce_origin) / u_bounce_spacing + 0.5) / u_bounce_dims;
  vec3 n2 = n * n;
  vec3 ex = n.x >= 0.0 ? textureLod(u_bounce[0], uvw, 0.0).rgb : textureLod(u_bounce[1], uvw, 0.0).rgb;
  vec3 ey = n.y >= 0.0 ? textureLod(u_bounce[2], uvw, 0.0).rgb : textureLod(u_bounce[3], uvw, 0.0).rgb;
  vec3 ez = n.z >= 0.0 ? textureLod(u_bounce[4], uvw, 0.0).rgb : textureLod(u_bounce[5], uvw, 0.0).rgb;
  return n2.x * ex + n2.y * ey + n2.z * ez;
}

void main() {
  vec4 p = vec4(a_position, 1.0);
  gl_Position = u_clip_from_world * p;
  v_world = a_position;
  v_normal = a_normal;
  v_material = a_material;
  v_extra = a_extra;
  v_bounce = vec3(0.0);
  if (u_bounce_on != 0) {
    // Two-sided: the side the camera sees.
    vec3 n = normalize(a_normal);
    if (dot(n, u_camera_center - a_position) < 0.0) n = -n;
    v_bounce = Bounce(a_position, n);
  }
  v_depth = (u_cam_from_world * p).z;
}
)";

const char* const kFragmentShader = R"(
in vec3 v_world;
in vec3 v_normal;
in vec2 v_material;
in vec2 v_extra;
in vec3 v_bounce;
in float v_depth;
uniform float u_person;
uniform vec3 u_camera_center;
uniform float u_ambient;
uniform int u_light_count;
uniform vec3 u_light_position[8];
uniform vec3 u_light_direction[8];
uniform float u_light_cos_half[8];
uniform float u_light_power[8];
uniform int u_light_band[8];  // 0: 850 nm, 1: 940 nm
uniform int u_light_shadow_slot[8];  // -1: no shadow map
uniform sampler2DArray u_shadow_maps;  // one layer per shadow slot
uniform mat4 u_shadow_clip_from_world[4];
uniform mat4 u_shadow_cam_from_world[4];
uniform float u_shadow_size_uv[4];  // light side / (2 tan(fov / 2))
uniform float u_shadow_texel[4];    // one texel in uv
layout(location = 0) out vec4 o_radiance;  // 850 nm, 940 nm, content, emission
layout(location = 1) out float o_mask;
layout(location = 2) out float o_depth;
// For the static scene's cache (Renderer::UpdateStaticCache): the surface's
// world point, and how far from its uv in any shadow map the taps read; per
// shadow slot, the largest depth a tap compares a shadow-map texel with (a
// texel at least that far from the light is no blocker; -1e30: no taps).
layout(location = 3) out vec4 o_world;
layout(location = 4) out vec4 o_blocker_depth;

#if SHADOWS
float ShadowDepth(int slot, vec2 uv) { return texture(u_shadow_maps, vec3(uv, float(slot))).r; }

// A point in a shadow map: uv, its camera-frame z there, and the receiver's
// depth gradient in uv (taken in uniform control flow).
struct ShadowPoint {
  bool in_front;
  vec2 uv;
  float z_r;
  vec2 dz_duv;
};

ShadowPoint InShadowMap(int slot, vec3 p) {
  ShadowPoint s;
  vec4 clip = u_shadow_clip_from_world[slot] * vec4(p, 1.0);
  s.in_front = clip.w > 0.0;
  s.uv = clip.xy / clip.w * 0.5 + 0.5;
  s.z_r = (u_shadow_cam_from_world[slot] * vec4(p, 1.0)).z;
  vec3 dx = dFdx(vec3(s.uv, s.z_r));
  vec3 dy = dFdy(vec3(s.uv, s.z_r));
  float det = dx.x * dy.y - dx.y * dy.x;
  vec2 dz_duv = abs(det) > 1e-12
      ? vec2(dy.y * dx.z - dx.y * dy.z, dx.x * dy.z - dy.x * dx.z) / det
      : vec2(0.0);
  s.dz_duv = clamp(dz_duv, vec2(-50.0 * s.z_r), vec2(50.0 * s.z_r));
  return s;
}

// Percentage-closer soft shadows for a square light: average the blockers'
// depth over the light's visibility pyramid, then filter over the pyramid's
// cross-section at that depth, so the penumbra grows as size * (z_r - z_b) / z_b.
// Depth comparisons follow the receiver's plane (its depth gradient in uv), so
// wide kernels do not shadow the receiver itself. `reach`: how far from uv
// (per axis) the taps read.
float Visibility(int slot, ShadowPoint s, int search_count, out float reach) {
  reach = 0.0;
  if (!s.in_front) return 1.0;
  vec2 uv = s.uv;
  float z_r = s.z_r;
  vec2 dz_duv = s.dz_duv;
  float texel = u_shadow_texel[slot];
  float bias = 0.01 + 0.004 * z_r;
  float size = u_shadow_size_uv[slot];
  float search = max(3.0 * size / z_r, 2.0 * texel);
  reach = search_count > 0 ? 0.5 * search : 0.0;
  float blockers = 0.0;
  float depth_sum = 0.0;
  for (int i = 0; i < search_count; ++i) {
      vec2 o = (vec2(i / 3, i % 3) / 2.0 - 0.5) * search;
      float d = ShadowDepth(slot, uv + o);
      if (d < z_r + dot(dz_duv, o) - bias) {
        depth_sum += d;
        blockers += 1.0;
      }
  }
  if (blockers == 0.0) return 1.0;
  float z_b = depth_sum / blockers;
  float width = max(size * (z_r - z_b) / (z_r * z_b), texel);
  reach = max(reach, 0.4 * width);
  float lit = 0.0;
  int count = blockers > 0.0 ? 25 : 0;
  for (int i = 0; i < count; ++i) {
      vec2 o = ((vec2(i / 5, i % 5) + 0.5) / 5.0 - 0.5) * width;
      lit += ShadowDepth(slot, uv + o) < z_r + dot(dz_duv, o) - bias ? 0.0 : 1.0;
  }
  return lit / 25.0;
}
#endif

void main() {
  vec3 n = normalize(v_normal);
  if (dot(n, u_camera_center - v_world) < 0.0) n = -n;  // two-sided
  vec4 radiance = vec4(0.0);
  o_world = vec4(v_world, 0.0);
  o_blocker_depth = vec4(-1e30);
  if (v_material.y > 0.5) {
    radiance.a = v_material.x;
  } else {
    // Irradiance per channel: illuminators at 850 and 940 nm, screen content.
    vec3 irradiance = vec3(u_ambient, 0.0, 0.0) + v_bounce;
    for (int i = 0; i < u_light_count; ++i) {
      vec3 to_light = u_light_position[i] - v_world;
      float d2 = max(dot(to_light, to_light), 0.25);
      vec3 l = to_light * inversesqrt(dot(to_light, to_light));
      float c = dot(-l, u_light_direction[i]);
      float cone = smoothstep(u_light_cos_half[i] - 0.05, u_light_cos_half[i] + 0.05, c);
      float lambert = max(dot(n, l), 0.0);
      float vis = 1.0;
      int slot = u_light_shadow_slot[i];
#if SHADOWS
      if (slot >= 0) {
        float reach;
        ShadowPoint s = InShadowMap(slot, v_world);
        vis = Visibility(slot, s, cone * lambert > 0.0 ? 9 : 0, reach);
        o_world.w = max(o_world.w, reach);
        o_blocker_depth[slot] = reach > 0.0 ? s.z_r + (abs(s.dz_duv.x) + abs(s.dz_duv.y)) * reach : -1e30;
      }
#endif
      float e = u_light_power[i] * cone * lambert * vis / d2;
      if (u_light_band[i] == 0) irradiance.x += e; else irradiance.y += e;
    }
    float r850 = v_material.x;
    float r940 = v_extra.x < 0.0 ? r850 : v_extra.x;
    radiance.rgb = vec3(r850, r940, 0.5 * (r850 + r940)) * irradiance;
    radiance.b += v_extra.y;
  }
  o_radiance = radiance;
  o_mask = u_person;
  o_depth = v_depth;
}
)";

// Shadow maps: camera-frame z of the nearest surface seen from the light.
const char* const kShadowVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_clip_from_world;
uniform mat4 u_cam_from_world;
out float v_z;
void main() {
  vec4 p = vec4(a_position, 1.0);
  gl_Position = u_clip_from_world * p;
  v_z = (u_cam_from_world * p).z;
}
)";

const char* const kShadowFragmentShader = R"(#version 330 core
in float v_z;
layout(location = 0) out float o_z;
void main() { o_z = v_z; }
)";

// The mark pass of the static scene's cache (Renderer::ShadeShadowedPixels):
// quads over the tiles of pixels the person's shadows may reach, stencil only.
const char* const kMarkVertexShader = R"(#version 330 core
layout(location = 0) in vec2 a_ndc;
void main() { gl_Position = vec4(a_ndc, 0.0, 1.0); }
)";

const char* const kMarkFragmentShader = R"(#version 330 core
void main() {}
)";

}  // namespace irbench::shaders
