#include "sim/sequence/motion_tools.h"

#include <cmath>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/paths.h"
#include "sim/body/avatar.h"
#include "sim/motion/bvh.h"
#include "sim/motion/retarget.h"
#include "sim/motion/session.h"
#include "sim/scene/scene.h"

namespace irbench {
namespace fs = std::filesystem;

std::string MotionListText() {
  std::ostringstream out;
  out << "# library motions (parameters in docs/motion.md)\n";
  for (const auto& [name, description] : LibraryMotions()) {
    char line[256];
    std::snprintf(line, sizeof(line), "%-20s %s\n", name.c_str(), description.c_str());
    out << line;
  }
  out << "# files in " << (DataRoot() / "motions").string() << "\n";
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(DataRoot() / "motions", ec)) {
    if (e.path().extension() == ".json") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    std::string format, description;
    try {
      const JsonNode root = ParseJsonFile(f.string());
      format = root.GetString("format", "");
      description = root.GetString("description", "");
    } catch (const InputError& e) {
      description = std::string("(unreadable: ") + e.what() + ")";
    }
    char line[512];
    std::snprintf(line, sizeof(line), "%-20s %-20s %s\n", f.stem().string().c_str(), format.c_str(),
                  description.c_str());
    out << line;
  }
  return out.str();
}

std::string MotionInfoText(const fs::path& file) {
  const MocapClip clip = LoadMocap(file);
  std::ostringstream out;
  out << "file        " << file.string() << "\n"
      << "convention  " << (clip.convention.empty() ? "unknown" : clip.convention) << "\n"
      << "joints      " << clip.joint_names.size() << "\n"
      << "frames      " << clip.frames.size() << "\n"
      << "frame time  " << clip.frame_time << " s (" << 1.0 / clip.frame_time << " fps)\n"
      << "duration    " << clip.Duration() << " s\n"
      << "joint map   (canonical <- clip)\n";
  const auto map = JointMapFor(clip.convention);
  for (int j = 0; j < kJointCount; ++j) {
    const auto it = map.find(JointName(j));
    out << "  " << JointName(j) << " <- " << (it == map.end() ? "(none)" : it->second) << "\n";
  }
  return out.str();
}

fs::path ExportMotion(const MotionExportOptions& options) {
  if (!(options.fps > 0 && options.fps <= 1000)) throw InputError("", "--fps", "must be in (0, 1000]");
  if (options.out.empty()) throw InputError("", "OUT", "no output file");
  if (fs::exists(options.out) && !options.overwrite) {
    throw InputError("", "OUT", "'" + options.out.string() + "' exists (pass --force to replace it)");
  }
  const fs::path avatar_file = ResolveDataFile("avatars", options.avatar, "--avatar");
  const Avatar avatar = LoadAvatar(avatar_file);
  const Scene scene = LoadScene(ResolveDataFile("scenes", options.scene, "--scene"));
  MotionContext ctx;
  ctx.avatar = &avatar;
  ctx.scene = &scene;
  ctx.style = StyleFor(avatar.params.name, options.seed, avatar.params.style, avatar_file.string());
  const ResolvedMotion motion = ResolveMotion(options.motion, ctx, "--motion");
  AtomicWriteFile(options.out, WriteBvh(MotionToBvh(*motion.motion, avatar.skeleton, options.fps)));
  return options.out;
}

}  // namespace irbench
