#include "ci/demo/demo_job.h"

#include "ci/score/score.h"
#include "ci/score/score_job.h"
#include "common/logging.h"
#include "common/paths.h"
#include "sim/sequence/render_job.h"
#include "tracker/pipeline/track_job.h"

namespace irbench {

DemoResult RunDemo(const DemoOptions& options) {
  RenderJobOptions render;
  render.rig = "theater4";
  render.avatar = options.avatar;
  render.motion = options.motion;
  render.sensor = options.sensor;
  render.frames = options.frames;
  render.seed = options.seed;
  render.background_frames = 12;
  render.out = options.out.empty() ? OutputRoot() / "renders" / "demo" : options.out;
  if (options.out.empty()) std::filesystem::create_directories(render.out.parent_path());
  render.overwrite = options.overwrite;
  Log().info("demo: 1/3 render ({} on theater4, {} preset)", options.avatar, options.sensor);
  DemoResult result;
  result.sequence = RunRenderJob(render);

  Log().info("demo: 2/3 track");
  TrackJobOptions track;
  track.sequence = result.sequence;
  track.overwrite = true;
  result.track = RunTrackJob(track);

  Log().info("demo: 3/3 score");
  ScoreJobOptions score;
  score.sequence = result.sequence;
  score.track = result.track / "track.jsonl";
  score.overwrite = true;
  result.score = RunScoreJob(score, &result.tables);
  return result;
}

}  // namespace irbench
