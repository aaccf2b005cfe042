#pragma once
// The renderer's GLSL programs (sim/render/renderer.cc): the scene's shading,
// the shadow maps' depth, and the stencil marks of the static scene's cache.

namespace irbench::shaders {

extern const char* const kVertexShader;
extern const char* const kFragmentShader;  // after "#version" and "#define SHADOWS 0|1"
extern const char* const kShadowVertexShader;
extern const char* const kShadowFragmentShader;
extern const char* const kMarkVertexShader;
extern const char* const kMarkFragmentShader;

}  // namespace irbench::shaders
