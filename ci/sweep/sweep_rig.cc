#include "ci/sweep/sweep_rig.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "common/error.h"
#include "sim/camera/rig.h"
#include "sim/sensor/sensor_model.h"

namespace irbench {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void Bad(const std::string& message) { throw InputError("", "value", message); }

// The rig's cameras kept: by name (in the rig's order) or the first n.
void KeepCameras(const nlohmann::json& value, nlohmann::json* rig) {
  nlohmann::json& cameras = (*rig)["cameras"];
  std::set<std::string> keep;
  if (value.is_number_integer()) {
    const int n = value.get<int>();
    if (n < 2 || n > static_cast<int>(cameras.size())) {
      Bad("a camera count must be in 2.." + std::to_string(cameras.size()) + " (the rig's cameras)");
    }
    for (int i = 0; i < n; ++i) keep.insert(cameras[i].value("name", ""));
  } else if (value.is_array()) {
    for (const nlohmann::json& name : value) {
      if (!name.is_string()) Bad("expected camera names");
      if (!keep.insert(name.get<std::string>()).second) Bad("camera '" + name.get<std::string>() + "' is listed twice");
    }
    if (keep.size() < 2) Bad("at least 2 cameras (the hull and the tracker need two views)");
    for (const std::string& name : keep) {
      const bool found = std::any_of(cameras.begin(), cameras.end(),
                                     [&](const nlohmann::json& c) { return c.value("name", "") == name; });
      if (!found) Bad("no camera '" + name + "' in rig " + rig->value("name", std::string("?")));
    }
  } else {
    Bad("expected a list of camera names or a camera count");
  }
  nlohmann::json kept = nlohmann::json::array();
  for (const nlohmann::json& c : cameras) {
    if (keep.count(c.value("name", ""))) kept.push_back(c);
  }
  cameras = kept;
}

double Number(const nlohmann::json& camera, const char* key) {
  if (!camera.contains(key) || !camera[key].is_number()) Bad(std::string("a camera without a number '") + key + "'");
  return camera[key].get<double>();
}

// Every camera at [width, height]: pixels scale by s = new / old per axis,
// so f' = f s and, pixel centres at integers, c' = (c + 0.5) s - 0.5.
void Resize(const nlohmann::json& value, nlohmann::json* rig) {
  if (!value.is_array() || value.size() != 2 || !value[0].is_number_integer() || !value[1].is_number_integer()) {
    Bad("expected [width, height] in pixels");
  }
  const int width = value[0].get<int>(), height = value[1].get<int>();
  if (width < 8 || width > 8192 || height < 8 || height > 8192) Bad("width and height must be in 8..8192");
  for (nlohmann::json& c : (*rig)["cameras"]) {
    // A rig's cameras are 320x240 unless they say (LoadRig's defaults).
    const double old_width = c.contains("width") ? Number(c, "width") : 320.0;
    const double old_height = c.contains("height") ? Number(c, "height") : 240.0;
    const double sx = width / old_width, sy = height / old_height;
    c["fx"] = Number(c, "fx") * sx;
    c["fy"] = Number(c, "fy") * sy;
    c["cx"] = (Number(c, "cx") + 0.5) * sx - 0.5;
    c["cy"] = (Number(c, "cy") + 0.5) * sy - 0.5;
    c["width"] = width;
    c["height"] = height;
  }
}

void Zoom(const nlohmann::json& value, nlohmann::json* rig) {
  if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0.1 ||
      value.get<double>() > 10) {
    Bad("a focal-length factor must be in 0.1..10");
  }
  for (nlohmann::json& c : (*rig)["cameras"]) {
    c["fx"] = Number(c, "fx") * value.get<double>();
    c["fy"] = Number(c, "fy") * value.get<double>();
  }
}

void Distort(const nlohmann::json& value, nlohmann::json* rig) {
  if (!value.is_array() || value.size() != 5 ||
      !std::all_of(value.begin(), value.end(), [](const nlohmann::json& k) { return k.is_number(); })) {
    Bad("expected 5 numbers: k1 k2 p1 p2 k3");
  }
  for (nlohmann::json& c : (*rig)["cameras"]) c["dist"] = value;
}

