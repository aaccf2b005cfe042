#include "tracker/live/live_job.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <mutex>
#include <thread>
#include <vector>

#include "common/atomic_file.h"
#include "common/cancel.h"
#include "common/error.h"
#include "common/logging.h"
#include "common/progress.h"
#include "tracker/pipeline/frame_tracker.h"

namespace irbench {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
namespace {

// The one frame-set waiting for the tracker, and the producer's state.
struct Mailbox {
  std::mutex mutex;
  std::condition_variable changed;
  bool full = false, done = false, stop = false;
  int frame = 0;
  std::vector<cv::Mat> images;
  std::vector<std::string> problems;
  Clock::time_point arrival;
  int arrived = 0, dropped = 0;
  std::exception_ptr error;
};

// The next frame-set into `images` (with each camera's problem, as
// SequenceInput::TryFrameSet); false at the end of the source.
using ReadFrameSet = std::function<bool(int frame, std::vector<cv::Mat>* images, std::vector<std::string>* problems)>;

// Reads frame-sets first..end-1 (end < 0: until `read` ends) into the
// mailbox, at most `fps` per second (0: as fast as `read` gives them),
// replacing (and counting) one the tracker has not taken yet.
void Produce(const ReadFrameSet& read, int first, int end, double fps, Mailbox& box) {
  try {
    const Clock::time_point start = Clock::now();
    for (int f = first; end < 0 || f < end; ++f) {
      if (fps > 0) {
        std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>((f - first) / fps)));
      }
      {
        std::lock_guard lock(box.mutex);
        if (box.stop) break;
      }
      std::vector<std::string> problems;
      std::vector<cv::Mat> images;
      if (!read(f, &images, &problems)) break;
      std::lock_guard lock(box.mutex);
      if (box.full) ++box.dropped;
      box.full = true;
      box.frame = f;
      box.images = std::move(images);
      box.problems = std::move(problems);
      box.arrival = Clock::now();
      ++box.arrived;
      box.changed.notify_one();
    }
  } catch (...) {
    std::lock_guard lock(box.mutex);
    box.error = std::current_exception();
  }
  std::lock_guard lock(box.mutex);
  box.done = true;
  box.changed.notify_one();
}

// A live rig (options.capture): its folder's calibration, the devices opened,
// their sizes and rate taken, and the empty stage captured (frame-sets
// [from, to) seconds from the start, skipping any a camera missed) or read
// from the folder's background videos.
struct CapturedRig {
  SequenceInput input;
  std::unique_ptr<CaptureRig> rig;
  int first_tracked = 0;  // the frame-set number after the empty stage
  int empty_stage = 0;
};

CapturedRig OpenCapturedRig(const LiveJobOptions& options) {
  if (options.input.videos) throw InputError("", "--from-videos", "reads a recording's videos; --capture reads devices");
  CapturedRig out{SequenceInput::OpenRig(options.source), nullptr};
  out.rig = std::make_unique<CaptureRig>(out.input.cameras(), options.capture);
  std::vector<std::string> devices;
  for (size_t c = 0; c < out.input.cameras().size(); ++c) devices.push_back(out.rig->device(static_cast<int>(c)));
  double fps = out.rig->fps() > 0 ? out.rig->fps() : options.fps.value_or(0);
  if (!(fps > 0)) {
    throw InputError(devices[0], "--capture", "the device reports no frame rate and calib/cameras.json gives none; give --fps");
  }
  out.input.UseCaptureFormat(out.rig->sizes(), fps, devices);
  if (!options.input.empty_stage_s) {
    out.input.OpenEmptyStageVideos();
    return out;
  }
  const auto [from_s, to_s] = *options.input.empty_stage_s;
  const int first = static_cast<int>(std::lround(from_s * out.input.fps()));
  const int end = static_cast<int>(std::lround(to_s * out.input.fps()));
  if (end <= first) throw InputError("", "--empty-stage", "holds no frame-set at the rig's frame rate");
  std::vector<std::vector<cv::Mat>> frames(devices.size());
  Log().info("live: capturing the empty stage, frame-sets {} to {}: keep the stage empty", first, end - 1);
  for (int f = 0; f < end; ++f) {
    ThrowIfCancelled();
    std::vector<cv::Mat> images;
    std::vector<std::string> problems;
    if (!out.rig->Read(&images, &problems)) {
      throw InputError(devices[0], "--empty-stage", "the capture ended after " + std::to_string(f) +
                                                        " frame-sets, before the empty stage did");
    }
    const bool whole = std::all_of(images.begin(), images.end(), [](const cv::Mat& m) { return !m.empty(); });
    if (f < first) continue;
    if (!whole) {
      Log().warn("live: an empty-stage frame-set with a camera's frame missing left out: {}",
                 *std::find_if(problems.begin(), problems.end(), [](const std::string& p) { return !p.empty(); }));
      continue;
    }
    for (size_t c = 0; c < images.size(); ++c) frames[c].push_back(std::move(images[c]));
  }
  if (frames[0].empty()) throw InputError("", "--empty-stage", "no whole frame-set was captured in that range");
  out.empty_stage = static_cast<int>(frames[0].size());
  out.first_tracked = end;
  out.input.UseEmptyStage(std::move(frames), devices);
  return out;
}

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  // Nearest rank: the smallest value with at least a share q at or below it.
  const size_t rank = std::clamp<size_t>(static_cast<size_t>(std::ceil(q * values.size())), 1, values.size());
  return values[rank - 1];
}

}  // namespace

