#include "tracker/live/live_job.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
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

// Reads frame-sets 0..frames-1 at `fps` into the mailbox, replacing (and
// counting) one the tracker has not taken yet.
void Produce(const SequenceInput& input, int frames, double fps, Mailbox& box) {
  try {
    const Clock::time_point start = Clock::now();
    for (int f = 0; f < frames; ++f) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(f / fps)));
      {
        std::lock_guard lock(box.mutex);
        if (box.stop) break;
      }
      std::vector<std::string> problems;
      std::vector<cv::Mat> images = input.TryFrameSet(f, &problems);
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
  const SequenceInput input = SequenceInput::Open(options.source, options.input);
  int frames = input.frame_count();
  if (options.frames) {
    if (*options.frames < 1) throw InputError("", "--frames", "must be at least 1");
    frames = std::min(frames, *options.frames);
  }
  OscPublisher publisher(options.osc);
  FrameTracker tracker(input, options.tracker, EffectiveFrontEndOptions(options.tracker),
                       LoadRestClassifier(options.tracker));
  LiveReport report;
  report.fps = options.fps.value_or(input.fps());
  Log().info("live: {} frame-sets at {:.1f}/s to OSC {}:{}", frames, report.fps, options.osc.host, options.osc.port);

  Mailbox box;
  std::thread producer(Produce, std::cref(input), frames, report.fps, std::ref(box));
  std::vector<double> latency_ms;
  std::string record;
  int last_frame = -1;
  // Motion labels come the labeller's latency after their frame's bundle.
  const auto publish_motion = [&](const std::vector<MotionLabeler::Labels>& labels) {
    for (const MotionLabeler::Labels& l : labels) {
      if (l.arms && !publisher.PublishMotion(l.frame, (*l.arms)[0], (*l.arms)[1])) ++report.send_failures;
    }
  };
  try {
    Progress progress("live", "frame-sets", frames);
    for (;;) {
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
      const FrameTracker::Step step = tracker.Track(f, std::move(images), problems, dt);
      if (!publisher.Publish(step.track_line, dropped)) ++report.send_failures;
      publish_motion(step.motion);
      latency_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - arrival).count());
      record += step.track_line.dump() + "\n";
      last_frame = f;
      ++report.tracked;
      progress.Set(f + 1, "frame");
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
  producer.join();
  report.arrived = box.arrived;
  report.dropped = box.dropped;
  report.latency_median_ms = Percentile(latency_ms, 0.5);
  report.latency_p99_ms = Percentile(latency_ms, 0.99);
  report.latency_max_ms = latency_ms.empty() ? 0 : *std::max_element(latency_ms.begin(), latency_ms.end());
  if (!options.record.empty()) AtomicWriteFile(options.record, record);
  return report;
}

}  // namespace irbench
