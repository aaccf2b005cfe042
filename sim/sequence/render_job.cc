#include "sim/sequence/render_job.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <future>
#include <memory>

#include "common/atomic_file.h"
#include "common/cancel.h"
#include "common/error.h"
#include "common/logging.h"
#include "common/progress.h"
#include "common/paths.h"
#include "sequence_format/calibration.h"
#include "sequence_format/manifest.h"
#include "sequence_format/screens.h"
#include "sim/motion/bvh.h"
#include "sim/sensor/exposure.h"
#include "sim/sequence/image_io.h"
#include "sim/sequence/render_resume.h"
#include "sim/sequence/sequence_video.h"

namespace irbench {
namespace fs = std::filesystem;

namespace {

double TruthTolerance(const Avatar& avatar, const std::string& joint_name) {
  // "left_elbow" -> "elbow"; a point is seen when the surface at its pixel lies
  // within its body radius (plus 3 cm of slack for the skin's curvature).
  std::string key = joint_name;
  for (const char* prefix : {"left_", "right_"}) {
    if (key.rfind(prefix, 0) == 0) key = key.substr(std::string(prefix).size());
  }
  const auto it = avatar.truth_radius.find(key);
  const double radius = it != avatar.truth_radius.end() ? it->second : 0.05;
  return key == "root" ? 0.05 : radius + 0.03;
}

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

double ScreenSweepLevel(int index, int count) {
  if (count < 2) return 1.0;
  return kSweepLow + (kSweepHigh - kSweepLow) * index / (count - 1);
}

bool SweepsScreens(const RenderJobOptions& options, const RenderInputs& in) {
  return options.screen_sweep && std::find(in.sensor_active.begin(), in.sensor_active.end(), true) != in.sensor_active.end();
}

RenderInputs LoadRenderInputs(const RenderJobOptions& options) {
  RenderInputs in;
  const auto preset = SensorPreset(options.sensor);
  if (!preset) {
    throw InputError("", "--sensor", "unknown preset '" + options.sensor + "' (clean, thesis, harsh)");
  }
  in.models_sensor = preset->models_sensor;
  if (options.frames && (*options.frames < 1 || *options.frames > 1000000)) {
    throw InputError("", "--frames", "must be in 1..1000000");
  }
  if (options.background_frames < 0 || options.background_frames > 10000) {
    throw InputError("", "--background-frames", "must be in 0..10000");
  }
  if (options.supersample < 1 || options.supersample > 4) {
    throw InputError("", "--supersample", "must be in 1..4");
  }
  in.rig_file = ResolveDataFile("rigs", options.rig, "--rig");
  in.rig = LoadRig(in.rig_file);
  const std::string scene_name = options.scene.empty() ? in.rig.scene : options.scene;
  if (scene_name.empty()) throw InputError("", "--scene", "not given and the rig names no scene");
  in.scene_file = ResolveDataFile("scenes", scene_name, "--scene");
  in.scene = LoadScene(in.scene_file);
  in.avatar_file = ResolveDataFile("avatars", options.avatar, "--avatar");
  in.avatar = LoadAvatar(in.avatar_file);
  MotionContext ctx;
  ctx.avatar = &in.avatar;
  ctx.scene = &in.scene;
  ctx.style = StyleFor(in.avatar.params.name, options.seed, in.avatar.params.style, in.avatar_file.string());
  in.style = ctx.style;
  const ResolvedMotion resolved = ResolveMotion(options.motion, ctx, "--motion");
  in.motion = resolved.motion;
  in.motion_kind = resolved.kind;
  in.motion_file = resolved.file;
  in.motion_name = in.motion->name();
  in.fps = in.rig.timing.front().fps;
  for (size_t i = 1; i < in.rig.timing.size(); ++i) {
    if (in.rig.timing[i].fps != in.fps) {
      throw InputError(in.rig_file.string(), "cameras[" + std::to_string(i) + "].fps",
                       "differs from cameras[0].fps; per-camera clocks are not supported yet");
    }
  }
  for (size_t i = 0; i < in.rig.cameras.size(); ++i) {
    SensorSetup setup = *preset;
    const nlohmann::json& overrides = in.rig.sensor_overrides[i];
    if (!overrides.is_null()) {
      ApplySensorOverrides(overrides, in.rig_file.string(), "cameras[" + std::to_string(i) + "].sensor",
                           &setup);
    }
    in.sensor_active.push_back(preset->models_sensor || !overrides.is_null());
    in.sensors.push_back(setup);
  }
  in.frame_count = options.frames.value_or(
      static_cast<int>(std::floor(in.motion->Duration() * in.fps + 1e-9)) + 1);
  return in;
}

RenderOptions RenderOptionsFor(const RenderJobOptions& options, const RenderInputs& in) {
  RenderOptions render_options;
  render_options.supersample = options.supersample;
  render_options.shadows = options.shadows.value_or(in.models_sensor);
  render_options.static_cache = options.static_cache;
  render_options.static_cache_min_pixels = options.static_cache_min_pixels;
  return render_options;
}

JointTransforms PoseAndUpload(const RenderInputs& inputs,
                              double t,
                              Renderer& renderer,
                              std::vector<MeshVertex>& skinned) {
  const Pose pose = inputs.motion->At(t);
  const JointTransforms world_from_joint = ForwardKinematics(inputs.avatar.skeleton, pose);
  SkinVertices(inputs.avatar, world_from_joint, skinned);
  renderer.UpdatePerson(skinned);
  return world_from_joint;
}

FrameTruth ComputeFrameTruth(const RenderInputs& inputs,
                             const JointTransforms& world_from_joint,
                             const Renderer& renderer) {
  FrameTruth truth;
  truth.joints3d = TruthJoints(inputs.avatar, world_from_joint);
  const auto& names = TruthJointNames();
  for (size_t c = 0; c < renderer.cameras().size(); ++c) {
    const Camera& cam = renderer.cameras()[c];
    std::vector<Eigen::Vector3d> per_joint;
    for (size_t j = 0; j < names.size(); ++j) {
      const Eigen::Vector2d px = cam.Project(truth.joints3d[j]);
      const bool is_root = names[j] == "root";
      const Visibility vis = renderer.PointVisibility(
          static_cast<int>(c), truth.joints3d[j], TruthTolerance(inputs.avatar, names[j]), !is_root);
      per_joint.emplace_back(px.x(), px.y(), static_cast<double>(vis));
    }
    truth.joints2d.push_back(per_joint);
  }
  return truth;
}

namespace {

// The files a render reads: scene, rig, avatar (and its mesh), motion.
std::vector<fs::path> RenderInputFiles(const RenderInputs& in) {
  std::vector<fs::path> files = {in.scene_file, in.rig_file, in.avatar_file, in.motion_file};
  const nlohmann::json& source = in.avatar.params.source;
  if (source.is_object() && source.contains("file") && source["file"].is_string()) {
    files.push_back(source["file"].get<std::string>());
  }
  return files;
}

// The sequence folder to write: --out, or renders/<rig>-<avatar>-<motion>-s<seed>.
// Throws InputError when its parent folder is missing, when it exists and
// --force was not given or irbench did not write it, or when it holds or lies
// in an input file; checked before the slow GL start.
fs::path OutputFolder(const RenderJobOptions& options, const RenderInputs& in) {
  fs::path out = options.out;
  if (out.empty()) {
    out = OutputRoot() / "renders" /
          (in.rig.name + "-" + in.avatar.params.name + "-" + in.motion_name + "-s" +
           std::to_string(options.seed));
    fs::create_directories(out.parent_path());  // the default's own folder
  }
  CheckOutputApart(out, RenderInputFiles(in), "--out");
  CheckOutputReplaceable(out, options.overwrite, "--out");
  return out;
}

// Creates the sequence folder's sub-folders under `root` (per camera:
// background/, frames/, truth/masks/ and, with `write_depth`, truth/depth/).
void CreateSequenceFolders(const fs::path& root, const RenderInputs& in, bool write_depth) {
  for (const char* dir : {"calib", "background", "frames", "truth", "truth/masks"}) {
    fs::create_directories(root / dir);
  }
  for (const Camera& cam : in.rig.cameras) {
    fs::create_directories(root / "background" / cam.name);
    fs::create_directories(root / "frames" / cam.name);
    fs::create_directories(root / "truth" / "masks" / cam.name);
    if (write_depth) fs::create_directories(root / "truth" / "depth" / cam.name);
  }
}

// Writes the rig's calibration (calib/intri.yml, calib/extri.yml,
// calib/cameras.json with the sensor setups) and the scene's screens
// (calib/screens.json) under `root`.
void WriteSequenceCalibration(const fs::path& root, const RenderInputs& in) {
  std::vector<nlohmann::json> sensors;
  for (const SensorSetup& sensor : in.sensors) sensors.push_back(SensorSetupJson(sensor));
  WriteCalibration(root, in.rig.cameras, in.rig.timing, sensors);
  WriteScreens(root, in.scene.name, in.scene.screens);
}

// The sequence's manifest.json (docs/architecture.md): what was rendered,
// from which inputs, with which renderer, and where its files lie.
nlohmann::json BuildManifest(const RenderJobOptions& options,
                             const RenderInputs& in,
                             bool sweep_screens,
                             const GlContext& context,
                             const RenderOptions& render_options) {
  nlohmann::json manifest;
  manifest[manifest_key::kFormat] = kSequenceFormat;
  manifest["tool_version"] = ToolVersion();
  manifest[manifest_key::kSeed] = options.seed;
  manifest[manifest_key::kScene] = {{manifest_key::kName, in.scene.name}, {"file", in.scene_file.filename().string()}};
  manifest[manifest_key::kRig] = {{manifest_key::kName, in.rig.name}, {"file", in.rig_file.filename().string()}};
  manifest[manifest_key::kAvatar] = {{manifest_key::kName, in.avatar.params.name},
                        {"file", in.avatar_file.filename().string()},
                        {"kind", in.avatar.params.kind},
                        {"build", in.avatar.params.build}};
  if (in.avatar.params.source.is_object()) {  // imported mesh: how its rig was read
    nlohmann::json source = in.avatar.params.source;
    source["file"] = fs::path(source["file"].get<std::string>()).filename().string();
    manifest[manifest_key::kAvatar]["source"] = source;
  }
  manifest[manifest_key::kMotion] = {{manifest_key::kName, in.motion_name},
                        {"file", in.motion_file.empty() ? nlohmann::json(nullptr)
                                                        : nlohmann::json(in.motion_file.filename().string())},
                        {"kind", in.motion_kind},
                        {"duration_s", in.motion->Duration()},
                        {"style", {{"tempo", in.style.tempo},
                                   {"amplitude", in.style.amplitude},
                                   {"asynchrony_s", in.style.asynchrony_s},
                                   {"tremor_deg", in.style.tremor_deg},
                                   {"tremor_hz", in.style.tremor_hz},
                                   {"handedness", in.style.handedness > 0 ? "right" : "left"}}}};
  manifest[manifest_key::kSensor] = options.sensor;
  manifest[manifest_key::kFps] = in.fps;
  manifest[manifest_key::kFrameCount] = in.frame_count;
  manifest["background_frame_count"] = options.background_frames;
  manifest["background_screen_sweep"] =
      sweep_screens ? nlohmann::json{{"from", kSweepLow}, {"to", kSweepHigh}} : nlohmann::json(nullptr);
  nlohmann::json camera_names = nlohmann::json::array();
  for (const Camera& cam : in.rig.cameras) camera_names.push_back(cam.name);
  manifest[manifest_key::kCameras] = camera_names;
  manifest["body_height_m"] = in.avatar.params.height_m;
  manifest[manifest_key::kJoints] = TruthJointNames();
  manifest["depth"] = options.write_depth;
  manifest["renderer"] = {{"backend", context.BackendName()},
                          {"gl", context.RendererString()},
                          {"supersample", options.supersample},
                          {"shadows", render_options.shadows}};
  manifest["files"] = {{"frames", "frames/<cam>/NNNNNN.png"},
                       {"background", "background/<cam>/NNNNNN.png"},
                       {"masks", "truth/masks/<cam>/NNNNNN.png"},
                       {"truth", "truth/frames.jsonl"},
                       {"background_truth", "truth/background.jsonl"},
                       {"events", "truth/events.json"},
                       {"motion_bvh", "truth/motion.bvh"}};
  if (options.write_depth) manifest["files"]["depth"] = "truth/depth/<cam>/NNNNNN.exr";
  if (options.write_video) {
    manifest["files"]["videos"] = std::string("videos/<cam>") + kVideoExtension;
    manifest["files"]["background_videos"] = std::string("background/<cam>") + kVideoExtension;
  }
  return manifest;
}

// The render's progress in frame-sets, per phase (background, frame):
// common/progress.h, a line rewritten in place on a terminal, a log line
// every few seconds otherwise.
class RenderProgress {
 public:
  RenderProgress() : start_(std::chrono::steady_clock::now()) {}

