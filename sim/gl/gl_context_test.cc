#include "sim/gl/gl_context.h"

#include <gtest/gtest.h>

namespace irbench {
namespace {

// Both backends create a core context with the functions we use. Each runs in
// its own test process (ctest runs every test separately).
TEST(GlContextTest, EglSurfaceless) {
  auto context = CreateGlContext(GlBackend::kEgl);
  EXPECT_EQ(context->BackendName(), "egl");
  EXPECT_NE(context->RendererString().find("Core Profile"), std::string::npos)
      << context->RendererString();
}

TEST(GlContextTest, OsMesaModule) {
  auto context = CreateGlContext(GlBackend::kOsMesa);
  EXPECT_EQ(context->BackendName(), "osmesa");
  EXPECT_NE(context->RendererString().find("Core Profile"), std::string::npos)
      << context->RendererString();
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
