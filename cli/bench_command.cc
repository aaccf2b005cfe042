// `irbench bench render|track`: throughput figures of the render path and the
// tracker. `bench track` renders its sequence here (sim/) and has the tracker
// timed on it by tracker/pipeline/track_benchmark, which must not depend on sim/.

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cli/commands.h"
#include "cli/option_checks.h"
#include "cli/render_options.h"
#include "common/error.h"
#include "common/logging.h"
#include "sim/sequence/render_bench.h"
#include "sim/sequence/render_job.h"
#include "tracker/pipeline/track_benchmark.h"

namespace irbench::cli {
namespace {

namespace fs = std::filesystem;

// What `irbench bench render`'s flags bind to.
struct BenchRenderArgs {
  RenderJobOptions render;
  std::string backend = "auto";
  std::string shadows;
  int frames = 60;
};

// What `irbench bench track`'s flags bind to.
struct BenchTrackArgs {
  RenderJobOptions render;
  std::string backend = "auto";
  std::string shadows;
  int frames = 30;
  int repeats = 3;
};

// Removes a folder, and what is in it, when it goes out of scope.
struct RemoveOnExit {
  fs::path dir;
  ~RemoveOnExit() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

// Renders `frames` frame-sets to a temporary folder (removed afterwards) and
// times the tracker's stages on them. `render`'s out is ignored.
std::vector<TrackBenchRow> RenderAndTimeTracker(RenderJobOptions render,
                                                int frames,
                                                int repeats,
                                                int* cameras) {
  const fs::path dir =
      fs::temp_directory_path() / ("irbench_bench_track_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const RemoveOnExit cleanup{dir};
  render.frames = frames;
  fs::create_directories(dir);
  render.out = dir / "seq";
  if (render.background_frames < 2) render.background_frames = 12;
  Log().info("bench track: rendering {} frame-sets", frames);
  const fs::path seq = RunRenderJob(render);
  return RunTrackBenchmark(seq, repeats, cameras);
}

// Runs `bench track`; prints its Markdown table.
int RunBenchTrack(BenchTrackArgs& args) {
  RenderJobOptions& render = args.render;
  render.backend = BackendOrThrow(args.backend);
  ApplyShadows(args.shadows, render);
  if (args.frames < 1) throw InputError("", "--frames", "must be at least 1");
  if (args.repeats < 1) throw InputError("", "--repeats", "must be at least 1");
  int cameras = 0;
  const auto rows = RenderAndTimeTracker(render, args.frames, args.repeats, &cameras);
  std::printf(
      "# irbench bench track: rig %s, avatar %s, motion %s, sensor %s, %d cameras, %d frame-sets x "
      "%d\n",
      render.rig.c_str(), render.avatar.c_str(), render.motion.c_str(), render.sensor.c_str(),
      cameras, args.frames, args.repeats);
  std::printf(
      "| stage | median ms per frame-set | mean ms | frame-sets per second (from the mean) |\n"
      "|---|---|---|---|\n");
  for (const auto& r : rows) {
    std::printf("| %s | %.2f | %.2f | %.1f |\n", r.stage.c_str(), r.median_ms, r.mean_ms,
                r.mean_ms > 0 ? 1000.0 / r.mean_ms : 0.0);
  }
  return kExitOk;
}

// Runs `bench render`; prints its Markdown table.
int RunBenchRender(BenchRenderArgs& args) {
  RenderJobOptions& bench = args.render;
  bench.backend = BackendOrThrow(args.backend);
  ApplyShadows(args.shadows, bench);
  if (args.frames < 1) throw InputError("", "--frames", "must be at least 1");
  std::string backend_description;
  const auto results = RunRenderBench(bench, {1.0, 2.0}, args.frames, &backend_description);
  std::printf("# irbench bench render: rig %s, avatar %s, motion %s, supersample %d\n",
              bench.rig.c_str(), bench.avatar.c_str(), bench.motion.c_str(), bench.supersample);
  std::printf("# %s\n", backend_description.c_str());
  std::printf(
      "| resolution | cameras | frame-sets | render frame-sets/s | ms/camera | "
      "with PNG encode frame-sets/s |\n|---|---|---|---|---|---|\n");
  for (const auto& r : results) {
    std::printf("| %s | %d | %d | %.1f | %.2f | %.1f |\n", r.label.c_str(), r.cameras, r.frames,
                r.render_fps, r.ms_per_camera, r.encode_fps);
  }
  std::printf(
      "\nms per frame-set by stage (the render pass's add up to its time; the GL draws while "
      "the first read-back waits, llvmpipe partly before):\n\n"
      "| resolution | pose, skin, upload | shadow maps, draw calls | read-back | resampling left | truth | "
      "PNG encode |\n|---|---|---|---|---|---|---|\n");
  for (const auto& r : results) {
    std::printf("| %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n", r.label.c_str(), r.pose_ms, r.draw_ms,
                r.read_back_ms, r.resample_ms, r.truth_ms, r.encode_ms);
  }
  return kExitOk;
}

// Adds `bench render` under `bench_cmd`.
Command AddBenchRender(CLI::App* bench_cmd) {
  auto args = std::make_shared<BenchRenderArgs>();
  CLI::App* cmd =
      bench_cmd->add_subcommand("render",
                                "Frame-sets per second of the render path at 1x and 2x the rig's "
                                "resolution\n(320x240 and 640x480 for the shipped rigs)");
  AddRenderInputOptions(cmd, args->render, args->backend, args->shadows);
  cmd->add_option("--frames", args->frames, "timed frame-sets per resolution")
      ->capture_default_str()
      ->transform(IntegerIn(1, 100000));
  cmd->add_option_function<std::string>(
         "--static-cache",
         [args](const std::string& v) {
           args->render.static_cache = v != "off";
           if (v == "on") args->render.static_cache_min_pixels = 0;
         },
         "the static scene drawn once per camera and reused (the same pixels): auto (default: from\n"
         "640x480 render pixels), on or off, to compare")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  return {cmd, [args] { return RunBenchRender(*args); }};
}

// Adds `bench track` under `bench_cmd`.
Command AddBenchTrack(CLI::App* bench_cmd) {
  auto args = std::make_shared<BenchTrackArgs>();
  args->render.sensor = "thesis";  // bench track's default preset, shown in its --help
  CLI::App* cmd = bench_cmd->add_subcommand(
      "track",
      "Milliseconds per frame-set of the tracker's stages, on a sequence rendered for it\n"
      "(images preloaded: decoding is not counted)");
  AddRenderInputOptions(cmd, args->render, args->backend, args->shadows);
  cmd->add_option("--frames", args->frames, "frame-sets to render and time")
      ->capture_default_str()
      ->transform(IntegerIn(1, 100000));
  cmd->add_option("--repeats", args->repeats, "passes over them")->capture_default_str()->transform(IntegerIn(1, 1000));
  return {cmd, [args] { return RunBenchTrack(*args); }};
}

}  // namespace

std::vector<Command> AddBenchCommand(CLI::App& app) {
  CLI::App* bench_cmd = app.add_subcommand("bench", "Print throughput figures");
  bench_cmd->require_subcommand(1);
  Command render = AddBenchRender(bench_cmd);
  Command track = AddBenchTrack(bench_cmd);
  return {render, track};
}

}  // namespace irbench::cli
