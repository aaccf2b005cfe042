#include "sim/sequence/avatar_tools.h"

#include <algorithm>
#include <map>
#include <iomanip>
#include <sstream>

#include "common/error.h"
#include "common/json_reader.h"
#include "common/paths.h"
#include "sim/body/avatar.h"
#include "sim/body/gltf_export.h"

namespace irbench {
namespace fs = std::filesystem;

std::string AvatarListText() {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(DataRoot() / "avatars", ec)) {
    if (e.path().extension() == ".json") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  std::ostringstream out;
  for (const fs::path& f : files) {
    char line[512];
    try {
      const JsonNode root = ParseJsonFile(f.string());
      std::snprintf(line, sizeof(line), "%-8s %-11s %.2f m  %s\n", f.stem().string().c_str(),
                    root.GetString("kind", "?").c_str(), root.GetDouble("height_m", 0.0),
                    root.GetString("description", "").c_str());
    } catch (const InputError& e) {
      std::snprintf(line, sizeof(line), "%-8s (unreadable: %s)\n", f.stem().string().c_str(), e.what());
    }
    out << line;
  }
  return out.str();
}

std::string AvatarInfoText(const std::string& name_or_path) {
  const fs::path file = ResolveDataFile("avatars", name_or_path, "AVATAR");
  const Avatar a = LoadAvatar(file);
  float top = -1e9f, bottom = 1e9f;
  for (const MeshVertex& v : a.bind_vertices) {
    top = std::max(top, v.position.z());
    bottom = std::min(bottom, v.position.z());
  }
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (size_t t = 0; t < a.indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t u = a.indices[t + e], v = a.indices[t + (e + 1) % 3];
      ++edges[{std::min(u, v), std::max(u, v)}];
    }
  }
  size_t open = 0;
  for (const auto& [edge, count] : edges) open += count != 2;
  std::ostringstream out;
  out << "avatar      " << a.params.name << " (" << file.string() << ")\n"
      << "kind        " << a.params.kind << "\n"
      << "height      " << top - bottom << " m (parameter " << a.params.height_m << " m)\n"
      << "build       " << a.params.build << "\n"
      << "triangles   " << a.indices.size() / 3 << "\n"
      << "vertices    " << a.bind_vertices.size() << "\n"
      << "watertight  " << (open == 0 ? "yes" : "no: " + std::to_string(open) + " edges not shared by two faces")
      << "\n"
      << "joints      " << kJointCount << " (canonical skeleton)\n";
  // The figures a tracker's per-user model configuration estimates (thesis
  // 6.1.1): joint centre to joint centre, at the bind pose.
  const auto& b = a.skeleton.bind_position;
  const auto length = [&](int from, int to) { return (b[to] - b[from]).norm(); };
  out << std::fixed << std::setprecision(3) << "arms        shoulder width " << length(kLeftShoulder, kRightShoulder)
      << " m; upper arm " << length(kRightShoulder, kRightElbow) << " / " << length(kLeftShoulder, kLeftElbow)
      << " m, forearm " << length(kRightElbow, kRightWrist) << " / " << length(kLeftElbow, kLeftWrist)
      << " m (right / left, joint centres)\n"
      << std::defaultfloat << std::setprecision(6);
  if (a.params.source.is_object()) {
    const nlohmann::json& src = a.params.source;
    out << "imported    " << src["file"].get<std::string>() << "\n"
        << "rig         "
        << (src["convention"] == "hierarchy" ? std::string("mapped by its hierarchy (no name table knows its joints)")
                                             : src["convention"].get<std::string>() + " names")
        << ", up " << src["up_axis"].get<std::string>()
        << ", " << src["scale"].get<double>() << " m per file unit\n"
        << "joint map   (canonical <- rig)\n";
    for (int j = 0; j < kJointCount; ++j) {
      const auto it = src["joint_map"].find(JointName(j));
      out << "  " << JointName(j) << std::string(16 - std::min<size_t>(15, std::string(JointName(j)).size()), ' ')
          << (it == src["joint_map"].end() ? std::string("(interpolated)") : it->get<std::string>()) << "\n";
    }
    std::string unmapped;
    for (const auto& n : src["unmapped_rig_joints"]) unmapped += (unmapped.empty() ? "" : ", ") + n.get<std::string>();
    out << "unmapped    " << (unmapped.empty() ? "none" : unmapped + " (follow their nearest mapped parent)") << "\n";
  }
  return out.str();
}

fs::path ExportAvatar(const std::string& name_or_path, const fs::path& out, bool overwrite) {
  if (out.empty()) throw InputError("", "OUT", "no output file");
  if (fs::exists(out) && !overwrite) {
    throw InputError("", "OUT", "'" + out.string() + "' exists (pass --force to replace it)");
  }
  if (!fs::is_directory(fs::absolute(out).parent_path())) {
    throw InputError("", "OUT", "folder '" + fs::absolute(out).parent_path().string() + "' does not exist");
  }
  const Avatar avatar = LoadAvatar(ResolveDataFile("avatars", name_or_path, "AVATAR"));
  WriteAvatarGlb(avatar, out);
  return out;
}

}  // namespace irbench
