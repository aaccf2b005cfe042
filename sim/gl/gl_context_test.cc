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

TEST(GlContextTest, ParseBackend) {
  EXPECT_EQ(ParseGlBackend("egl"), GlBackend::kEgl);
  EXPECT_EQ(ParseGlBackend("osmesa"), GlBackend::kOsMesa);
  EXPECT_EQ(ParseGlBackend("auto"), GlBackend::kAuto);
  EXPECT_FALSE(ParseGlBackend("vulkan").has_value());
  for (GlBackend b : {GlBackend::kAuto, GlBackend::kEgl, GlBackend::kOsMesa}) {
    EXPECT_EQ(ParseGlBackend(GlBackendName(b)), b);
  }
}

}  // namespace
}  // namespace irbench
