#pragma once
// Scenes (scenes/*.json): static geometry, projection screens with their screen
// frames and targets, near-IR illuminators, and the stage area where people act.
// Format in docs/formats.md.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/scene/mesh.h"
#include "sim/scene/screen_mesh.h"

namespace irbench {

struct IrLight {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();  // unit
  double cone_deg = 60.0;  // full opening angle
  double power = 1.0;      // relative radiant intensity on axis
  double wavelength_nm = 850.0;
  // Side of the square emitting area facing `direction`, metres; 0 is a point.
  // Shadows' penumbrae grow with it (rendered when shadows are on).
  double size_m = 0.0;
  bool casts_shadows = true;
};

// How the renderer computes the diffuse bounce light (sim/lighting/bounce.h).
struct SceneBounce {
  int bounces = 2;       // 0: none; 1: light reflected once; 2: once more
  double patch_m = 0.5;  // patch size
  double grid_m = 0.5;   // irradiance volume spacing
};

struct Scene {
  std::string name;
  std::filesystem::path source;
  Eigen::Vector2d stage_center = Eigen::Vector2d::Zero();
  Eigen::Vector2d stage_size = Eigen::Vector2d(3, 3);
  // Unshadowed fill light on every lit surface (stray light the bounce does
  // not model); it counts as the illuminators' 850 nm light.
  double ambient = 0.3;
  SceneBounce bounce;
  std::vector<ScreenSurface> screens;
  std::vector<IrLight> lights;
  TriangleMesh mesh;  // all static geometry, screens included
};

// Physical ranges of a scene file's numbers (a file beyond them is refused
// with InputError naming the file and field, instead of rendering black frames
// from overflowed light). The presets use ambient 0.02..0.42, light power
// 1.5..11 and rooms of 12 m; the bounds leave a wide margin.
// Every coordinate, extent and direction component, metres: |x| <= this.
inline constexpr double kMaxSceneCoordinateM = 1000.0;
// `ambient`, relative radiance (1 lights an albedo-1 surface to white): [0, 10].
inline constexpr double kMaxSceneAmbient = 10.0;
// A light's `power`, relative on-axis radiant intensity: [0, 1000].
inline constexpr double kMaxLightPower = 1000.0;

// Loads and validates a scene (format and ranges in docs/formats.md and above).
Scene LoadScene(const std::filesystem::path& path);

}  // namespace irbench