  // Counts frame-set `index` of `count` of `phase` done.
  void FrameSetDone(const char* phase, int index, int count) {
    if (!phase_ || phase_name_ != phase) {
      phase_.reset();  // ends the previous phase's line first
      phase_ = std::make_unique<Progress>("render", "frame-sets", count);
      phase_name_ = phase;
    }
    phase_->Set(index + 1, phase);
  }

  // Seconds since the progress began.
  double ElapsedS() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
  std::unique_ptr<Progress> phase_;
  std::string phase_name_;
};

// Motion blur: sub-frame renders over the exposure, averaged.
struct MotionBlurPlan {
  int samples = 1;          // sub-frame renders per frame
  double exposure_s = 0.0;  // the exposure they span
  // Sub-frame offsets (s) from the camera's instant, the final render at the
  // instant itself left out; with an odd count that is the centre one.
  std::vector<double> offsets;
  bool centre_counts = false;  // whether the final render is one of the samples
};

// The motion blur of the cameras with a sensor model: the most sub-frames any
// asks for, over the longest exposure of those blurring.
MotionBlurPlan PlanMotionBlur(const RenderInputs& in) {
  MotionBlurPlan blur;
  for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
    const CameraTiming& timing = in.rig.timing[c];
    const SensorSetup& setup = in.sensors[c];
    if (!in.sensor_active[c]) continue;
    if (setup.optics.motion_blur_samples > blur.samples) blur.samples = setup.optics.motion_blur_samples;
    if (setup.optics.motion_blur_samples > 1) {
      blur.exposure_s = std::max(blur.exposure_s, timing.exposure_ms / 1000.0);
    }
  }
  for (int k = 0; blur.samples > 1 && k < blur.samples; ++k) {
    const double offset = ((k + 0.5) / blur.samples - 0.5) * blur.exposure_s;
    if (std::abs(offset) > 1e-12) blur.offsets.push_back(offset);
  }
  blur.centre_counts = blur.samples > 1 && blur.samples % 2 == 1;
  return blur;
}

// Whether the frames' final renders need depth: written with --depth, or
// read by a camera's defocus.
bool NeedsDepth(const RenderJobOptions& options, const RenderInputs& in) {
  bool need_depth = options.write_depth;
  for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
    if (!in.sensor_active[c]) continue;
    need_depth = need_depth || in.sensors[c].optics.f_number > 0;
  }
  return need_depth;
}

// What the render steps share: the job and its inputs, the renderer and its
// last images, the sequence folder being written and the sensor chains.
struct RenderRun {
  const RenderJobOptions& options;
  const RenderInputs& in;
  Renderer& renderer;
  const fs::path& root;  // the staging folder
  RigExposure& exposure;
  RenderProgress& progress;
  bool need_depth;
  std::vector<CameraImages> all_images;  // per camera, reused by every render
};

// Camera images as the sensor chain reads them.
CleanRender CleanRenderOf(const CameraImages& images) {
  return {images.grey, images.radiance, images.depth};
}

// The rig's camera names, in order.
std::vector<std::string> CameraNames(const RenderInputs& in) {
  std::vector<std::string> names;
  for (const Camera& cam : in.rig.cameras) names.push_back(cam.name);
  return names;
}

// Where a frame loop starts: the first frame-set to render, and those before
// `kept` (rendered again only to restore the cameras' state) checked against
// the kept files and `kept_lines` instead of written (render_resume.h).
struct ResumeFrom {
  const std::vector<std::string>& kept_lines;
  int kept = 0;
  int first = 0;
};

ResumeFrom ResumeFromKept(const std::vector<std::string>& kept_lines, const RenderInputs& in) {
  return {kept_lines, static_cast<int>(kept_lines.size()), ReplayStart(kept_lines, CameraNames(in))};
}

// Frame-set f's truth line `line`: appended to `lines` and the journal, or,
// rendered again, checked against the kept one.
void KeepTruthLine(RenderRun& run, const char* kind, const ResumeFrom& from, int f, const std::string& line,
                   std::string& lines) {
  if (f < from.kept) {
    if (line != from.kept_lines[f]) throw ResumeMismatch(std::string(kind) + " truth line " + std::to_string(f) + " differs");
    return;
  }
  lines += line;
  AppendToJournal(run.root, kind, line);
}

// Renders and writes the empty-stage frames (background/<cam>/), at the
// camera rate before t = 0 (`background_s` s of them), with the screens'
// calibration sweep when `sweep_screens`; returns truth/background.jsonl.
// Resumed, carries on after the `kept` frame-sets.
std::string RenderBackground(RenderRun& run,
                             bool sweep_screens,
                             double background_s,
                             const std::vector<std::string>& kept) {
  const RenderInputs& in = run.in;
  const int count = run.options.background_frames;
  std::string background_lines;
  for (const std::string& line : kept) background_lines += line;
  const ResumeFrom from = ResumeFromKept(kept, in);
  run.renderer.SetPersonVisible(false);
  // The empty stage looks the same in every frame-set until the sensor sees
  // it (the screens' content, flicker, sweep and noise are the exposure's):
  // rendered once, exposed once per frame-set.
  bool rendered = false;
  for (int f = from.kept < count ? from.first : count; f < count; ++f) {
    ThrowIfCancelled();
    if (!rendered) run.renderer.RenderAll(&run.all_images, run.need_depth);
    rendered = true;
    const double t = f / in.fps - background_s;
    nlohmann::json sensor_truth = nlohmann::json::object();
    const double sweep = sweep_screens ? ScreenSweepLevel(f, count) : -1.0;
    for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
      const cv::Mat frame = run.exposure.Expose(c, CleanRenderOf(run.all_images[c]), cv::Mat(), 1, t,
                                                (1ull << 40) + f, sensor_truth, sweep);
      WriteOrVerify(run.root / "background" / in.rig.cameras[c].name / FrameFileName(f, "png"), EncodePng(frame),
                    f < from.kept);
    }
    const std::string line = nlohmann::json{{"frame", f}, {"t", t}, {"sensor", sensor_truth}}.dump() + "\n";
    KeepTruthLine(run, "background", from, f, line, background_lines);
    run.progress.FrameSetDone("background", f, count);
  }
  return background_lines;
}

