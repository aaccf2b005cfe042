#include "sequence_format/manifest.h"

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// `name` of an object field ({"name": ...}), the string itself, or "".
std::string NameOf(const JsonNode& root, const std::string& key, const std::string& name_key) {
  if (!root.Has(key)) return "";
  const JsonNode node = root[key];
  if (node.raw().is_string()) return node.String();
  if (node.raw().is_object() && node.Has(name_key)) return node.GetString(name_key);
  return "";
}

std::vector<std::string> Strings(const JsonNode& root, const std::string& key) {
  std::vector<std::string> out;
  if (!root.Has(key)) return out;
  const JsonNode list = root[key];
  for (size_t i = 0; i < list.Size(); ++i) out.push_back(list[i].String());
  return out;
}

}  // namespace

bool HasManifest(const fs::path& sequence_dir) {
  return fs::is_regular_file(sequence_dir / kManifestFile);
}

void WriteManifest(const fs::path& sequence_dir, const nlohmann::json& manifest) {
  const auto format = manifest.find(manifest_key::kFormat);
  if (format == manifest.end() || !format->is_string() ||
      format->get<std::string>() != kSequenceFormat) {
    throw RuntimeError("a manifest without \"format\": \"" + std::string(kSequenceFormat) + "\"");
  }
  AtomicWriteFile(sequence_dir / kManifestFile, manifest.dump(2) + "\n");
}

Manifest ReadManifest(const fs::path& sequence_dir) {
  const fs::path path = sequence_dir / kManifestFile;
  if (!fs::is_regular_file(path))
    throw InputError(path.string(), "", "missing (not a sequence folder?)");
  const JsonNode root = ParseJsonFile(path.string());
  if (root.GetString(manifest_key::kFormat) != kSequenceFormat) {
    root[manifest_key::kFormat].Fail("expected \"" + std::string(kSequenceFormat) + "\"");
  }
  Manifest m;
  m.json = root.raw();
  if (root.Has(manifest_key::kSeed)) {
    if (!root[manifest_key::kSeed].raw().is_number_unsigned())
      root[manifest_key::kSeed].Fail("expected an unsigned integer");
    m.seed = root[manifest_key::kSeed].raw().get<uint64_t>();
  }
  m.fps = root.GetDouble(manifest_key::kFps, 0.0);
  m.frame_count = root.GetInt(manifest_key::kFrameCount, 0);
  m.cameras = Strings(root, manifest_key::kCameras);
  m.joints = Strings(root, manifest_key::kJoints);
  m.scene = NameOf(root, manifest_key::kScene, manifest_key::kName);
  m.rig = NameOf(root, manifest_key::kRig, manifest_key::kName);
  m.avatar = NameOf(root, manifest_key::kAvatar, manifest_key::kName);
  m.motion = NameOf(root, manifest_key::kMotion, manifest_key::kName);
  m.sensor = NameOf(root, manifest_key::kSensor, "preset");
  return m;
}

}  // namespace irbench
