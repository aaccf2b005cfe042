#include "sim/scene/scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "common/error.h"
#include "sim/scene/materials.h"

namespace irbench {
namespace {

std::vector<Scene> AllScenes() {
  std::vector<Scene> scenes;
  for (const auto& e : std::filesystem::directory_iterator(std::string(IRBENCH_SOURCE_DIR) + "/scenes")) {
    if (e.path().extension() == ".json") scenes.push_back(LoadScene(e.path()));
  }
  return scenes;
}

TEST(SceneTest, ShippedScenesLoadWithScreensAndTargets) {
  const auto scenes = AllScenes();
  std::set<std::string> names;
  for (const Scene& s : scenes) {
    names.insert(s.name);
    EXPECT_GT(s.mesh.TriangleCount(), 10u) << s.name;
    ASSERT_FALSE(s.screens.empty()) << s.name;
    for (const ScreenSurface& screen : s.screens) EXPECT_FALSE(screen.targets.empty()) << s.name;
    EXPECT_FALSE(s.lights.empty()) << s.name;
  }
  EXPECT_TRUE(names.count("theater") && names.count("flatworld") && names.count("lab"));
}

// A ray from the stage to each target's world point hits the screen at that
// target's screen coordinates, and the nearest target is the target itself.
TEST(SceneTest, RaysToTargetsHitTheirScreenCoordinates) {
  for (const Scene& s : AllScenes()) {
    const Eigen::Vector3d eye(s.stage_center.x(), s.stage_center.y(), 1.6);
    for (const ScreenSurface& screen : s.screens) {
      for (const auto& [name, st] : screen.targets) {
        const Eigen::Vector3d p = screen.PointAt(st);
        const auto hit = screen.Intersect(eye, (p - eye).normalized());
        ASSERT_TRUE(hit.has_value()) << s.name << "/" << name;
        EXPECT_NEAR(hit->x(), st.x(), 1e-9);
        EXPECT_NEAR(hit->y(), st.y(), 1e-9);
        EXPECT_EQ(screen.NearestTarget(*hit), name);
      }
    }
  }
}

}  // namespace
}  // namespace irbench

namespace irbench {
namespace {

std::filesystem::path WriteScene(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("irbench_scene_test_" + std::to_string(::getpid()) + "_" + name + ".json");
  std::ofstream(path) << text;
  return path;
}

// Reflectances: a number is grey, a name comes from the table, a pair gives
// both wavelengths; a screen's content light is read; bad values name the field.
TEST(SceneMaterialTest, NamesPairsAndNumbers) {
  const auto path = WriteScene("materials", R"({"format": "irbench.scene/1", "name": "m", "bounce": {"bounces": 1},
    "objects": [{"type": "quad", "name": "a", "origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0], "albedo": "skin_light"},
                {"type": "quad", "name": "b", "origin": [0, 0, 1], "u": [1, 0, 0], "v": [0, 1, 0], "albedo": {"850": 0.4, "940": 0.2}},
                {"type": "quad", "name": "c", "origin": [0, 0, 2], "u": [1, 0, 0], "v": [0, 1, 0], "albedo": 0.3}],
    "screens": [{"name": "s", "type": "plane", "origin": [0, 3, 0], "right": [1, 0, 0], "up": [0, 0, 1],
                 "width": 2, "height": 1, "albedo": "projection_screen", "content_radiance": 0.4}]})");
  const Scene scene = LoadScene(path);
  EXPECT_EQ(scene.bounce.bounces, 1);
  EXPECT_EQ(scene.mesh.vertices[0].Reflectance(), (NirReflectance{0.60f, 0.55f}));
  EXPECT_EQ(scene.mesh.vertices[4].Reflectance(), (NirReflectance{0.4f, 0.2f}));
  EXPECT_EQ(scene.mesh.vertices[8].Reflectance(), NirReflectance::Grey(0.3f));
  EXPECT_FLOAT_EQ(scene.mesh.vertices[12].content, 0.4f);
  EXPECT_EQ(scene.mesh.vertices[12].Reflectance(), (NirReflectance{0.85f, 0.84f}));
  for (const NirMaterial& m : NirMaterials()) {
    EXPECT_GT(m.reflectance.at_850, 0.0f) << m.name;
    EXPECT_LE(m.reflectance.at_850, 1.0f) << m.name;
    EXPECT_LE(m.reflectance.at_940, 1.0f) << m.name;
  }
  auto error_of = [](const std::string& name, const std::string& albedo) {
    try {
      LoadScene(WriteScene(name, R"({"format": "irbench.scene/1", "objects": [{"type": "quad", "name": "a",
        "origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0], "albedo": )" + albedo + "}]}"));
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  EXPECT_EQ(error_of("unknown", "\"velvet_purple\""), "objects[0].albedo");
  EXPECT_EQ(error_of("range", "{\"850\": 0.4, \"940\": 1.2}"), "objects[0].albedo.940");
  EXPECT_EQ(error_of("key", "{\"850\": 0.4, \"900\": 0.2}"), "objects[0].albedo.900");
  auto scene_error = [](const std::string& name, const std::string& text) {
    try {
      LoadScene(WriteScene(name, text));
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  const std::string quad = R"("objects": [{"type": "quad", "origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0]}])";
  EXPECT_EQ(scene_error("content", R"({"format": "irbench.scene/1", "screens": [{"name": "s", "type": "plane",
      "origin": [0, 3, 0], "right": [1, 0, 0], "up": [0, 0, 1], "width": 2, "height": 1, "content_radiance": -1}]})"),
            "screens[0].content_radiance");
  EXPECT_EQ(scene_error("bounces", R"({"format": "irbench.scene/1", "bounce": {"bounces": 9}, )" + quad + "}"),
            "bounce.bounces");
  EXPECT_EQ(scene_error("patch", R"({"format": "irbench.scene/1", "bounce": {"patch_m": 0.01}, )" + quad + "}"),
            "bounce.patch_m");
  // Too fine for the room: refused before any work, naming the bounce.
  EXPECT_EQ(scene_error("cost", R"({"format": "irbench.scene/1", "bounce": {"patch_m": 0.05},
      "objects": [{"type": "room", "min": [-6, -5, 0], "max": [6, 5.5, 4.2]}]})"),
            "bounce");
  EXPECT_EQ(scene_error("off", R"({"format": "irbench.scene/1", "bounce": false, )" + quad + "}"), "no error");
}

