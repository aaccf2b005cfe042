#include "sequence_format/screens.h"

#include <cmath>

#include "common/atomic_file.h"

namespace irbench {
namespace {

void ReadCylinder(const JsonNode& s, ScreenSurface& screen) {
  screen.kind = ScreenSurface::Kind::kCylinder;
  screen.center_xy = s["center_xy"].Vec2();
  screen.radius = s.GetDouble("radius");
  if (screen.radius <= 0) s["radius"].Fail("must be positive");
  screen.angle_left_deg = s.GetDouble("angle_left_deg");
  screen.angle_right_deg = s.GetDouble("angle_right_deg");
  if (screen.angle_left_deg <= screen.angle_right_deg ||
      screen.angle_left_deg - screen.angle_right_deg > 360) {
    s["angle_left_deg"].Fail("must exceed angle_right_deg by at most 360");
  }
  const Eigen::Vector2d z = s["z"].Vec2();
  screen.z0 = z.x();
  screen.z1 = z.y();
  if (screen.z1 <= screen.z0) s["z"].Fail("top must be above bottom");
}

void ReadPlane(const JsonNode& s, ScreenSurface& screen) {
  screen.kind = ScreenSurface::Kind::kPlane;
  screen.origin = s.GetVec3("origin");
  screen.right = s.GetVec3("right");
  screen.up = s.GetVec3("up");
  if (screen.right.norm() < 1e-9) s["right"].Fail("must be non-zero");
  if (screen.up.norm() < 1e-9) s["up"].Fail("must be non-zero");
  screen.right.normalize();
  screen.up.normalize();
  if (std::abs(screen.right.dot(screen.up)) > 1e-3)
    s["up"].Fail("must be perpendicular to 'right'");
  screen.width = s.GetDouble("width");
  screen.height = s.GetDouble("height");
  if (screen.width <= 0) s["width"].Fail("must be positive");
  if (screen.height <= 0) s["height"].Fail("must be positive");
}

// Targets as [s, t] or {"screen": [s, t], "world": ...}; each on the screen.
void ReadTargets(const JsonNode& targets, TargetForm form, ScreenSurface& screen) {
  const Eigen::Vector2d size = screen.Size();
  for (const std::string& name : targets.Keys()) {
    const JsonNode target = targets[name];
    if (form == TargetForm::kSurveyed) target.CheckKeys({"screen", "world"});
    const Eigen::Vector2d st =
        form == TargetForm::kSurveyed ? target["screen"].Vec2() : target.Vec2();
    if (st.x() < 0 || st.x() > size.x() || st.y() < 0 || st.y() > size.y()) {
      target.Fail("target outside the screen (size " + std::to_string(size.x()) + " x " +
                  std::to_string(size.y()) + " m)");
    }
    screen.targets[name] = st;
  }
}

}  // namespace

ScreenSurface ReadScreenSurface(const JsonNode& s,
                                TargetForm target_form,
                                const std::vector<std::string>& allowed_keys) {
  ScreenSurface screen;
  screen.name = s.GetString("name");
  const std::string type = s.GetString("type");
  const auto check_keys = [&](std::vector<std::string> keys) {
    keys.insert(keys.end(), allowed_keys.begin(), allowed_keys.end());
    s.CheckKeys(keys);
  };
  if (type == "cylinder") {
    check_keys({"name", "type", "center_xy", "radius", "angle_left_deg", "angle_right_deg", "z",
                "targets"});
    ReadCylinder(s, screen);
  } else if (type == "plane") {
    check_keys({"name", "type", "origin", "right", "up", "width", "height", "targets"});
    ReadPlane(s, screen);
  } else {
    s["type"].Fail("unknown screen type '" + type + "' (cylinder, plane)");
  }
  if (s.Has("targets")) ReadTargets(s["targets"], target_form, screen);
  return screen;
}

nlohmann::json ScreenJson(const ScreenSurface& screen) {
  nlohmann::json j;
  j["name"] = screen.name;
  if (screen.kind == ScreenSurface::Kind::kCylinder) {
    j["type"] = "cylinder";
    j["center_xy"] = {screen.center_xy.x(), screen.center_xy.y()};
    j["radius"] = screen.radius;
    j["angle_left_deg"] = screen.angle_left_deg;
    j["angle_right_deg"] = screen.angle_right_deg;
    j["z"] = {screen.z0, screen.z1};
    j["screen_frame"] =
        "s: arc length in metres from the left edge (angle_left_deg) towards the right; "
        "t: height in metres above z[0]";
  } else {
    j["type"] = "plane";
    j["origin"] = {screen.origin.x(), screen.origin.y(), screen.origin.z()};
    j["right"] = {screen.right.x(), screen.right.y(), screen.right.z()};
    j["up"] = {screen.up.x(), screen.up.y(), screen.up.z()};
    j["width"] = screen.width;
    j["height"] = screen.height;
    j["screen_frame"] = "s: metres along 'right' from 'origin'; t: metres along 'up'";
  }
  const Eigen::Vector2d size = screen.Size();
  j["size"] = {size.x(), size.y()};
  nlohmann::json targets_json = nlohmann::json::object();
  for (const auto& [target_name, st] : screen.targets) {
    const Eigen::Vector3d p = screen.PointAt(st);
    targets_json[target_name] = {{"screen", {st.x(), st.y()}}, {"world", {p.x(), p.y(), p.z()}}};
  }
  j["targets"] = targets_json;
  return j;
}

nlohmann::json ScreensJson(const std::string& scene_name,
                           const std::vector<ScreenSurface>& screens) {
  nlohmann::json j;
  j["format"] = kScreensFormat;
  j["scene"] = scene_name;
  j["screens"] = nlohmann::json::array();
  for (const ScreenSurface& s : screens) j["screens"].push_back(ScreenJson(s));
  return j;
}

void WriteScreens(const std::filesystem::path& sequence_dir,
                  const std::string& scene_name,
                  const std::vector<ScreenSurface>& screens) {
  AtomicWriteFile(sequence_dir / kScreensFile, ScreensJson(scene_name, screens).dump(2) + "\n");
}

std::vector<ScreenSurface> ReadScreens(const std::filesystem::path& sequence_dir) {
  const std::filesystem::path path = sequence_dir / kScreensFile;
  if (!std::filesystem::is_regular_file(path)) return {};
  const JsonNode root = ParseJsonFile(path.string());
  if (root.GetString("format") != kScreensFormat)
    root["format"].Fail(std::string("expected \"") + kScreensFormat + "\"");
  root.CheckKeys({"format", "scene", "screens", "description"});
  std::vector<ScreenSurface> out;
  const JsonNode list = root["screens"];
  for (size_t i = 0; i < list.Size(); ++i)
    out.push_back(
        ReadScreenSurface(list[i], TargetForm::kSurveyed, {"screen_frame", "size", "description"}));
  return out;
}

}  // namespace irbench