// Each camera's capture instant (s) for frame f at time t: t, plus the
// camera's seeded sync jitter if it has one; sets *jittered when any has.
std::vector<double> CaptureInstants(const RenderInputs& in, uint64_t seed, int f, double t, bool* jittered) {
  std::vector<double> instant(in.rig.cameras.size(), t);
  for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
    const double jitter_s = in.sensor_active[c] ? in.sensors[c].capture.sync_jitter_ms / 1000.0 : 0.0;
    if (jitter_s <= 0) continue;
    float z0, z1;
    StandardNormalPair(MixHash(MixHash(seed, 0x5C1Cull + c), uint64_t(f)), &z0, &z1);
    instant[c] = t + jitter_s * z0;
    *jittered = true;
  }
  return instant;
}

// Adds a sub-frame's radiance `sources` to `sum` (a copy when `sum` is empty).
void Accumulate(cv::Mat& sum, const cv::Mat& sources) {
  if (sum.empty()) sum = sources.clone(); else sum += sources;
}

// Renders one frame-set into run.all_images, each camera at `instant[c]` (s),
// the final render of each at its instant; with motion blur, the sub-frames'
// radiance (and the final one's when it counts) is summed into
// `radiance_sums`. Unless `jittered`, the cameras share every render.
void RenderFrameSet(RenderRun& run,
                    const MotionBlurPlan& blur,
                    double t,
                    const std::vector<double>& instant,
                    bool jittered,
                    std::vector<MeshVertex>& skinned,
                    std::vector<cv::Mat>& radiance_sums) {
  const RenderInputs& in = run.in;
  std::vector<CameraImages>& all_images = run.all_images;
  for (cv::Mat& sum : radiance_sums) sum.release();
  if (!jittered) {
    // Synchronised cameras share every render.
    for (double offset : blur.offsets) {
      PoseAndUpload(in, t + offset, run.renderer, skinned);
      run.renderer.RenderAll(&all_images, false);
      for (size_t c = 0; c < all_images.size(); ++c) Accumulate(radiance_sums[c], all_images[c].radiance);
    }
    PoseAndUpload(in, t, run.renderer, skinned);
    run.renderer.RenderAll(&all_images, run.need_depth);
    for (size_t c = 0; blur.centre_counts && c < all_images.size(); ++c) {
      Accumulate(radiance_sums[c], all_images[c].radiance);
    }
  } else {
    // Each camera sees the person at its own instant (skinned per camera).
    all_images.resize(in.rig.cameras.size());
    for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
      for (double offset : blur.offsets) {
        PoseAndUpload(in, instant[c] + offset, run.renderer, skinned);
        run.renderer.Render(static_cast<int>(c), &all_images[c], false);
        Accumulate(radiance_sums[c], all_images[c].radiance);
      }
      PoseAndUpload(in, instant[c], run.renderer, skinned);
      run.renderer.Render(static_cast<int>(c), &all_images[c], run.need_depth);
      if (blur.centre_counts) Accumulate(radiance_sums[c], all_images[c].radiance);
    }
  }
}

