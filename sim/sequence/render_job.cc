#include "sim/sequence/render_job.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

#include "common/atomic_file.h"
#include "common/cancel.h"
#include "common/error.h"
#include "common/logging.h"
#include "common/paths.h"
#include "sim/sequence/calib_io.h"
#include "sim/sequence/image_io.h"
#include "sim/motion/bvh.h"
#include "sim/sensor/flicker.h"

namespace irbench {
namespace fs = std::filesystem;

namespace {

std::string FrameName(int frame, const char* ext) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%06d.%s", frame, ext);
  return buffer;
}

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
  in.fps = in.rig.cameras.front().fps;
  for (size_t i = 1; i < in.rig.cameras.size(); ++i) {
    if (in.rig.cameras[i].fps != in.fps) {
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
    in.sensor_active.push_back(options.sensor != "clean" || !overrides.is_null());
    in.sensors.push_back(setup);
  }
  in.frame_count = options.frames.value_or(
      static_cast<int>(std::floor(in.motion->Duration() * in.fps + 1e-9)) + 1);
  return in;
}

RenderOptions RenderOptionsFor(const RenderJobOptions& options) {
  RenderOptions render_options;
  render_options.supersample = options.supersample;
  render_options.shadows = options.shadows.value_or(options.sensor != "clean");
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

fs::path RunRenderJob(const RenderJobOptions& options) {
  // 1. Everything from outside is checked before anything is created.
  const RenderInputs in = LoadRenderInputs(options);
  const bool sweep_screens = SweepsScreens(options, in);
  fs::path out = options.out;
  if (out.empty()) {
    out = DataRoot() / "renders" /
          (in.rig.name + "-" + in.avatar.params.name + "-" + in.motion_name + "-s" +
           std::to_string(options.seed));
  }
  // Checks the parent folder and an existing output before the slow GL start.
  if (!fs::is_directory(fs::absolute(out).parent_path())) {
    throw InputError("", "--out", "parent folder '" + fs::absolute(out).parent_path().string() +
                                      "' does not exist");
  }
  if (fs::exists(out) && !options.overwrite) {
    throw InputError("", "--out", "'" + out.string() + "' exists (pass --force to replace it)");
  }

  // 2. GL and the renderer.
  auto context = CreateGlContext(options.backend);
  Log().info("render: {} backend, {}", context->BackendName(), context->RendererString());
  const RenderOptions render_options = RenderOptionsFor(options);
  Renderer renderer(*context, in.rig.cameras, render_options);
  renderer.SetScene(in.scene);
  renderer.SetPersonTopology(in.avatar.indices, in.avatar.bind_vertices.size());

  // 3. The staging folder and the static files.
  StagingDir staging(out, options.overwrite, "--out");
  const fs::path root = staging.path();
  for (const char* dir : {"calib", "background", "frames", "truth", "truth/masks"}) {
    fs::create_directories(root / dir);
  }
  for (const Camera& cam : in.rig.cameras) {
    fs::create_directories(root / "background" / cam.name);
    fs::create_directories(root / "frames" / cam.name);
    fs::create_directories(root / "truth" / "masks" / cam.name);
    if (options.write_depth) fs::create_directories(root / "truth" / "depth" / cam.name);
  }
  AtomicWriteFile(root / "calib" / "intri.yml", IntriYaml(in.rig.cameras));
  AtomicWriteFile(root / "calib" / "extri.yml", ExtriYaml(in.rig.cameras));
  AtomicWriteFile(root / "calib" / "cameras.json",
                  CamerasJson(in.rig.cameras, in.sensors).dump(2) + "\n");
  AtomicWriteFile(root / "calib" / "screens.json", in.scene.ScreensJson().dump(2) + "\n");

  nlohmann::json manifest;
  manifest["format"] = "irbench.sequence/1";
  manifest["tool_version"] = ToolVersion();
  manifest["seed"] = options.seed;
  manifest["scene"] = {{"name", in.scene.name}, {"file", in.scene_file.filename().string()}};
  manifest["rig"] = {{"name", in.rig.name}, {"file", in.rig_file.filename().string()}};
  manifest["avatar"] = {{"name", in.avatar.params.name},
                        {"file", in.avatar_file.filename().string()},
                        {"kind", in.avatar.params.kind},
                        {"build", in.avatar.params.build}};
  if (in.avatar.params.source.is_object()) {  // imported mesh: how its rig was read
    nlohmann::json source = in.avatar.params.source;
    source["file"] = fs::path(source["file"].get<std::string>()).filename().string();
    manifest["avatar"]["source"] = source;
  }
  manifest["motion"] = {{"name", in.motion_name},
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
  manifest["sensor"] = options.sensor;
  manifest["fps"] = in.fps;
  manifest["frame_count"] = in.frame_count;
  manifest["background_frame_count"] = options.background_frames;
  manifest["background_screen_sweep"] =
      sweep_screens ? nlohmann::json{{"from", kSweepLow}, {"to", kSweepHigh}} : nlohmann::json(nullptr);
  nlohmann::json camera_names = nlohmann::json::array();
  for (const Camera& cam : in.rig.cameras) camera_names.push_back(cam.name);
  manifest["cameras"] = camera_names;
  manifest["body_height_m"] = in.avatar.params.height_m;
  manifest["joints"] = TruthJointNames();
  manifest["depth"] = options.write_depth;
  manifest["renderer"] = {{"backend", context->BackendName()},
                          {"gl", context->RendererString()},
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

  const auto start = std::chrono::steady_clock::now();
  auto last_report = start;
  const int total = options.background_frames + in.frame_count;
  int done = 0;
  auto report = [&](const char* phase, int index, int count) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_report < std::chrono::seconds(1) && index + 1 < count) return;
    last_report = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    Log().info("render: {} {}/{} ({:.1f} frame-sets/s)", phase, index + 1, count,
               elapsed > 0 ? done / elapsed : 0.0);
  };

  // The sensor model per camera; background frames come before t = 0.
  const double background_s = options.background_frames / in.fps;
  std::vector<SensorModel> sensors;
  std::vector<FlickerModel> flickers;
  std::vector<Optics> optics;
  int blur_samples = 1;           // sub-frame renders per frame (motion blur)
  double blur_exposure_s = 0.0;   // the exposure they span
  bool need_depth = options.write_depth;
  for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
    const Camera& cam = in.rig.cameras[c];
    const SensorSetup& setup = in.sensors[c];
    sensors.emplace_back(setup.sensor, options.seed, cam.name, cam.width, cam.height);
    flickers.emplace_back(setup.flicker, options.seed, -background_s, in.frame_count / in.fps);
    optics.emplace_back(setup.optics, cam);
    if (!in.sensor_active[c]) continue;
    if (setup.optics.motion_blur_samples > blur_samples) blur_samples = setup.optics.motion_blur_samples;
    if (setup.optics.motion_blur_samples > 1) {
      blur_exposure_s = std::max(blur_exposure_s, cam.exposure_ms / 1000.0);
    }
    need_depth = need_depth || setup.optics.f_number > 0;
  }
  // Turns camera c's render (its radiance per source, or their mean over the
  // exposure's sub-frames, `radiance_sum` / `samples`) into the written frame:
  // the illuminators' light follows the mains, the screens' content light the
  // content's flicker, each row its own with a rolling shutter; the 940 nm
  // light counts by the sensor's relative quantum efficiency. A `sweep` level
  // of 0 or more replaces the content's (the calibration sweep of empty-stage
  // frames). Records the levels, exposure and drops in `sensor_truth`.
  std::vector<cv::Mat> last_written(in.rig.cameras.size());
  std::vector<double> last_flicker(in.rig.cameras.size(), 1.0);  // of the image a drop repeats
  cv::Mat radiance;
  auto expose = [&](size_t c, const CameraImages& images, const cv::Mat& radiance_sum, int samples,
                    double t, uint64_t noise_frame, nlohmann::json& sensor_truth, double sweep = -1) -> cv::Mat {
    const Camera& cam = in.rig.cameras[c];
    if (!in.sensor_active[c]) {
      sensor_truth[cam.name] = {{"flicker", 1.0}, {"screen", 1.0}, {"illuminators", 1.0},
                                {"exposure_ms", cam.exposure_ms}, {"dropped", false}};
      return images.grey;
    }
    const SensorSetup& setup = in.sensors[c];
    // The exposure is centred on the frame time, where the truth is; with a
    // rolling shutter, the middle row's is.
    const double exposure_s = cam.exposure_ms / 1000.0;
    const double start_s = t - 0.5 * exposure_s;
    const double mains = flickers[c].MainsMean(start_s, exposure_s);
    const double screen = sweep >= 0 ? sweep : flickers[c].ScreenMean(start_s, exposure_s);
    const double drop_u = UniformFromHash(MixHash(options.seed, 0xD50Bull + c), noise_frame);
    const bool dropped = drop_u < setup.capture.drop_rate && !last_written[c].empty();
    nlohmann::json& truth = sensor_truth[cam.name];
    // A dropped frame repeats the last image, and its illumination.
    truth = {{"flicker", last_flicker[c]}, {"screen", screen}, {"illuminators", mains},
             {"exposure_ms", cam.exposure_ms}, {"dropped", dropped}};
    if (dropped) return last_written[c];
    const cv::Mat sources = samples > 1 ? cv::Mat(radiance_sum / samples) : images.radiance;
    const double qe = setup.sensor.quantum_efficiency;
    const float q940 = qe > 0 ? static_cast<float>(setup.sensor.quantum_efficiency_940 / qe) : 0.0f;
    const float q_content = 0.5f * (1.0f + q940);
    const double readout_s = setup.capture.rolling_shutter_ms / 1000.0;
    const cv::Scalar mean = cv::mean(sources);
    const double steady = mean[0] + q940 * mean[1] + q_content * mean[2] + mean[3];
    double lit = 0;
    if (readout_s <= 0 || sources.rows < 2) {
      const float m = static_cast<float>(mains), s = static_cast<float>(screen);
      const cv::Matx14f weights(m, m * q940, s * q_content, 1.0f);
      cv::transform(sources, radiance, weights);
      lit = mains * (mean[0] + q940 * mean[1]) + screen * q_content * mean[2] + mean[3];
    } else {
      radiance.create(sources.size(), CV_32FC1);
      for (int y = 0; y < sources.rows; ++y) {
        const double row_start = start_s + (double(y) / (sources.rows - 1) - 0.5) * readout_s;
        const float m = static_cast<float>(flickers[c].MainsMean(row_start, exposure_s));
        const float s = static_cast<float>(sweep >= 0 ? sweep : flickers[c].ScreenMean(row_start, exposure_s));
        const cv::Vec4f* in_row = sources.ptr<cv::Vec4f>(y);
        float* out_row = radiance.ptr<float>(y);
        double row_sum = 0;
        for (int x = 0; x < sources.cols; ++x) {
          const cv::Vec4f& v = in_row[x];
          out_row[x] = m * (v[0] + q940 * v[1]) + s * q_content * v[2] + v[3];
          row_sum += out_row[x];
        }
        lit += row_sum / (double(sources.rows) * sources.cols);
      }
    }
    last_flicker[c] = steady > 0 ? lit / steady : 1.0;
    truth["flicker"] = last_flicker[c];
    const cv::Mat seen = optics[c].Apply(radiance, images.depth);
    last_written[c] = sensors[c].ToOutput(sensors[c].Expose(seen, cam.exposure_ms, noise_frame));
    return last_written[c];
  };

  // 4. Empty-stage frames.
  std::vector<CameraImages> all_images;
  std::string background_lines;
  renderer.SetPersonVisible(false);
  for (int f = 0; f < options.background_frames; ++f) {
    ThrowIfCancelled();
    renderer.RenderAll(&all_images, need_depth);
    const double t = f / in.fps - background_s;
    nlohmann::json sensor_truth = nlohmann::json::object();
    const double sweep = sweep_screens ? ScreenSweepLevel(f, options.background_frames) : -1.0;
    for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
      const cv::Mat frame = expose(c, all_images[c], cv::Mat(), 1, t, (1ull << 40) + f, sensor_truth, sweep);
      WritePngAtomic(root / "background" / in.rig.cameras[c].name / FrameName(f, "png"), frame);
    }
    background_lines += nlohmann::json{{"frame", f}, {"t", t}, {"sensor", sensor_truth}}.dump() + "\n";
    ++done;
    report("background", f, options.background_frames);
  }
  for (cv::Mat& m : last_written) m.release();

