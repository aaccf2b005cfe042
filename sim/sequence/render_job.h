#pragma once
// `irbench render`: load a scene, rig, avatar and motion; render every camera
// for every frame; write a sequence folder (docs/architecture.md) under a
// staging name and rename it into place when complete.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "sim/body/avatar.h"
#include "sim/motion/labels.h"
#include "sim/motion/session.h"
#include "sim/camera/rig.h"
#include "sim/gl/gl_context.h"
#include "sim/render/renderer.h"
#include "sim/scene/scene.h"
#include "sim/sensor/sensor_model.h"

namespace irbench {

struct RenderJobOptions {
  std::string scene;  // name or path; empty: the rig's scene
  std::string rig = "theater4";
  std::string avatar = "p1";
  std::string motion = "wave";
  std::optional<int> frames;  // default: the motion's duration
  int background_frames = 10;
  // The empty-stage frames are filmed while the screens show a brightness
  // ramp, from kSweepLow to kSweepHigh times the content's nominal level (a
  // calibration sweep an installer runs with the empty theater), so that the
  // tracker can tell the screens' light on the stage from the illuminators'.
  // false: the screens play their content, flickering as during the sequence.
  // No effect where no camera has a sensor model (`--sensor clean` without
  // per-camera overrides: no flicker at all).
  bool screen_sweep = true;
  uint64_t seed = 1;
  std::string sensor = "clean";
  std::filesystem::path out;  // empty: renders/<rig>-<avatar>-<motion>-s<seed>
  bool overwrite = false;
  // Carry on from the frames an interrupted render of the same `out` and the
  // same options left in its staging folder (render_resume.h); without it a
  // dead render's staging folder is removed.
  bool resume = false;
  bool write_depth = false;
  bool write_video = false;  // also videos/<cam>.mkv, background/<cam>.mkv (FFV1; sequence_video.h)
  GlBackend backend = GlBackend::kAuto;
  int supersample = 2;
  // Soft shadows of the scene's lights; default: on with a sensor preset other
  // than clean.
  std::optional<bool> shadows;
  // The static scene drawn once per camera and reused (RenderOptions::
  // static_cache, from static_cache_min_pixels render pixels): the same
  // bytes either way; off, or on at any size, only to compare.
  bool static_cache = true;
  int static_cache_min_pixels = 640 * 480;
};

// The screens' level in empty-stage frame `index` of `count` with the
// calibration sweep on: evenly from kSweepLow to kSweepHigh (their mean is the
// content's nominal level, 1).
constexpr double kSweepLow = 0.25, kSweepHigh = 1.75;
double ScreenSweepLevel(int index, int count);

// Everything a render needs, loaded and validated (InputError on bad input).
struct RenderInputs {
  Scene scene;
  Rig rig;
  Avatar avatar;
  MotionPtr motion;
  std::string motion_name;
  std::string motion_kind;  // library, keyframes, session, bvh, amc
  MotionStyle style;
  std::filesystem::path scene_file, rig_file, avatar_file, motion_file;
  int frame_count = 0;
  double fps = 30;
  // Per camera: the sensor preset with the rig's per-knob overrides.
  std::vector<SensorSetup> sensors;
  std::vector<bool> sensor_active;  // false: the clean render is written as is
  bool models_sensor = false;       // the preset models a sensor (not `clean`)
};

RenderInputs LoadRenderInputs(const RenderJobOptions& options);

// Whether the empty-stage frames show the screens' calibration sweep: asked
// for, and some camera has a sensor model (a camera without one writes the
// clean render, whose light does not change).
bool SweepsScreens(const RenderJobOptions& options, const RenderInputs& in);

// The renderer's options for a job: its supersampling, and shadows unless
// turned off (default: on for every sensor preset but clean).
RenderOptions RenderOptionsFor(const RenderJobOptions& options, const RenderInputs& in);

// Per-frame truth joints and their projections, for one posed frame.
struct FrameTruth {
  std::vector<Eigen::Vector3d> joints3d;  // TruthJointNames() order
  // [camera][joint] = (u, v, visibility)
  std::vector<std::vector<Eigen::Vector3d>> joints2d;
};

// Poses the avatar at time t, skins it (once) and uploads it to the renderer.
JointTransforms PoseAndUpload(const RenderInputs& inputs,
                              double t,
                              Renderer& renderer,
                              std::vector<MeshVertex>& skinned);

// Projects the truth joints into every camera with visibility from the
// renderer's last images of each camera.
FrameTruth ComputeFrameTruth(const RenderInputs& inputs,
                             const JointTransforms& world_from_joint,
                             const Renderer& renderer);

// Runs the whole job; returns the final sequence folder. Polls for SIGINT.
// The folder replaces `out` only when irbench wrote it (--force) and may not
// hold or lie in an input file (common/atomic_file.h).
std::filesystem::path RunRenderJob(const RenderJobOptions& options);

}  // namespace irbench