// Exposes frame f (time t, s) of every camera from run.all_images and writes
// it, its mask and (with --depth) its depth, or with `verify` checks the
// frame and mask against the files there; returns the sensor truth per
// camera, with each camera's sync offset (ms).
nlohmann::json ExposeAndWriteFrameSet(RenderRun& run,
                                      const MotionBlurPlan& blur,
                                      int f,
                                      double t,
                                      const std::vector<double>& instant,
                                      const std::vector<cv::Mat>& radiance_sums,
                                      bool verify) {
  const RenderInputs& in = run.in;
  const fs::path& root = run.root;
  // Each camera's sensor chain and PNG encoding on a thread of its own (the
  // chains share nothing); the files are written here, in camera order.
  struct Encoded {
    nlohmann::json truth = nlohmann::json::object();
    std::string frame_png, mask_png;
  };
  std::vector<Encoded> encoded(in.rig.cameras.size());
  std::vector<std::future<void>> done;
  for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
    done.push_back(std::async(std::launch::async, [&run, &blur, &instant, &radiance_sums, &encoded, c, f] {
      Encoded& e = encoded[c];
      const cv::Mat frame = run.exposure.Expose(c, CleanRenderOf(run.all_images[c]), radiance_sums[c],
                                                blur.samples, instant[c], f, e.truth);
      e.frame_png = EncodePng(frame);
      e.mask_png = EncodePng(run.all_images[c].mask);
    }));
  }
  for (std::future<void>& d : done) d.get();
  nlohmann::json sensor_truth = nlohmann::json::object();
  for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
    const std::string& cam_name = in.rig.cameras[c].name;
    sensor_truth[cam_name] = std::move(encoded[c].truth[cam_name]);
    sensor_truth[cam_name]["sync_offset_ms"] = (instant[c] - t) * 1000.0;
    WriteOrVerify(root / "frames" / cam_name / FrameFileName(f, "png"), encoded[c].frame_png, verify);
    WriteOrVerify(root / "truth" / "masks" / cam_name / FrameFileName(f, "png"), encoded[c].mask_png, verify);
    if (run.options.write_depth && !verify) {
      WriteDepthExrAtomic(root / "truth" / "depth" / cam_name / FrameFileName(f, "exr"),
                          run.all_images[c].depth);
    }
  }
  return sensor_truth;
}