  // 5. The sequence. With motion blur, sub-frames over the exposure are
  // rendered and averaged; the last render is always at the frame time, so
  // masks, depth and visibility belong to the truth's instant.
  renderer.SetPersonVisible(true);
  std::vector<MeshVertex> skinned;
  std::string truth_lines;
  const Labeler labeler(in.avatar, &in.scene, *in.motion);
  const auto& joint_names = TruthJointNames();
  std::vector<cv::Mat> radiance_sums(in.rig.cameras.size());
  // Sub-frame offsets over the exposure; with an odd count the centre one is
  // the final render at the camera's instant.
  std::vector<double> offsets;
  for (int k = 0; blur_samples > 1 && k < blur_samples; ++k) {
    const double offset = ((k + 0.5) / blur_samples - 0.5) * blur_exposure_s;
    if (std::abs(offset) > 1e-12) offsets.push_back(offset);
  }
  const bool centre_counts = blur_samples > 1 && blur_samples % 2 == 1;
  for (int f = 0; f < in.frame_count; ++f) {
    ThrowIfCancelled();
    const double t = f / in.fps;
    // Each camera's instant: the frame time, plus its sync jitter if any.
    std::vector<double> instant(in.rig.cameras.size(), t);
    bool jittered = false;
    for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
      const double jitter_s = in.sensor_active[c] ? in.sensors[c].capture.sync_jitter_ms / 1000.0 : 0.0;
      if (jitter_s <= 0) continue;
      float z0, z1;
      StandardNormalPair(MixHash(MixHash(options.seed, 0x5C1Cull + c), uint64_t(f)), &z0, &z1);
      instant[c] = t + jitter_s * z0;
      jittered = true;
    }
    auto accumulate = [&](size_t c, const cv::Mat& sources) {
      if (radiance_sums[c].empty()) radiance_sums[c] = sources.clone(); else radiance_sums[c] += sources;
    };
    for (cv::Mat& sum : radiance_sums) sum.release();
    if (!jittered) {
      // Synchronised cameras share every render.
      for (double offset : offsets) {
        PoseAndUpload(in, t + offset, renderer, skinned);
        renderer.RenderAll(&all_images, false);
        for (size_t c = 0; c < all_images.size(); ++c) accumulate(c, all_images[c].radiance);
      }
      PoseAndUpload(in, t, renderer, skinned);
      renderer.RenderAll(&all_images, need_depth);
      for (size_t c = 0; centre_counts && c < all_images.size(); ++c) accumulate(c, all_images[c].radiance);
    } else {
      // Each camera sees the person at its own instant (skinned per camera).
      all_images.resize(in.rig.cameras.size());
      for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
        for (double offset : offsets) {
          PoseAndUpload(in, instant[c] + offset, renderer, skinned);
          renderer.Render(static_cast<int>(c), &all_images[c], false);
          accumulate(c, all_images[c].radiance);
        }
        PoseAndUpload(in, instant[c], renderer, skinned);
        renderer.Render(static_cast<int>(c), &all_images[c], need_depth);
        if (centre_counts) accumulate(c, all_images[c].radiance);
      }
    }
    const JointTransforms world_from_joint =
        ForwardKinematics(in.avatar.skeleton, in.motion->At(t));
    nlohmann::json sensor_truth = nlohmann::json::object();
    for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
      const std::string& cam_name = in.rig.cameras[c].name;
      const cv::Mat frame = expose(c, all_images[c], radiance_sums[c], blur_samples, instant[c], f, sensor_truth);
      sensor_truth[cam_name]["sync_offset_ms"] = (instant[c] - t) * 1000.0;
      WritePngAtomic(root / "frames" / cam_name / FrameName(f, "png"), frame);
      WritePngAtomic(root / "truth" / "masks" / cam_name / FrameName(f, "png"), all_images[c].mask);
      if (options.write_depth) {
        WriteDepthExrAtomic(root / "truth" / "depth" / cam_name / FrameName(f, "exr"),
                            all_images[c].depth);
      }
    }
    const FrameTruth truth = ComputeFrameTruth(in, world_from_joint, renderer);
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
    for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
      nlohmann::json per_cam = nlohmann::json::object();
      for (size_t j = 0; j < joint_names.size(); ++j) {
        const Eigen::Vector3d& uvv = truth.joints2d[c][j];
        per_cam[joint_names[j]] = {uvv.x(), uvv.y(), static_cast<int>(uvv.z())};
      }
      joints2d[in.rig.cameras[c].name] = per_cam;
    }
    line["joints2d"] = joints2d;
    line["labels"] = labeler.Labels(t);
    line["pointing"] = labeler.Pointing(t);
    line["sensor"] = sensor_truth;
    truth_lines += line.dump() + "\n";
    ++done;
    report("frame", f, in.frame_count);
  }
  AtomicWriteFile(root / "truth" / "frames.jsonl", truth_lines);
  AtomicWriteFile(root / "truth" / "background.jsonl", background_lines);
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
  AtomicWriteFile(root / "manifest.json", manifest.dump(2) + "\n");
  ThrowIfCancelled();
  staging.Commit();
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Log().info("render: {} frame-sets ({} cameras) in {:.1f} s", total, in.rig.cameras.size(), elapsed);
  return staging.final_path();
}

}  // namespace irbench
