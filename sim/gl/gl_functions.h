#pragma once
// The OpenGL 3.3 core functions the renderer uses, as a table of pointers
// loaded from the current backend (eglGetProcAddress / OSMesaGetProcAddress).

#include <GL/glcorearb.h>

#include <functional>
#include <string>

namespace irbench {

#define IRBENCH_GL_FUNCTIONS(X)                                        \
  X(PFNGLGETSTRINGPROC, GetString)                                     \
  X(PFNGLGETERRORPROC, GetError)                                       \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                 \
  X(PFNGLVIEWPORTPROC, Viewport)                                       \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                             \
  X(PFNGLENABLEPROC, Enable)                                           \
  X(PFNGLDISABLEPROC, Disable)                                         \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                     \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                         \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                         \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)               \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)         \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)           \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                   \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                       \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                       \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                 \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                 \
  X(PFNGLGENTEXTURESPROC, GenTextures)                                 \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                                 \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                   \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                             \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                           \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                 \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                   \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                   \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                 \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                   \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                   \
  X(PFNGLBUFFERDATAPROC, BufferData)                                   \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                             \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                             \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                         \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                         \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                   \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)         \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                 \
  X(PFNGLCREATESHADERPROC, CreateShader)                               \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                               \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                             \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                 \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                       \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                             \
  X(PFNGLATTACHSHADERPROC, AttachShader)                               \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                 \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                               \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                     \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                   \
  X(PFNGLDELETESHADERPROC, DeleteShader)                               \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                             \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                   \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                       \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                     \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                     \
  X(PFNGLUNIFORM1IVPROC, Uniform1iv)                                   \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                   \
  X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                   \
  X(PFNGLUNIFORM1FVPROC, Uniform1fv)                                   \
  X(PFNGLDRAWELEMENTSPROC, DrawElements)                               \
  X(PFNGLFINISHPROC, Finish)                                           \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                             \
  X(PFNGLTEXIMAGE3DPROC, TexImage3D)                                   \
  X(PFNGLFRAMEBUFFERTEXTURELAYERPROC, FramebufferTextureLayer)       \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                         \
  X(PFNGLSTENCILFUNCPROC, StencilFunc)                                 \
  X(PFNGLSTENCILOPPROC, StencilOp)                                     \
  X(PFNGLSTENCILMASKPROC, StencilMask)                                 \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                     \
  X(PFNGLCLEARBUFFERFIPROC, ClearBufferfi)                             \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                                   \
  X(PFNGLSCISSORPROC, Scissor)

struct GlFunctions {
#define IRBENCH_GL_MEMBER(type, name) type name = nullptr;
  IRBENCH_GL_FUNCTIONS(IRBENCH_GL_MEMBER)
#undef IRBENCH_GL_MEMBER

  // Loads every function; throws RuntimeError naming the first one missing.
  void Load(const std::function<void*(const char*)>& get_proc);
};

}  // namespace irbench
