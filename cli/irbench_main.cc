// irbench: one program, one subcommand per job. Exit codes: 0 success,
// 1 runtime failure, 2 bad input or usage, 130 interrupted.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "cli/bench_track.h"
#include "common/cancel.h"
#include "common/error.h"
#include "common/logging.h"
#include "common/paths.h"
#include "sim/sequence/avatar_tools.h"
#include "sim/sequence/motion_tools.h"
#include "sim/sequence/render_bench.h"
#include "sim/sequence/render_job.h"
#include "ci/demo/demo_job.h"
#include "ci/score/score.h"
#include "ci/score/score_job.h"
#include "ci/suite/suite.h"
#include "tracker/pipeline/track_job.h"
#include "ci/train/rest_training.h"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitRuntime = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitInterrupted = 130;

void AddRenderInputOptions(CLI::App* cmd,
                           irbench::RenderJobOptions& o,
                           std::string& backend,
                           std::string& shadows) {
  cmd->add_option("--scene", o.scene, "scene name (scenes/) or file; default: the rig's scene");
  cmd->add_option("--rig", o.rig, "camera rig name (rigs/) or file")->capture_default_str();
  cmd->add_option("--avatar", o.avatar, "avatar name (avatars/), avatar .json, or a rigged mesh (.glb/.gltf/.fbx/.dae)")->capture_default_str();
  cmd->add_option("--motion", o.motion,
                  "a library motion (irbench motion list), a file in motions/ (keyframes or session "
                  "script), or a path to a .json, .bvh or .amc file")
      ->capture_default_str();
  cmd->add_option("--backend", backend, "OpenGL backend: auto, egl or osmesa")
      ->capture_default_str();
  cmd->add_option("--supersample", o.supersample, "pinhole pixels per output pixel per axis (1-4)")
      ->capture_default_str();
  cmd->add_option("--sensor", o.sensor, "sensor preset: clean, thesis or harsh")->capture_default_str();
  cmd->add_option("--shadows", shadows,
                  "soft shadows of the scene's lights: on or off (default: on unless --sensor clean)")
      ->check(CLI::IsMember({"on", "off"}));
}

void ApplyShadows(const std::string& shadows, irbench::RenderJobOptions& o) {
  if (!shadows.empty()) o.shadows = shadows == "on";
}