// Frame f's line of truth/frames.jsonl (time t, s): whether the person is on
// the stage, the joints in the world (m) and in each camera (px, visibility),
// the motion's labels and pointing, and the sensor truth.
nlohmann::json TruthLine(const RenderInputs& in,
                         const Labeler& labeler,
                         int f,
                         double t,
                         const FrameTruth& truth,
                         const nlohmann::json& sensor_truth) {
  const auto& joint_names = TruthJointNames();
  nlohmann::json line;
  line["frame"] = f;
  line["t"] = t;
  const Eigen::Vector3d& root_point = truth.joints3d[0];
  const Eigen::Vector2d stage_offset = root_point.head<2>() - in.scene.stage_center;
  line["present"] = std::abs(stage_offset.x()) <= in.scene.stage_size.x() / 2 &&
                    std::abs(stage_offset.y()) <= in.scene.stage_size.y() / 2;
  nlohmann::json joints3d = nlohmann::json::object();
  for (size_t j = 0; j < joint_names.size(); ++j) joints3d[joint_names[j]] = Vec(truth.joints3d[j]);
  line["joints3d"] = joints3d;
  nlohmann::json joints2d = nlohmann::json::object();
  std::vector<int> views(joint_names.size(), 0);
  for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
    nlohmann::json per_cam = nlohmann::json::object();
    for (size_t j = 0; j < joint_names.size(); ++j) {
      const Eigen::Vector3d& uvv = truth.joints2d[c][j];
      const int vis = static_cast<int>(uvv.z());
      per_cam[joint_names[j]] = {uvv.x(), uvv.y(), vis};
      if (vis == 2) ++views[j];
    }
    joints2d[in.rig.cameras[c].name] = per_cam;
  }
  line["joints2d"] = joints2d;
  // How many cameras see each joint (vis 2): how hidden a pose is.
  nlohmann::json joint_views = nlohmann::json::object();
  for (size_t j = 0; j < joint_names.size(); ++j) joint_views[joint_names[j]] = views[j];
  line["views"] = joint_views;
  line["labels"] = labeler.Labels(t);
  line["pointing"] = labeler.Pointing(t);
  line["sensor"] = sensor_truth;
  return line;
}