// `sensor.<group>.<knob>` split into (group, knob); nullopt for any other key.
std::optional<std::pair<std::string, std::string>> SensorKnob(const std::string& key) {
  const std::string prefix = "sensor.";
  if (key.rfind(prefix, 0) != 0) return std::nullopt;
  const size_t dot = key.find('.', prefix.size());
  if (dot == std::string::npos || dot == prefix.size() || dot + 1 == key.size() ||
      key.find('.', dot + 1) != std::string::npos) {
    return std::nullopt;
  }
  return std::make_pair(key.substr(prefix.size(), dot - prefix.size()), key.substr(dot + 1));
}

// Every camera's override of the knob `sensor.<group>.<knob>` set to the value.
void SetKnob(const std::string& key, const nlohmann::json& value, nlohmann::json* rig) {
  if (!value.is_number() && !value.is_boolean()) Bad("a sensor knob takes a number or true/false");
  const auto [group, knob] = *SensorKnob(key);
  for (nlohmann::json& c : (*rig)["cameras"]) {
    if (!c.contains("sensor") || !c["sensor"].is_object()) c["sensor"] = nlohmann::json::object();
    if (!c["sensor"].contains(group) || !c["sensor"][group].is_object()) c["sensor"][group] = nlohmann::json::object();
    c["sensor"][group][knob] = value;
  }
}

}  // namespace

bool IsSensorKnobKey(const std::string& key) { return SensorKnob(key).has_value(); }

const std::vector<std::string>& RigAxisKeys() {
  static const std::vector<std::string> keys = {"rig.cameras", "rig.resolution", "rig.focal_scale", "rig.dist"};
  return keys;
}

bool IsRigAxisKey(const std::string& key) {
  return std::find(RigAxisKeys().begin(), RigAxisKeys().end(), key) != RigAxisKeys().end() || IsSensorKnobKey(key);
}

void ApplyRigAxis(const std::string& key, const nlohmann::json& value, nlohmann::json* rig) {
  if (!rig->contains("cameras") || !(*rig)["cameras"].is_array()) Bad("the rig has no cameras list");
  if (key == "rig.cameras") {
    KeepCameras(value, rig);
  } else if (key == "rig.resolution") {
    Resize(value, rig);
  } else if (key == "rig.focal_scale") {
    Zoom(value, rig);
  } else if (key == "rig.dist") {
    Distort(value, rig);
  } else if (IsSensorKnobKey(key)) {
    SetKnob(key, value, rig);
  } else {
    Bad("not a rig axis: " + key);
  }
}

std::string RigAxisProblem(const fs::path& rig_file, const std::vector<std::pair<std::string, nlohmann::json>>& values,
                           const std::vector<std::string>& presets) {
  nlohmann::json rig;
  bool knob = false;
  try {
    std::ifstream in(rig_file);
    rig = nlohmann::json::parse(in);
    for (const auto& [key, value] : values) {
      ApplyRigAxis(key, value, &rig);
      knob |= IsSensorKnobKey(key);
    }
  } catch (const InputError& e) {
    return e.message();
  } catch (const nlohmann::json::exception& e) {
    return rig_file.string() + ": " + e.what();
  }
  static std::atomic<int> counter{0};
  const fs::path scratch =
      fs::temp_directory_path() /
      ("irbench-sweep-rig-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".json");
  std::ofstream(scratch) << rig.dump(2) << "\n";
  std::string problem;
  try {
    const Rig loaded = LoadRig(scratch);
    for (size_t i = 0; knob && i < loaded.cameras.size(); ++i) {
      for (const std::string& preset : presets) {
        std::optional<SensorSetup> setup = SensorPreset(preset);
        if (!setup) continue;  // an unknown preset is the `sensor` key's error
        ApplySensorOverrides(loaded.sensor_overrides[i], "", "cameras[" + std::to_string(i) + "].sensor", &*setup);
      }
    }
  } catch (const InputError& e) {
    problem = "rig " + rig_file.filename().string() + " with it: " + (e.field().empty() ? "" : e.field() + ": ") +
              e.message();
  }
  std::error_code ignored;
  fs::remove(scratch, ignored);
  return problem;
}

}  // namespace irbench
