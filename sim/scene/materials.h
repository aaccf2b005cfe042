#pragma once
// Near-IR reflectance of the materials a theater and its users are made of,
// at the two illuminator wavelengths (850 and 940 nm). Scenes and avatars name
// them ("skin_light", "cotton_dyed", ...) or give numbers (docs/sensor.md
// "Materials" lists the table and where its values come from).

#include <optional>
#include <string>
#include <vector>

#include "common/json_reader.h"
#include "sim/scene/mesh.h"

namespace irbench {

struct NirMaterial {
  const char* name;
  NirReflectance reflectance;
  const char* note;
};

// The built-in table, in a fixed order.
const std::vector<NirMaterial>& NirMaterials();
std::optional<NirReflectance> FindNirMaterial(const std::string& name);

// A reflectance from JSON: a number (the same at both wavelengths), a
// material name from the table, or {"850": r, "940": r}. Values must lie in
// [0, 1]; bad input throws InputError naming the node's file and field.
NirReflectance ReadReflectance(const JsonNode& node);

}  // namespace irbench