irbench::GlBackend BackendOrThrow(const std::string& name) {
  const auto backend = irbench::ParseGlBackend(name);
  if (!backend) throw irbench::InputError("", "--backend", "must be auto, egl or osmesa");
  return *backend;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"irbench: a test bench for multi-camera near-infrared body tracking.\n"
               "Renders calibrated multi-camera sequences with exact truth (render),\n"
               "runs the tracker on them (track) and scores track files against the truth (score).",
               "irbench"};
  app.require_subcommand(1);
  app.set_version_flag("--version", irbench::ToolVersion());
  int verbosity = 1;
  app.add_flag_callback("-q,--quiet", [&] { verbosity = 0; }, "only warnings and errors on stderr");
  app.add_flag_callback("-v,--verbose", [&] { verbosity = 2; }, "debug messages on stderr");

  // render
  irbench::RenderJobOptions render;
  std::string render_backend = "auto";
  std::string render_shadows, bench_shadows;
  int frames = 0;
  CLI::App* render_cmd = app.add_subcommand(
      "render", "Render a calibrated multi-camera sequence with exact truth into a folder");
  AddRenderInputOptions(render_cmd, render, render_backend, render_shadows);
  render_cmd->add_option("--frames", frames, "frames to render (default: the motion's length)");
  render_cmd->add_option("--background-frames", render.background_frames,
                         "empty-stage frames per camera")
      ->capture_default_str();
  bool no_sweep = false;
  render_cmd->add_flag("--no-screen-sweep", no_sweep,
                       "film the empty stage with the screens playing their content; by default they show a "
                       "brightness ramp (0.25 to 1.75 of the content's level) so the tracker can tell their light "
                       "from the illuminators'");
  render_cmd->add_option("--seed", render.seed, "seed for everything random")->capture_default_str();
  std::string out;
  render_cmd->add_option("--out", out,
                         "output folder (default: renders/<rig>-<avatar>-<motion>-s<seed>)");
  render_cmd->add_flag("--force", render.overwrite, "replace an existing output folder");
  render_cmd->add_flag("--depth", render.write_depth, "also write camera depth as OpenEXR");

  // track
  irbench::TrackJobOptions track;
  std::string track_sequence, track_out;
  int track_frames = 0;
  bool track_keep_shadows = false;
  CLI::App* track_cmd = app.add_subcommand(
      "track", "Run the tracker on a sequence folder (frames, calibration and empty-stage frames only)");
  track_cmd->add_option("SEQ", track_sequence, "sequence folder written by render")->required();
  track_cmd->add_option("--stage", track.stage,
                        "how far to go: pose (front end + particle-filter pose, joints and pointing) or\n"
                        "features (silhouettes, axis points, hull only)")
      ->capture_default_str();
  track_cmd->add_option("--particles", track.particles, "pose: particles of the filter (thesis 6.3)")
      ->capture_default_str();
  track_cmd->add_option("--seed", track.seed, "pose: seed of the filter's random stream")->capture_default_str();
  std::string track_rest_model;
  track_cmd->add_option("--rest-model", track_rest_model,
                        "pose: rest-state SVM (default: tracker/models/rest_svm.yml when present)");
  track_cmd->add_option("--background-model", track.background_model,
                        "flicker (light-following, pooled) or plain (the thesis's per-pixel Gaussian)")
      ->capture_default_str();
  track_cmd->add_flag("--keep-shadows", track_keep_shadows, "skip the edge-based shadow removal");
  track_cmd->add_option("--shadow-edge-scale", track.shadow_edge_scale,
                        "shadow removal's edge thresholds times this, 0.25-8 (1: set for the thesis preset's\n"
                        "washed-out images; 2 for the clean preset with --shadows on)")
      ->capture_default_str();
  track_cmd->add_flag("--overlays", track.overlays, "also write debug overlays (PNG, colour)");
  track_cmd->add_flag("--ply", track.ply, "also write the voxel and polyhedral hulls per frame as PLY");
  track_cmd->add_option("--hull-missing-views", track.hull_missing_views,
                        "voxel hull: cameras allowed to disagree, 0 or 1 (0: the thesis's hull; 1 keeps what one view lost)")
      ->capture_default_str();
  track_cmd->add_option("--frames", track_frames, "frames to process (default: all)");
  track_cmd->add_option("--out", track_out, "output folder (default: SEQ/track)");
  track_cmd->add_flag("--force", track.overwrite, "replace an existing output folder");

  // demo
  irbench::DemoOptions demo;
  std::string demo_out;
  int demo_frames = 0;
  CLI::App* demo_cmd = app.add_subcommand(
      "demo", "The main job: render the default session (theater4, thesis preset, about 20 s),\n"
              "run the tracker, score it against the truth, print the tables and write report.html");
  demo_cmd->add_option("--out", demo_out, "sequence folder, track/ and score/ go inside (default: renders/demo)");
  demo_cmd->add_option("--avatar", demo.avatar, "avatar name (avatars/) or file")->capture_default_str();
  demo_cmd->add_option("--motion", demo.motion, "motion, as for render --motion")->capture_default_str();
  demo_cmd->add_option("--sensor", demo.sensor, "sensor preset: clean, thesis or harsh")->capture_default_str();
  demo_cmd->add_option("--frames", demo_frames, "frames to render (default: the whole session; fewer for a quick look)");
  demo_cmd->add_option("--seed", demo.seed, "seed for everything random")->capture_default_str();
  demo_cmd->add_flag("--force", demo.overwrite, "replace an existing output folder");

  // suite
  irbench::SuiteRunOptions suite;
  std::string suite_name, suite_baselines, suite_cache;
  CLI::App* suite_cmd = app.add_subcommand("suite", "Closed-loop accuracy regression: run a suite of scenarios");
  suite_cmd->require_subcommand(1);
  CLI::App* suite_run = suite_cmd->add_subcommand(
      "run", "Render (cached), track and score every scenario of a suite; check thresholds and the\n"
             "blessed baseline; print a pass/fail table; exit 1 on a regression");
  suite_run->add_option("SUITE", suite_name, "suite name (ci/suites/) or file")->required();
  suite_run->add_flag("--bless", suite.bless, "write this run's figures as the new baseline (on purpose)");
  suite_run->add_option("--baselines", suite_baselines, "baseline folder (default: ci/baselines)");
  suite_run->add_option("--cache", suite_cache, "render cache folder (default: renders/cache)");
  suite_run->add_option("--jobs", suite.jobs, "scenarios at a time (default: the core count)")
      ->check(CLI::PositiveNumber);

  // score
  irbench::ScoreJobOptions score;
  std::string score_sequence, score_track, score_out;
  CLI::App* score_cmd = app.add_subcommand(
      "score", "Score a track file against the sequence's truth: the thesis's tables (joint errors with\n"
               "Chauvenet outliers, pointing angles, rest state, motion labels; the silhouettes' IoU per camera\n"
               "when irbench track's silhouettes/ lie beside the track file) as JSON, Markdown and CSV, and\n"
               "report.html: the tables, plots and a frame viewer with the truth and the track drawn over\n"
               "every camera's image, worst frames first");
  score_cmd->add_option("SEQ", score_sequence, "sequence folder written by render")->required();
  score_cmd->add_option("--track", score_track, "track.jsonl to score (default: SEQ/track/track.jsonl)");
  score_cmd->add_option("--out", score_out, "output folder (default: SEQ/score)");
  score_cmd->add_flag("--include-rest-arms", score.score.include_rest_arms,
                      "also score elbows and wrists of arms at rest (the thesis leaves them out)");
  score_cmd->add_flag("--force", score.overwrite, "replace an existing output folder");
  bool score_no_report = false;
  score_cmd->add_flag("--no-report", score_no_report,
                      "skip report.html (tables, gnuplot plots, frame viewer; opens offline in a browser)");

  // motion
  CLI::App* motion_cmd = app.add_subcommand("motion", "List, inspect and export motions");
  motion_cmd->require_subcommand(1);
  CLI::App* motion_list = motion_cmd->add_subcommand("list", "List the library motions and motions/ files");
  std::string info_file;
  CLI::App* motion_info = motion_cmd->add_subcommand(
      "info", "Describe a BVH or AMC clip: convention, frames, frame time, the joint map");
  motion_info->add_option("FILE", info_file, ".bvh or .amc file")->required();
  irbench::MotionExportOptions export_options;
  CLI::App* motion_export = motion_cmd->add_subcommand(
      "export", "Write a motion, posed on an avatar, as BVH (Blender, assimp, MotionBuilder open it)");
  motion_export->add_option("--motion", export_options.motion, "motion, as for render --motion")
      ->required();
  motion_export->add_option("--avatar", export_options.avatar, "avatar name (avatars/), avatar .json, or a rigged mesh (.glb/.gltf/.fbx/.dae)")->capture_default_str();
  motion_export->add_option("--scene", export_options.scene, "scene (for pointing targets)")
      ->capture_default_str();
  motion_export->add_option("--fps", export_options.fps, "frames per second")->capture_default_str();
  motion_export->add_option("--seed", export_options.seed, "seed of the person's style")->capture_default_str();
  motion_export->add_option("OUT", export_options.out, "output .bvh file")->required();
  motion_export->add_flag("--force", export_options.overwrite, "replace an existing file");

  // avatar
  CLI::App* avatar_cmd = app.add_subcommand("avatar", "List, inspect and export avatars");
  avatar_cmd->require_subcommand(1);
  CLI::App* avatar_list = avatar_cmd->add_subcommand("list", "List the avatars in avatars/");
  std::string avatar_name;
  CLI::App* avatar_info = avatar_cmd->add_subcommand("info", "Height, triangles and closedness of an avatar");
  avatar_info->add_option("AVATAR", avatar_name, "avatar name (avatars/), avatar .json, or a rigged mesh (.glb/.gltf/.fbx/.dae)")->required();
  std::string avatar_export_name;
  std::filesystem::path avatar_out;
  bool avatar_force = false;
  CLI::App* avatar_export = avatar_cmd->add_subcommand(
      "export", "Write an avatar as binary glTF (.glb): mesh, skeleton and skin, for Blender or any viewer");
  avatar_export->add_option("AVATAR", avatar_export_name, "avatar name (avatars/), avatar .json, or a rigged mesh (.glb/.gltf/.fbx/.dae)")->required();
  avatar_export->add_option("OUT", avatar_out, "output .glb file")->required();
  avatar_export->add_flag("--force", avatar_force, "replace an existing file");

  // train
  CLI::App* train_cmd = app.add_subcommand("train", "Train the tracker's learned parts from simulated truth");
  train_cmd->require_subcommand(1);
  irbench::RestTrainingOptions train_rest;
  std::string train_rest_out;
  CLI::App* train_rest_cmd = train_cmd->add_subcommand(
      "rest", "Rest-state SVM (thesis 6.4): RBF SVM on elbow and wrist in the upper-body frame, C and gamma\n"
              "by k-fold cross-validation, from library motions played on avatars (no rendering)");
  train_rest_cmd->add_option("--avatars", train_rest.avatars, "avatars to sample")->capture_default_str();
  train_rest_cmd->add_option("--motions", train_rest.motions, "library motions or motion files")
      ->capture_default_str();
  train_rest_cmd->add_option("--fps", train_rest.sample_fps, "samples per second of motion")->capture_default_str();
  train_rest_cmd->add_option("--folds", train_rest.folds, "cross-validation folds")->capture_default_str();
  train_rest_cmd->add_option("--seed", train_rest.seed, "seed of the motions' styles")->capture_default_str();
  train_rest_cmd->add_option("--out", train_rest_out, "model file (default: tracker/models/rest_svm.yml)");

  // bench
  CLI::App* bench_cmd = app.add_subcommand("bench", "Print throughput figures");
  bench_cmd->require_subcommand(1);
  irbench::RenderJobOptions bench;
  std::string bench_backend = "auto";
  int bench_frames = 60;
  CLI::App* bench_render = bench_cmd->add_subcommand(
      "render", "Frame-sets per second of the render path at 1x and 2x the rig's resolution\n(320x240 and 640x480 for the shipped rigs)");
  AddRenderInputOptions(bench_render, bench, bench_backend, bench_shadows);
  bench_render->add_option("--frames", bench_frames, "timed frame-sets per resolution")
      ->capture_default_str();

  irbench::RenderJobOptions bench_track_render;
  bench_track_render.sensor = "thesis";
  std::string bench_track_backend = "auto", bench_track_shadows;
  int bench_track_frames = 30, bench_track_repeats = 3;
  CLI::App* bench_track = bench_cmd->add_subcommand(
      "track", "Milliseconds per frame-set of the tracker's stages, on a sequence rendered for it\n"
               "(images preloaded: decoding is not counted)");
  AddRenderInputOptions(bench_track, bench_track_render, bench_track_backend, bench_track_shadows);
  bench_track->add_option("--frames", bench_track_frames, "frame-sets to render and time")->capture_default_str();
  bench_track->add_option("--repeats", bench_track_repeats, "passes over them")->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "error: " << e.what() << " (see --help)\n";
    return kExitBadInput;
  }
  irbench::SetVerbosity(verbosity);
  irbench::InstallCancelHandlers();

  try {
    if (render_cmd->parsed()) {
      if (render_cmd->count("--frames") > 0) render.frames = frames;
      render.out = out;
      render.screen_sweep = !no_sweep;
      render.backend = BackendOrThrow(render_backend);
      ApplyShadows(render_shadows, render);
      const std::filesystem::path folder = irbench::RunRenderJob(render);
      std::cout << folder.string() << "\n";
      return kExitOk;
    }
    if (track_cmd->parsed()) {
      track.sequence = track_sequence;
      track.out = track_out;
      track.remove_shadows = !track_keep_shadows;
      track.rest_model = track_rest_model;
      if (track_cmd->count("--frames") > 0) track.frames = track_frames;
      std::cout << irbench::RunTrackJob(track).string() << "\n";
      return kExitOk;
    }
    if (train_rest_cmd->parsed()) {
      train_rest.out = train_rest_out;
      const irbench::RestTrainingResult r = irbench::RunRestTraining(train_rest);
      std::cout << "rest-state SVM: " << r.samples << " arm samples (" << r.at_rest << " at rest), "
                << train_rest.folds << "-fold cross-validated accuracy " << r.cv_accuracy * 100 << "%\n"
                << r.model.string() << "\n";
      return kExitOk;
    }
    if (demo_cmd->parsed()) {
      demo.out = demo_out;
      if (demo_cmd->count("--frames") > 0) demo.frames = demo_frames;
      const irbench::DemoResult r = irbench::RunDemo(demo);
      std::cout << r.tables << "\n"
                << "sequence  " << r.sequence.string() << "\n"
                << "track     " << r.track.string() << "\n"
                << "score     " << r.score.string() << "\n"
                << "report    " << (r.score / "report.html").string() << "  (open in a browser)\n";
      return kExitOk;
    }
    if (suite_run->parsed()) {
      suite.suite = suite_name;
      suite.baselines = suite_baselines;
      suite.cache = suite_cache;
      const irbench::SuiteResult r = irbench::RunSuite(suite);
      std::cout << "# suite " << r.name << (suite.bless ? " (blessed)" : "") << "\n" << r.Table() << "\nreports:\n";
      for (const auto& [scenario, report] : r.reports) std::cout << "  " << scenario << "  " << report.string() << "\n";
      if (!r.pass) {
        int failed = 0;
        for (const auto& row : r.rows) failed += !row.pass;
        std::cerr << "error: suite " << r.name << ": " << failed << " metric(s) failed\n";
        return kExitRuntime;
      }
      return kExitOk;
    }
    if (score_cmd->parsed()) {
      score.sequence = score_sequence;
      score.track = score_track;
      score.out = score_out;
      score.report = !score_no_report;
      std::string tables;
      const std::filesystem::path folder = irbench::RunScoreJob(score, &tables);
      std::cout << tables << "\n";
      if (score.report) std::cout << "report  " << (folder / "report.html").string() << "\n";
      std::cout << folder.string() << "\n";
      return kExitOk;
    }
    if (avatar_list->parsed()) {
      std::cout << irbench::AvatarListText();
      return kExitOk;
    }
    if (avatar_info->parsed()) {
      std::cout << irbench::AvatarInfoText(avatar_name);
      return kExitOk;
    }
    if (avatar_export->parsed()) {
      std::cout << irbench::ExportAvatar(avatar_export_name, avatar_out, avatar_force).string() << "\n";
      return kExitOk;
    }
    if (motion_list->parsed()) {
      std::cout << irbench::MotionListText();
      return kExitOk;
    }
    if (motion_info->parsed()) {
      std::cout << irbench::MotionInfoText(info_file);
      return kExitOk;
    }
    if (motion_export->parsed()) {
      std::cout << irbench::ExportMotion(export_options).string() << "\n";
      return kExitOk;
    }
    if (bench_track->parsed()) {
      bench_track_render.backend = BackendOrThrow(bench_track_backend);
      ApplyShadows(bench_track_shadows, bench_track_render);
      if (bench_track_frames < 1) throw irbench::InputError("", "--frames", "must be at least 1");
      if (bench_track_repeats < 1) throw irbench::InputError("", "--repeats", "must be at least 1");
      int cameras = 0;
      const auto rows = irbench::RunTrackBench(bench_track_render, bench_track_frames, bench_track_repeats, &cameras);
      std::printf("# irbench bench track: rig %s, avatar %s, motion %s, sensor %s, %d cameras, %d frame-sets x %d\n",
                  bench_track_render.rig.c_str(), bench_track_render.avatar.c_str(),
                  bench_track_render.motion.c_str(), bench_track_render.sensor.c_str(), cameras,
                  bench_track_frames, bench_track_repeats);
      std::printf("| stage | median ms per frame-set | mean ms | frame-sets per second (from the mean) |\n"
                  "|---|---|---|---|\n");
      for (const auto& r : rows) {
        std::printf("| %s | %.2f | %.2f | %.1f |\n", r.stage.c_str(), r.median_ms, r.mean_ms,
                    r.mean_ms > 0 ? 1000.0 / r.mean_ms : 0.0);
      }
      return kExitOk;
    }
    if (bench_render->parsed()) {
      bench.backend = BackendOrThrow(bench_backend);
      ApplyShadows(bench_shadows, bench);
      if (bench_frames < 1) throw irbench::InputError("", "--frames", "must be at least 1");
      std::string backend_description;
      const auto results =
          irbench::RunRenderBench(bench, {1.0, 2.0}, bench_frames, &backend_description);
      std::printf("# irbench bench render: rig %s, avatar %s, motion %s, supersample %d\n",
                  bench.rig.c_str(), bench.avatar.c_str(), bench.motion.c_str(), bench.supersample);
      std::printf("# %s\n", backend_description.c_str());
      std::printf("| resolution | cameras | frame-sets | render frame-sets/s | ms/camera | "
                  "with PNG encode frame-sets/s |\n|---|---|---|---|---|---|\n");
      for (const auto& r : results) {
        std::printf("| %s | %d | %d | %.1f | %.2f | %.1f |\n", r.label.c_str(), r.cameras, r.frames,
                    r.render_fps, r.ms_per_camera, r.encode_fps);
      }
      return kExitOk;
    }
  } catch (const irbench::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const irbench::Cancelled&) {
    std::cerr << "interrupted: nothing was left half-written\n";
    return kExitInterrupted;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitRuntime;
  }
  return kExitBadInput;
}