LiveReport RunLiveJob(const LiveJobOptions& options) {
  CheckTrackerSettings(options.tracker);
  if (options.fps && !(*options.fps > 0 && std::isfinite(*options.fps))) {
    throw InputError("", "--fps", "must be > 0");
  }
  if (!options.record.empty()) {
    CheckOutputApart(options.record, {options.source}, "--record");
    if (fs::exists(options.record) && !options.overwrite) {
      throw InputError(options.record.string(), "--record", "exists (--force replaces it)");
    }
  }
  std::optional<CapturedRig> captured;
  std::optional<SequenceInput> sequence;
  if (!options.capture.empty()) {
    captured.emplace(OpenCapturedRig(options));
  } else {
    sequence.emplace(SequenceInput::Open(options.source, options.input));
  }
  const SequenceInput& input = captured ? captured->input : *sequence;
  if (options.frames && *options.frames < 1) throw InputError("", "--frames", "must be at least 1");
  // Frame-sets [first, end) arrive; end < 0: until the capture ends.
  const int first = captured ? captured->first_tracked : 0;
  int end = captured ? -1 : input.frame_count();
  if (options.frames) end = end < 0 ? first + *options.frames : std::min(end, *options.frames);
  OscPublisher publisher(options.osc);
  FrameTracker tracker(input, options.tracker, EffectiveFrontEndOptions(options.tracker),
                       LoadRestClassifier(options.tracker));
  LiveReport report;
  report.fps = options.fps.value_or(input.fps());
  report.empty_stage = captured ? captured->empty_stage : 0;
  const double pace_fps = captured ? options.fps.value_or(0) : report.fps;
  const ReadFrameSet read = captured ? ReadFrameSet([&](int, std::vector<cv::Mat>* images, std::vector<std::string>* problems) {
    return captured->rig->Read(images, problems);
  })
                                     : ReadFrameSet([&](int f, std::vector<cv::Mat>* images, std::vector<std::string>* problems) {
                                         *images = input.TryFrameSet(f, problems);
                                         return true;
                                       });
  if (captured) {
    Log().info("live: capturing from frame-set {} to OSC {}:{} (a signal ends it)", first, options.osc.host, options.osc.port);
  } else {
    Log().info("live: {} frame-sets at {:.1f}/s to OSC {}:{}", end, report.fps, options.osc.host, options.osc.port);
  }

  const Clock::time_point started = Clock::now();
  Mailbox box;
  std::thread producer(Produce, std::cref(read), first, end, pace_fps, std::ref(box));
  std::vector<double> latency_ms;
  // The record's lines, by frame: the motion labels go onto theirs when
  // they come (the labeller's latency), as in irbench track's track.jsonl.
  std::map<int, nlohmann::json> record;
  int last_frame = -1;
  // Motion labels come the labeller's latency after their frame's bundle.
  const auto publish_motion = [&](const std::vector<MotionLabeler::Labels>& labels) {
    for (const MotionLabeler::Labels& l : labels) {
      if (l.arms && !publisher.PublishMotion(l.frame, (*l.arms)[0], (*l.arms)[1])) ++report.send_failures;
      if (const auto line = record.find(l.frame); line != record.end()) line->second["motion"] = FrameTracker::MotionJson(l);
    }
  };
  try {
    Progress progress("live", "frame-sets", end < 0 ? 0 : end - first);
    for (;;) {
      // A capture has no end of its own: a signal ends it like the end of
      // the streams.
      if (captured && CancelRequested()) {
        report.stopped_by_signal = true;
        break;
      }
      ThrowIfCancelled();
      std::unique_lock lock(box.mutex);
      box.changed.wait_for(lock, std::chrono::milliseconds(100), [&] { return box.full || box.done; });
      if (box.error) std::rethrow_exception(box.error);
      if (!box.full) {
        if (box.done) break;
        continue;
      }
      const int f = box.frame;
      std::vector<cv::Mat> images = std::move(box.images);
      const std::vector<std::string> problems = std::move(box.problems);
      const Clock::time_point arrival = box.arrival;
      const int dropped = box.dropped;
      box.full = false;
      lock.unlock();
      const double dt = (last_frame < 0 ? 1 : f - last_frame) / input.fps();
      std::optional<FrameTracker::Step> tracked;
      try {
        tracked.emplace(tracker.Track(f, std::move(images), problems, dt));
      } catch (const Cancelled&) {
        if (!captured) throw;
        report.stopped_by_signal = true;  // this frame-set is left out
        break;
      }
      const FrameTracker::Step& step = *tracked;
      if (!publisher.Publish(step.track_line, dropped)) ++report.send_failures;
      record[f] = step.track_line;
      publish_motion(step.motion);
      latency_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - arrival).count());
      last_frame = f;
      ++report.tracked;
      progress.Set(f + 1 - first, "frame");
    }
    // The motion labels of the last frames, which waited for frames that
    // will not come.
    publish_motion(tracker.FinishMotion());
  } catch (...) {
    {
      std::lock_guard lock(box.mutex);
      box.stop = true;
    }
    producer.join();
    throw;
  }
  {
    std::lock_guard lock(box.mutex);
    box.stop = true;
  }
  producer.join();
  report.arrived = box.arrived;
  // A capture's rate is what the devices delivered.
  if (captured && box.arrived > 0) report.fps = box.arrived / std::chrono::duration<double>(Clock::now() - started).count();
  report.dropped = box.dropped;
  report.latency_median_ms = Percentile(latency_ms, 0.5);
  report.latency_p99_ms = Percentile(latency_ms, 0.99);
  report.latency_max_ms = latency_ms.empty() ? 0 : *std::max_element(latency_ms.begin(), latency_ms.end());
  if (!options.record.empty()) {
    std::string text;
    for (const auto& [f, line] : record) text += line.dump() + "\n";
    AtomicWriteFile(options.record, text);
  }
  return report;
}

}  // namespace irbench