// Issue 27.3: ambient 1e39 or a light power of 1e308 rendered all-black
// frames with exit 0; every number has a physical range and an error naming
// the field.
TEST(SceneRangeTest, NumbersOutsidePhysicalRangesNameTheField) {
  auto scene_error = [](const std::string& name, const std::string& body) {
    try {
      LoadScene(WriteScene(name, R"({"format": "irbench.scene/1", "bounce": false, )" + body + "}"));
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  const std::string quad = R"("objects": [{"type": "quad", "origin": [0, 0, 0], "u": [1, 0, 0], "v": [0, 1, 0]}])";
  auto light = [&](const std::string& fields) {
    return quad + R"(, "lights": [{"name": "l", "position": [0, 0, 3], "look_at": [0, 0, 0], )" + fields + "}]";
  };
  EXPECT_EQ(scene_error("ambient", R"("ambient": 1e39, )" + quad), "ambient");
  EXPECT_EQ(scene_error("ambient_high", R"("ambient": 10.5, )" + quad), "ambient");
  EXPECT_EQ(scene_error("power", light(R"("power": 1e308)")), "lights[0].power");
  EXPECT_EQ(scene_error("power_high", light(R"("power": 1001)")), "lights[0].power");
  EXPECT_EQ(scene_error("light_far", quad + R"(, "lights": [{"name": "l", "position": [0, 0, 1e30], "look_at": [0, 0, 0]}])"),
            "lights[0].position[2]");
  EXPECT_EQ(scene_error("quad_far", R"("objects": [{"type": "quad", "origin": [0, 0, 0], "u": [1e39, 0, 0], "v": [0, 1, 0]}])"),
            "objects[0].u[0]");
  EXPECT_EQ(scene_error("room_far", R"("objects": [{"type": "room", "min": [-1e6, -5, 0], "max": [5, 5, 4]}])"),
            "objects[0].min[0]");
  EXPECT_EQ(scene_error("stage", R"("stage": {"center": [0, 0], "size": [3, 1e300]}, )" + quad), "stage.size[1]");
  EXPECT_EQ(scene_error("screen", quad + R"(, "screens": [{"name": "s", "type": "cylinder", "center_xy": [0, 0],
      "radius": 1e300, "angle_left_deg": 160, "angle_right_deg": 20, "z": [0, 2]}])"),
            "screens[0].radius");
  // At the bounds: fine.
  EXPECT_EQ(scene_error("bounds", R"("ambient": 10, )" + light(R"("power": 1000)")), "no error");
  // Every shipped scene is well inside them.
  for (const Scene& scene : AllScenes()) {
    EXPECT_LE(scene.ambient, 1.0) << scene.name;
    for (const IrLight& l : scene.lights) EXPECT_LE(l.power, 100.0) << scene.name;
  }
}

}  // namespace
}  // namespace irbench
