#include "sim/scene/materials.h"

namespace irbench {

const std::vector<NirMaterial>& NirMaterials() {
  // Typical diffuse reflectances. Skin: high in the near IR whatever its
  // visible tone (melanin absorbs little past 800 nm), a little lower at
  // 940 nm (the water band at 970 nm). Most textile dyes are transparent in
  // the near IR, so dyed fabric looks light whatever its colour; carbon-black
  // pigments (synthetic black, rubber, matte black paint) absorb it.
  static const std::vector<NirMaterial> table = {
      {"skin_light", {0.60f, 0.55f}, "fair skin"},
      {"skin_medium", {0.52f, 0.48f}, "medium skin"},
      {"skin_dark", {0.45f, 0.42f}, "dark skin"},
      {"hair_black", {0.15f, 0.18f}, "black hair"},
      {"hair_brown", {0.25f, 0.29f}, "brown hair"},
      {"hair_blond", {0.48f, 0.52f}, "blond hair"},
      {"cotton_white", {0.75f, 0.72f}, "undyed or white cotton"},
      {"cotton_dyed", {0.62f, 0.62f}, "cotton in most dyes (NIR-transparent)"},
      {"cotton_black", {0.25f, 0.30f}, "sulphur-black cotton"},
      {"denim", {0.40f, 0.44f}, "indigo denim"},
      {"wool_grey", {0.40f, 0.41f}, "grey wool"},
      {"synthetic_black", {0.07f, 0.07f}, "carbon-black polyester"},
      {"leather_black", {0.12f, 0.14f}, "black leather"},
      {"rubber", {0.06f, 0.06f}, "rubber soles, carbon-black"},
      {"carpet_grey", {0.30f, 0.30f}, "grey carpet"},
      {"paint_black_matte", {0.05f, 0.05f}, "matte black paint"},
      {"paint_grey", {0.22f, 0.22f}, "dark grey paint"},
      {"drape_black", {0.04f, 0.05f}, "black theatre velour"},
      {"wood", {0.55f, 0.57f}, "light wood"},
      {"concrete", {0.35f, 0.36f}, "concrete"},
      {"projection_screen", {0.85f, 0.84f}, "matte white projection screen"},
  };
  return table;
}

std::optional<NirReflectance> FindNirMaterial(const std::string& name) {
  for (const NirMaterial& m : NirMaterials()) {
    if (name == m.name) return m.reflectance;
  }
  return std::nullopt;
}

NirReflectance ReadReflectance(const JsonNode& node) {
  auto check = [](const JsonNode& n) {
    const double v = n.Number();
    if (!(v >= 0 && v <= 1)) n.Fail("reflectance must be in [0, 1]");
    return static_cast<float>(v);
  };
  const nlohmann::json& raw = node.raw();
  if (raw.is_number()) return NirReflectance::Grey(check(node));
  if (raw.is_string()) {
    const std::string name = raw.get<std::string>();
    if (auto r = FindNirMaterial(name)) return *r;
    std::string known;
    for (const NirMaterial& m : NirMaterials()) known += (known.empty() ? "" : ", ") + std::string(m.name);
    node.Fail("unknown material '" + name + "' (" + known + ")");
  }
  if (raw.is_object()) {
    node.CheckKeys({"850", "940"});
    return {check(node["850"]), check(node["940"])};
  }
  node.Fail("expected a reflectance: a number, a material name or {\"850\": r, \"940\": r}");
  return {};
}

}  // namespace irbench