// Renders and writes the sequence's frames from t = 0 (frames/, truth/masks/,
// truth/depth/). With motion blur, sub-frames over the exposure are rendered
// and averaged; the last render is always at the frame time, so masks, depth
// and visibility belong to the truth's instant. Returns truth/frames.jsonl.
// Resumed, carries on after the `kept` frame-sets.
std::string RenderSequence(RenderRun& run, const MotionBlurPlan& blur, const std::vector<std::string>& kept) {
  const RenderInputs& in = run.in;
  run.renderer.SetPersonVisible(true);
  std::vector<MeshVertex> skinned;
  std::string truth_lines;
  for (const std::string& line : kept) truth_lines += line;
  const ResumeFrom from = ResumeFromKept(kept, in);
  const Labeler labeler(in.avatar, &in.scene, *in.motion);
  std::vector<cv::Mat> radiance_sums(in.rig.cameras.size());
  for (int f = from.kept < in.frame_count ? from.first : in.frame_count; f < in.frame_count; ++f) {
    ThrowIfCancelled();
    const double t = f / in.fps;
    bool jittered = false;
    const std::vector<double> instant = CaptureInstants(in, run.options.seed, f, t, &jittered);
    RenderFrameSet(run, blur, t, instant, jittered, skinned, radiance_sums);
    const JointTransforms world_from_joint =
        ForwardKinematics(in.avatar.skeleton, in.motion->At(t));
    const nlohmann::json sensor_truth =
        ExposeAndWriteFrameSet(run, blur, f, t, instant, radiance_sums, f < from.kept);
    const FrameTruth truth = ComputeFrameTruth(in, world_from_joint, run.renderer);
    KeepTruthLine(run, "frames", from, f, TruthLine(in, labeler, f, t, truth, sensor_truth).dump() + "\n",
                  truth_lines);
    run.progress.FrameSetDone("frame", f, in.frame_count);
  }
  return truth_lines;
}

