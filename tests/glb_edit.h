#pragma once
// GLB surgery for the importer's tests: the JSON chunk edited, the BIN chunk
// kept (or appended to). Used by sim/body/avatar_import_test.cc and
// tests/avatar_render_test.cc.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

namespace irbench::testing {

struct Glb {
  nlohmann::json json;
  std::string bin;
};

inline Glb ReadGlb(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto u32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  Glb glb;
  const uint32_t json_length = u32(12);
  glb.json = nlohmann::json::parse(bytes.substr(20, json_length));
  const size_t bin_at = 20 + json_length;
  if (bin_at + 8 <= bytes.size()) glb.bin = bytes.substr(bin_at + 8, u32(bin_at));
  return glb;
}

inline void WriteGlb(const std::filesystem::path& path, const Glb& glb) {
  std::string json = glb.json.dump();
  while (json.size() % 4) json += ' ';
  std::string bin = glb.bin;
  while (bin.size() % 4) bin += '\0';
  std::string out;
  auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  out += "glTF";
  u32(2);
  u32(static_cast<uint32_t>(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size())));
  u32(static_cast<uint32_t>(json.size()));
  u32(0x4E4F534A);
  out += json;
  if (!bin.empty()) {
    u32(static_cast<uint32_t>(bin.size()));
    u32(0x004E4942);
    out += bin;
  }
  std::ofstream(path, std::ios::binary) << out;
}

inline void RenameNodes(Glb& glb, const std::map<std::string, std::string>& renames) {
  for (auto& node : glb.json["nodes"]) {
    if (!node.contains("name")) continue;
    const auto it = renames.find(node["name"].get<std::string>());
    if (it != renames.end()) node["name"] = it->second;
  }
}

// Adds an unweighted joint `name` under the node `parent` to skin 0 (its
// inverse bind matrix the identity), as an IK helper bone would be.
inline void AddHelperJoint(Glb& glb, const std::string& parent, const std::string& name) {
  nlohmann::json& j = glb.json;
  int parent_node = -1;
  for (size_t i = 0; i < j["nodes"].size(); ++i) {
    if (j["nodes"][i].value("name", "") == parent) parent_node = static_cast<int>(i);
  }
  ASSERT_GE(parent_node, 0) << parent;
  const int node = static_cast<int>(j["nodes"].size());
  j["nodes"].push_back({{"name", name}, {"translation", {0.3, 0.0, 0.1}}});
  j["nodes"][parent_node]["children"].push_back(node);
  nlohmann::json& skin = j["skins"][0];
  const nlohmann::json accessor = j["accessors"][skin["inverseBindMatrices"].get<int>()];
  const nlohmann::json view = j["bufferViews"][accessor["bufferView"].get<int>()];
  const size_t count = accessor["count"].get<size_t>();
  std::string data = glb.bin.substr(view.value("byteOffset", 0) + accessor.value("byteOffset", 0), count * 64);
  const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  data.append(reinterpret_cast<const char*>(identity), sizeof(identity));
  while (glb.bin.size() % 4) glb.bin += '\0';
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", glb.bin.size()}, {"byteLength", data.size()}});
  glb.bin += data;
  j["accessors"].push_back({{"bufferView", j["bufferViews"].size() - 1},
                            {"componentType", 5126},
                            {"count", count + 1},
                            {"type", "MAT4"}});
  skin["inverseBindMatrices"] = j["accessors"].size() - 1;
  skin["joints"].push_back(node);
  j["buffers"][0]["byteLength"] = glb.bin.size();
}

// Every skin joint named "b<k>"; returns the new name of each old one.
inline std::map<std::string, std::string> RenameJointsMeaninglessly(Glb& glb) {
  std::map<std::string, std::string> renames;
  int k = 0;
  for (const auto& joint : glb.json["skins"][0]["joints"]) {
    const std::string old = glb.json["nodes"][joint.get<int>()]["name"];
    renames[old] = "b" + std::to_string(k++);
  }
  RenameNodes(glb, renames);
  return renames;
}

// Moves every skin weight of the joints named `from` to the joint named `to`.
inline void MoveWeights(Glb& glb, const std::set<std::string>& from, const std::string& to) {
  nlohmann::json& j = glb.json;
  std::set<int> from_index;
  int to_index = -1;
  const auto& joints = j["skins"][0]["joints"];
  for (size_t k = 0; k < joints.size(); ++k) {
    const std::string name = j["nodes"][joints[k].get<int>()].value("name", "");
    if (from.count(name)) from_index.insert(static_cast<int>(k));
    if (name == to) to_index = static_cast<int>(k);
  }
  ASSERT_EQ(from_index.size(), from.size());
  ASSERT_GE(to_index, 0);
  for (const auto& mesh : j["meshes"]) {
    for (const auto& primitive : mesh["primitives"]) {
      if (!primitive["attributes"].contains("JOINTS_0")) continue;
      const auto& accessor = j["accessors"][primitive["attributes"]["JOINTS_0"].get<int>()];
      const auto& view = j["bufferViews"][accessor["bufferView"].get<int>()];
      const int component = accessor["componentType"] == 5121 ? 1 : 2;
      const size_t stride = view.value("byteStride", 4 * component);
      const size_t at = view.value("byteOffset", 0) + accessor.value("byteOffset", 0);
      for (size_t v = 0; v < accessor["count"].get<size_t>(); ++v) {
        for (int c = 0; c < 4; ++c) {
          char* p = glb.bin.data() + at + v * stride + c * component;
          int index = component == 1 ? static_cast<unsigned char>(*p) : *reinterpret_cast<uint16_t*>(p);
          if (!from_index.count(index)) continue;
          if (component == 1) *p = static_cast<char>(to_index);
          else *reinterpret_cast<uint16_t*>(p) = static_cast<uint16_t>(to_index);
        }
      }
    }
  }
}


}  // namespace irbench::testing
