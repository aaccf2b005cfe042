#include "sim/gl/gl_context.h"

#include <gtest/gtest.h>

namespace irbench {
namespace {

// A core-profile context of OpenGL 3.3 or newer (asked of the context, not
// read from the version string, which only Mesa's says "Core Profile").
void ExpectCore33(const GlContext& context) {
  GLint major = 0, minor = 0, profile = 0;
  context.gl().GetIntegerv(GL_MAJOR_VERSION, &major);
  context.gl().GetIntegerv(GL_MINOR_VERSION, &minor);
  context.gl().GetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  EXPECT_GE(major * 10 + minor, 33) << context.RendererString();
  EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT) << context.RendererString();
}

// Both backends create a core context with the functions we use. Each runs in
// its own test process (ctest runs every test separately).
TEST(GlContextTest, EglSurfaceless) {
  auto context = CreateGlContext(GlBackend::kEgl);
  EXPECT_EQ(context->BackendName(), "egl");
  ExpectCore33(*context);
}

TEST(GlContextTest, OsMesaModule) {
  auto context = CreateGlContext(GlBackend::kOsMesa);
  EXPECT_EQ(context->BackendName(), "osmesa");
  ExpectCore33(*context);
}

// The GPU path never lands on Mesa's software renderer: on a machine without
// a GPU (CI) it refuses with the EGL devices it saw; with one, the context is
// the GPU's.
TEST(GlContextTest, GpuBackendIsAGpuOrAClearRefusal) {
  try {
    auto context = CreateGlContext(GlBackend::kGpu);
    EXPECT_EQ(context->BackendName(), "gpu");
    EXPECT_EQ(context->RendererString().find("llvmpipe"), std::string::npos) << context->RendererString();
    EXPECT_EQ(context->RendererString().find("softpipe"), std::string::npos) << context->RendererString();
    ExpectCore33(*context);
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_TRUE(what.find("no GPU among the EGL devices") != std::string::npos ||
                what.find("EGL") != std::string::npos)
        << what;
  }
}

TEST(GlContextTest, ParseBackend) {
  EXPECT_EQ(ParseGlBackend("egl"), GlBackend::kEgl);
  EXPECT_EQ(ParseGlBackend("osmesa"), GlBackend::kOsMesa);
  EXPECT_EQ(ParseGlBackend("auto"), GlBackend::kAuto);
  EXPECT_EQ(ParseGlBackend("gpu"), GlBackend::kGpu);
  EXPECT_FALSE(ParseGlBackend("vulkan").has_value());
  for (GlBackend b : {GlBackend::kAuto, GlBackend::kEgl, GlBackend::kOsMesa, GlBackend::kGpu}) {
    EXPECT_EQ(ParseGlBackend(GlBackendName(b)), b);
  }
}

}  // namespace
}  // namespace irbench
