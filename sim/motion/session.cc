#include "sim/motion/session.h"

#include <algorithm>

#include "common/error.h"
#include "common/json_reader.h"
#include "common/paths.h"
#include "common/text.h"
#include "sim/motion/keyframes.h"
#include "sim/motion/retarget.h"

namespace irbench {
namespace fs = std::filesystem;

namespace {

bool IsLibraryName(const std::string& name) {
  for (const auto& [n, text] : LibraryMotions()) {
    if (n == name) return true;
  }
  return false;
}

// Keyframe files are absolute poses at the origin; moving the person there
// keeps the next motion's start consistent.
MotionPtr LoadKeyframeFile(const fs::path& path, MotionContext& ctx) {
  auto motion = std::make_shared<KeyframeMotion>(LoadKeyframes(path));
  const Pose end = motion->At(motion->Duration());
  ctx.state.position = end.root_offset.head<2>();
  ctx.state.heading_deg = 0;
  return motion;
}

MotionPtr LoadClip(const fs::path& path, MotionContext& ctx, double start_s, double end_s) {
  MocapClip clip = LoadMocap(path);
  // Trim to [start_s, end_s] before retargeting, so frame 0 is placed.
  const size_t first = std::min(clip.frames.size() - 1, static_cast<size_t>(std::max(0.0, start_s) / clip.frame_time));
  size_t last = clip.frames.size() - 1;
  if (end_s > 0) last = std::min(last, static_cast<size_t>(end_s / clip.frame_time));
  if (last <= first) throw InputError(path.string(), "end_s", "the clip range is empty");
  clip.frames = std::vector<MocapClip::Frame>(clip.frames.begin() + first, clip.frames.begin() + last + 1);
  RetargetOptions options;
  options.place_at = ctx.state.position;
  options.heading_deg = ctx.state.heading_deg;
  auto motion = Retarget(clip, ctx.avatar->skeleton, options);
  const Pose end = motion->At(motion->Duration());
  ctx.state.position = (ctx.avatar->skeleton.bind_position[kPelvis] + end.root_offset).head<2>();
  return motion;
}

}  // namespace

MotionPtr LoadSession(const fs::path& path, MotionContext& ctx) {
  const JsonNode root = ParseJsonFile(path.string());
  root.CheckKeys({"format", "name", "description", "crossfade_s", "start", "items"});
  if (root.GetString("format") != "irbench.session/1") root["format"].Fail("expected \"irbench.session/1\"");
  const double default_fade = root.GetDouble("crossfade_s", 0.3);
  if (default_fade < 0 || default_fade > 5) root["crossfade_s"].Fail("must be in 0..5 s");
  if (root.Has("start")) {
    const JsonNode start = root["start"];
    start.CheckKeys({"position", "heading_deg"});
    if (start.Has("position")) ctx.state.position = start["position"].Vec2();
    ctx.state.heading_deg = start.GetDouble("heading_deg", 0.0);
  }
  const JsonNode items = root["items"];
  if (items.Size() == 0) items.Fail("needs at least one item");
  std::vector<SequenceMotion::Item> sequence;
  for (size_t i = 0; i < items.Size(); ++i) {
    const JsonNode item = items[i];
    const std::string where = item.path();
    nlohmann::json params = item.raw();
    if (!params.is_object()) item.Fail("must be an object");
    const int kinds = item.Has("motion") + item.Has("clip") + item.Has("keyframes");
    if (kinds != 1) item.Fail("needs exactly one of \"motion\" (a library name), \"clip\" (a BVH/AMC file) "
                              "or \"keyframes\" (a keyframe file)");
    const double fade = item.GetDouble("crossfade_s", default_fade);
    if (fade < 0 || fade > 5) item["crossfade_s"].Fail("must be in 0..5 s");
    const bool mirror = item.GetBool("mirror", false);
    const double speed = item.GetDouble("speed", 1.0);
    if (speed < 0.1 || speed > 10) item["speed"].Fail("must be in 0.1..10");
    const int repeat = item.GetInt("repeat", 1);
    if (repeat < 1 || repeat > 100) item["repeat"].Fail("must be in 1..100");
    for (const char* common : {"crossfade_s", "mirror", "speed", "repeat"}) params.erase(common);
    MotionPtr motion;
    if (item.Has("motion")) {
      const std::string name = item.GetString("motion");
      params.erase("motion");
      motion = BuildLibraryMotion(name, params.empty() ? nlohmann::json(nullptr) : params, ctx,
                                  path.string(), where);
    } else {
      const bool is_clip = item.Has("clip");
      const std::string file = item.GetString(is_clip ? "clip" : "keyframes");
      if (is_clip) {
        item.CheckKeys({"clip", "start_s", "end_s", "crossfade_s", "mirror", "speed", "repeat"});
      } else {
        item.CheckKeys({"keyframes", "crossfade_s", "mirror", "speed", "repeat"});
      }
      fs::path file_path = file;
      if (file_path.is_relative()) file_path = path.parent_path() / file_path;
      if (!fs::is_regular_file(file_path)) {
        if (!is_clip) file_path = ResolveDataFile("motions", file, where + ".keyframes");
        else item["clip"].Fail("no such file '" + file_path.string() + "'");
      }
      motion = is_clip ? LoadClip(file_path, ctx, item.GetDouble("start_s", 0.0), item.GetDouble("end_s", 0.0))
                       : LoadKeyframeFile(file_path, ctx);
    }
    if (mirror) motion = std::make_shared<MirrorMotion>(motion);
    if (speed != 1.0) motion = TimeWarpMotion::Speed(motion, speed);
    if (repeat > 1) motion = LoopMotion(motion, repeat, fade);
    sequence.push_back({motion, fade});
  }
  return std::make_shared<SequenceMotion>(root.GetString("name", path.stem().string()), std::move(sequence));
}

ResolvedMotion ResolveMotion(const std::string& spec, MotionContext& ctx, const std::string& option) {
  if (spec.empty()) throw InputError("", option, "empty motion");
  const fs::path as_path(spec);
  const std::string ext = AsciiLower(as_path.extension().string());
  if (ext == ".bvh" || ext == ".amc") {
    if (!fs::is_regular_file(as_path)) throw InputError(spec, option, "no such file");
    return {LoadClip(as_path, ctx, 0, 0), ext.substr(1), as_path};
  }
  const bool looks_like_path = spec.find('/') != std::string::npos || as_path.has_extension();
  if (!looks_like_path && IsLibraryName(spec) &&
      !fs::is_regular_file(DataRoot() / "motions" / (spec + ".json"))) {
    return {BuildLibraryMotion(spec, nullptr, ctx, "", option), "library", {}};
  }
  if (!looks_like_path && !fs::is_regular_file(DataRoot() / "motions" / (spec + ".json"))) {
    std::string names;
    for (const auto& [n, text] : LibraryMotions()) names += (names.empty() ? "" : ", ") + n;
    std::string files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(DataRoot() / "motions", ec)) {
      if (entry.path().extension() == ".json") files += (files.empty() ? "" : ", ") + entry.path().stem().string();
    }
    throw InputError("", option, "unknown motion '" + spec + "' (library: " + names + "; files in motions/: " +
                                     files + "; or a path to a .json, .bvh or .amc file)");
  }
  const fs::path file = ResolveDataFile("motions", spec, option);
  const JsonNode root = ParseJsonFile(file.string());
  const std::string format = root.GetString("format", "");
  if (format == "irbench.session/1") return {LoadSession(file, ctx), "session", file};
  if (format == "irbench.keyframes/1") return {LoadKeyframeFile(file, ctx), "keyframes", file};
  root["format"].Fail("expected \"irbench.keyframes/1\" or \"irbench.session/1\"");
}

}  // namespace irbench
