#include "sim/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "common/json_reader.h"
#include "sequence_format/screens.h"
#include "sim/scene/materials.h"

namespace irbench {
namespace {

Material ReadMaterial(const JsonNode& node, const std::string& key, float fallback) {
  if (!node.Has(key)) return Material::Of(NirReflectance::Grey(fallback));
  return Material::Of(ReadReflectance(node[key]));
}

// Every number under `node` (a number or arrays/objects of them, `depth`
// levels deep at most: deeper shapes are the format readers' to refuse)
// within +-kMaxSceneCoordinateM.
void CheckExtent(const JsonNode& node, int depth = 3) {
  const nlohmann::json& raw = node.raw();
  if (depth < 0) return;
  if (raw.is_number()) {
    const double v = node.Number();
    if (std::abs(v) > kMaxSceneCoordinateM) {
      node.Fail("must be within +-" + std::to_string(static_cast<int>(kMaxSceneCoordinateM)) +
                " m (got " + raw.dump() + ")");
    }
  } else if (raw.is_array()) {
    for (size_t i = 0; i < node.Size(); ++i) CheckExtent(node[i], depth - 1);
  } else if (raw.is_object()) {
    for (const std::string& key : node.Keys()) CheckExtent(node[key], depth - 1);
  }
}

// CheckExtent on each of `keys` that `node` has.
void CheckExtents(const JsonNode& node, const std::vector<std::string>& keys) {
  for (const std::string& key : keys) {
    if (node.Has(key)) CheckExtent(node[key]);
  }
}

void CheckBox(const JsonNode& node, const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  if ((max - min).minCoeff() <= 0) node["max"].Fail("must exceed 'min' on every axis");
}

// A scene file's screen: its surface (sequence_format/screens.h, shared with
// calib/screens.json) and how it renders.
ScreenSurface ReadScreen(const JsonNode& s, Material* material) {
  CheckExtents(s,
               {"origin", "right", "up", "width", "height", "center_xy", "radius", "z", "targets"});
  ScreenSurface screen = ReadScreenSurface(s, TargetForm::kScreenCoordinates, {"albedo", "content_radiance", "description"});
  *material = ReadMaterial(s, "albedo", 0.8f);
  // The near-IR radiance the projected content adds (projectors leak near IR);
  // it flickers with the content (docs/sensor.md).
  material->content = static_cast<float>(s.GetDouble("content_radiance", 0.0));
  if (material->content < 0 || material->content > 10) {
    s["content_radiance"].Fail("must be in [0, 10]");
  }
  return screen;
}

// One of the scene's near-IR illuminators.
IrLight ReadLight(const JsonNode& l) {
  l.CheckKeys(
      {"name", "position", "look_at", "cone_deg", "power", "wavelength_nm", "size_m", "shadows"});
  CheckExtents(l, {"position", "look_at"});
  IrLight light;
  light.name = l.GetString("name");
  light.position = l.GetVec3("position");
  const Eigen::Vector3d dir = l.GetVec3("look_at") - light.position;
  if (dir.norm() < 1e-9) l["look_at"].Fail("must differ from 'position'");
  light.direction = dir.normalized();
  light.cone_deg = l.GetDouble("cone_deg", 60.0);
  if (light.cone_deg <= 0 || light.cone_deg > 180) l["cone_deg"].Fail("must be in (0, 180]");
  light.power = l.GetDouble("power", 1.0);
  if (!(light.power >= 0 && light.power <= kMaxLightPower)) {
    l["power"].Fail("must be in [0, " + std::to_string(static_cast<int>(kMaxLightPower)) + "]");
  }
  light.wavelength_nm = l.GetDouble("wavelength_nm", 850.0);
  if (light.wavelength_nm != 850.0 && light.wavelength_nm != 940.0) {
    l["wavelength_nm"].Fail("must be 850 or 940");
  }
  light.size_m = l.GetDouble("size_m", 0.0);
  if (light.size_m < 0 || light.size_m > 5) l["size_m"].Fail("must be in [0, 5] m");
  light.casts_shadows = l.GetBool("shadows", true);
  return light;
}

}  // namespace

Scene LoadScene(const std::filesystem::path& path) {
  const JsonNode root = ParseJsonFile(path.string());
  root.CheckKeys({"format", "name", "description", "stage", "ambient", "bounce", "objects", "screens", "lights"});
  if (root.GetString("format") != "irbench.scene/1") root["format"].Fail("expected \"irbench.scene/1\"");
  Scene scene;
  scene.source = path;
  scene.name = root.GetString("name", path.stem().string());
  if (root.Has("stage")) {
    const JsonNode stage = root["stage"];
    stage.CheckKeys({"center", "size"});
    CheckExtents(stage, {"center", "size"});
    scene.stage_center = stage["center"].Vec2();
    scene.stage_size = stage["size"].Vec2();
    if (scene.stage_size.minCoeff() <= 0) stage["size"].Fail("must be positive");
  }
  scene.ambient = root.GetDouble("ambient", 0.3);
  if (!(scene.ambient >= 0 && scene.ambient <= kMaxSceneAmbient)) {
    root["ambient"].Fail("must be in [0, " + std::to_string(static_cast<int>(kMaxSceneAmbient)) +
                         "]");
  }
  if (root.Has("bounce")) {
    const JsonNode b = root["bounce"];
    if (b.raw().is_boolean()) {
      if (!b.Bool()) scene.bounce.bounces = 0;
    } else {
      b.CheckKeys({"bounces", "patch_m", "grid_m"});
      scene.bounce.bounces = b.GetInt("bounces", scene.bounce.bounces);
      if (scene.bounce.bounces < 0 || scene.bounce.bounces > 4) b["bounces"].Fail("must be in 0..4");
      scene.bounce.patch_m = b.GetDouble("patch_m", scene.bounce.patch_m);
      if (!(scene.bounce.patch_m >= 0.05 && scene.bounce.patch_m <= 5)) b["patch_m"].Fail("must be in [0.05, 5] m");
      scene.bounce.grid_m = b.GetDouble("grid_m", scene.bounce.grid_m);
      if (!(scene.bounce.grid_m >= 0.05 && scene.bounce.grid_m <= 5)) b["grid_m"].Fail("must be in [0.05, 5] m");
    }
  }

  // Rooms enclose everything; they go last in the mesh so that the renderer's
  // depth test rejects their hidden fragments early instead of shading them.
  TriangleMesh enclosure;
  if (root.Has("objects")) {
    const JsonNode objects = root["objects"];
    for (size_t i = 0; i < objects.Size(); ++i) {
      const JsonNode o = objects[i];
      const std::string type = o.GetString("type");
      CheckExtents(o, {"min", "max", "origin", "u", "v"});
      if (type == "room") {
        o.CheckKeys({"type", "name", "min", "max", "floor", "ceiling", "walls"});
        const Eigen::Vector3d min = o.GetVec3("min"), max = o.GetVec3("max");
        CheckBox(o, min, max);
        AppendRoom(enclosure, min, max, ReadMaterial(o, "floor", 0.3f),
                   ReadMaterial(o, "ceiling", 0.2f), ReadMaterial(o, "walls", 0.25f));
      } else if (type == "box") {
        o.CheckKeys({"type", "name", "min", "max", "albedo"});
        const Eigen::Vector3d min = o.GetVec3("min"), max = o.GetVec3("max");
        CheckBox(o, min, max);
        AppendBox(scene.mesh, min, max, ReadMaterial(o, "albedo", 0.5f), false);
      } else if (type == "quad") {
        o.CheckKeys({"type", "name", "origin", "u", "v", "albedo"});
        const Eigen::Vector3d u = o.GetVec3("u"), v = o.GetVec3("v");
        if (u.cross(v).norm() < 1e-9) o["v"].Fail("must not be parallel to 'u'");
        AppendQuad(scene.mesh, o.GetVec3("origin"), u, v, ReadMaterial(o, "albedo", 0.5f));
      } else {
        o["type"].Fail("unknown object type '" + type + "' (room, box, quad)");
      }
    }
  }
  if (root.Has("screens")) {
    const JsonNode screens = root["screens"];
    std::set<std::string> names;
    for (size_t i = 0; i < screens.Size(); ++i) {
      Material material;
      ScreenSurface screen = ReadScreen(screens[i], &material);
      if (!names.insert(screen.name).second) screens[i]["name"].Fail("duplicate screen name");
      AppendScreenGeometry(screen, material, scene.mesh);
      scene.screens.push_back(std::move(screen));
    }
  }
  if (root.Has("lights")) {
    const JsonNode lights = root["lights"];
    if (lights.Size() > 8) lights.Fail("at most 8 lights");
    for (size_t i = 0; i < lights.Size(); ++i) {
      scene.lights.push_back(ReadLight(lights[i]));
    }
  }
  scene.mesh.Append(enclosure);
  if (scene.mesh.vertices.empty()) root.Fail("scene has no geometry");
  if (scene.bounce.bounces > 0) {
    // The bounce gathers patch to patch (quadratic) and sums every patch into
    // every volume point: keep both counts where a render stays interactive.
    double patches = 0;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (size_t t = 0; t + 2 < scene.mesh.indices.size(); t += 3) {
      double longest = 0;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3f d = scene.mesh.vertices[scene.mesh.indices[t + k]].position -
                                  scene.mesh.vertices[scene.mesh.indices[t + (k + 1) % 3]].position;
        longest = std::max(longest, double(d.norm()));
      }
      patches += std::pow(std::max(1.0, std::ceil(longest / scene.bounce.patch_m)), 2);
    }
    for (const MeshVertex& v : scene.mesh.vertices) {
      lo = lo.cwiseMin(v.position.cast<double>());
      hi = hi.cwiseMax(v.position.cast<double>());
    }
    double points = 1;
    for (int k = 0; k < 3; ++k) points *= std::ceil((hi[k] - lo[k]) / scene.bounce.grid_m) + 1;
    const JsonNode where = root.Has("bounce") ? root["bounce"] : root;
    if (patches > 60000) {
      where.Fail("the bounce light would need " + std::to_string(static_cast<long>(patches)) +
                 " patches (at most 60000): raise patch_m");
    }
    if (points > 200000) {
      where.Fail("the bounce light's volume would have " + std::to_string(static_cast<long>(points)) +
                 " points (at most 200000): raise grid_m");
    }
  }
  return scene;
}

}  // namespace irbench