// Writes the motion's events (truth/events.json: times in s and the frames
// they span) and the motion itself (truth/motion.bvh) under `root`.
void WriteMotionTruth(const fs::path& root, const RenderInputs& in) {
  nlohmann::json events = nlohmann::json::array();
  for (const MotionEvent& e : in.motion->Events()) {
    events.push_back({{"kind", e.kind},
                      {"value", e.value},
                      {"side", e.side.empty() ? nlohmann::json(nullptr) : nlohmann::json(e.side)},
                      {"start_s", e.start},
                      {"end_s", e.end},
                      {"start_frame", static_cast<int>(std::ceil(e.start * in.fps - 1e-9))},
                      {"end_frame", static_cast<int>(std::floor(e.end * in.fps + 1e-9))}});
  }
  AtomicWriteFile(root / "truth" / "events.json", events.dump(2) + "\n");
  AtomicWriteFile(root / "truth" / "motion.bvh", WriteBvh(MotionToBvh(*in.motion, in.avatar.skeleton, in.fps, in.frame_count)));
}

}  // namespace

namespace {

// The job's parts once GL is up: the inputs, the renderer and the staging
// folder's root.
struct RenderSetup {
  const RenderJobOptions& options;
  const RenderInputs& in;
  Renderer& renderer;
  fs::path root;
  bool sweep_screens = false;
};

// Creates the folders, writes the calibration, renders the empty-stage frames
// and the sequence after what `kept` holds, and writes the truth files.
void RenderFrameSets(const RenderSetup& setup, const RenderJournal& kept) {
  const RenderJobOptions& options = setup.options;
  const RenderInputs& in = setup.in;
  CreateSequenceFolders(setup.root, in, options.write_depth);
  WriteSequenceCalibration(setup.root, in);
  RenderProgress progress;
  // The sensor model per camera; background frames come before t = 0.
  const double background_s = options.background_frames / in.fps;
  RigExposure exposure(in.rig.cameras, in.rig.timing, in.sensors, in.sensor_active, options.seed, -background_s,
                       in.frame_count / in.fps);
  const MotionBlurPlan blur = PlanMotionBlur(in);
  RenderRun run{options, in, setup.renderer, setup.root, exposure, progress, NeedsDepth(options, in), {}};
  const std::string background_lines = RenderBackground(run, setup.sweep_screens, background_s, kept.background_lines);
  exposure.ForgetLastFrames();
  const std::string truth_lines = RenderSequence(run, blur, kept.frame_lines);
  AtomicWriteFile(setup.root / "truth" / "frames.jsonl", truth_lines);
  AtomicWriteFile(setup.root / "truth" / "background.jsonl", background_lines);
  WriteMotionTruth(setup.root, in);
  Log().info("render: {} frame-sets ({} cameras) in {:.1f} s", options.background_frames + in.frame_count,
             in.rig.cameras.size(), progress.ElapsedS());
}

}  // namespace

fs::path RunRenderJob(const RenderJobOptions& options) {
  // 1. Everything from outside is checked before anything is created.
  const RenderInputs in = LoadRenderInputs(options);
  const bool sweep_screens = SweepsScreens(options, in);
  const fs::path out = OutputFolder(options, in);

  // 2. GL and the renderer.
  auto context = CreateGlContext(options.backend);
  Log().info("render: {} backend, {}", context->BackendName(), context->RendererString());
  const RenderOptions render_options = RenderOptionsFor(options, in);
  Renderer renderer(*context, in.rig.cameras, render_options);
  renderer.SetScene(in.scene);
  renderer.SetPersonTopology(in.avatar.indices, in.avatar.bind_vertices.size());

  // 3. The staging folder (with --resume, a dead render's of the same
  // options, adopted) and its journal (render_resume.h).
  StagingDir staging(out, options.overwrite, "--out", "render",
                     options.resume ? StagingDir::Stale::kAdopt : StagingDir::Stale::kRemove);
  if (options.resume && !staging.adopted()) Log().info("render: no unfinished render of {} to resume", out.string());
  const nlohmann::json manifest = BuildManifest(options, in, sweep_screens, *context, render_options);
  const std::string hash = RenderOptionsHash(manifest, RenderInputFiles(in));
  const RenderLayout layout{CameraNames(in), options.background_frames, in.frame_count, options.write_depth};
  const RenderSetup setup{options, in, renderer, staging.path(), sweep_screens};

  // 4. The frames, then the truth files and the manifest.
  try {
    RenderFrameSets(setup, StartRenderJournal(staging, hash, layout));
  } catch (const ResumeMismatch& e) {
    Log().warn("render: {}: the kept frames were not rendered this way; starting over", e.what());
    staging.Clear();
    RenderFrameSets(setup, StartRenderJournal(staging, hash, layout));
  }
  RemoveRenderJournal(staging.path());
  if (options.write_video) {
    Log().info("render: writing one FFV1 video per camera");
    WriteSequenceVideos(staging.path(), CameraNames(in), in.frame_count, options.background_frames, in.fps);
  }
  WriteManifest(staging.path(), manifest);
  ThrowIfCancelled();
  staging.Commit();
  return staging.final_path();
}

}  // namespace irbench
