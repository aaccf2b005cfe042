// irbench live (issue 33.2): frame-sets tracked as they arrive, each
// published as one OSC bundle over UDP. A receiver on localhost (liblo, as a
// VR application would use it) gets one bundle per tracked frame-set, whose
// joints equal the --record file's; frame-sets that arrive faster than the
// tracker runs are dropped and counted, never queued. The latency is
// printed, not asserted (docs/live.md has the figures).

#include <gtest/gtest.h>
#include <lo/lo.h>
#include <sys/socket.h>

#include <chrono>
#include <map>
#include <mutex>
#include <thread>

#include "common/error.h"
#include "sim/sequence/render_job.h"
#include "tests/shared_render.h"
#include "tests/test_util.h"
#include "tests/track_figures.h"
#include "tracker/live/live_job.h"
#include "tracker/motion_labels/motion_labeler.h"
#include "tracker/pose/rest_state.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::SharedRender;
using irbench::testing::ReadJsonLines;

// What the receiver heard: per frame, its joints and rest state, in order.
struct Heard {
  std::mutex mutex;
  std::vector<int> frames;
  std::map<int, std::map<std::string, std::array<double, 3>>> joints;
  std::map<int, std::map<std::string, int>> rest;
  std::map<int, int> dropped;
  std::map<int, std::string> posture;
  std::map<int, std::array<std::string, 2>> motion;  // frame -> right, left
};

int OnMessage(const char* path, const char* types, lo_arg** argv, int argc, lo_message, void* user) {
  Heard& heard = *static_cast<Heard*>(user);
  std::lock_guard lock(heard.mutex);
  const std::string p = path;
  if (p == "/irbench/frame" && std::string(types) == "idsi") {
    heard.frames.push_back(argv[0]->i);
    heard.dropped[argv[0]->i] = argv[3]->i;
  } else if (p == "/irbench/joint" && std::string(types) == "sddd" && !heard.frames.empty()) {
    heard.joints[heard.frames.back()][&argv[0]->s] = {argv[1]->d, argv[2]->d, argv[3]->d};
  } else if (p == "/irbench/rest" && argc == 2 && !heard.frames.empty()) {
    heard.rest[heard.frames.back()][&argv[0]->s] = argv[1]->i;
  } else if (p == "/irbench/posture" && std::string(types) == "s" && !heard.frames.empty()) {
    heard.posture[heard.frames.back()] = &argv[0]->s;
  } else if (p == "/irbench/motion" && std::string(types) == "iss") {
    heard.motion[argv[0]->i] = {&argv[1]->s, &argv[2]->s};
  }
  return 0;
}

// A liblo receiver on a free localhost port, with a large socket buffer.
class Receiver {
 public:
  Receiver() {
    server_ = lo_server_thread_new_with_proto(nullptr, LO_UDP, nullptr);
    if (server_ == nullptr) throw std::runtime_error("no OSC server");
    const int fd = lo_server_get_socket_fd(lo_server_thread_get_server(server_));
    const int bytes = 8 << 20;
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof(bytes));
    lo_server_thread_add_method(server_, nullptr, nullptr, OnMessage, &heard_);
    lo_server_thread_start(server_);
  }
  ~Receiver() {
    lo_server_thread_stop(server_);
    lo_server_thread_free(server_);
  }
  int port() const { return lo_server_thread_get_port(server_); }
  Heard& heard() { return heard_; }

 private:
  lo_server_thread server_ = nullptr;
  Heard heard_;
};

class LiveTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(FreshTempDir("live_" + std::to_string(getpid())));
    RenderJobOptions options;
    options.rig = "theater4";
    options.avatar = "p1";
    options.motion = "wave";
    options.sensor = "thesis";
    options.background_frames = 12;
    options.supersample = 1;
    options.seed = 3;
    options.out = *dir_ / "seq";
    seq_ = new fs::path(SharedRender("wave_p1", options));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete seq_;
  }
  static LiveJobOptions Options(int port, const std::string& record) {
    LiveJobOptions options;
    options.source = *seq_;
    options.osc = ParseOscTarget("127.0.0.1:" + std::to_string(port), "--osc");
    options.record = *dir_ / record;
    return options;
  }
  static fs::path* dir_;
  static fs::path* seq_;
};
fs::path* LiveTest::dir_ = nullptr;
fs::path* LiveTest::seq_ = nullptr;

TEST_F(LiveTest, EveryTrackedFrameSetIsOneBundleWithTheRecordedJoints) {
  Receiver receiver;
  // Frame-sets arrive at 10/s, well under what the tracker keeps up with on a
  // loaded 2-core machine (about 20/s), so that nearly every one is tracked
  // and the accuracy below does not depend on the machine's load; dropping
  // is the next test's.
  LiveJobOptions options = Options(receiver.port(), "live.jsonl");
  options.fps = 10;
  const LiveReport report = RunLiveJob(options);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last datagrams
  std::printf("live: %d arrived, %d tracked, %d dropped; latency median %.1f ms, p99 %.1f ms, max %.1f ms\n",
              report.arrived, report.tracked, report.dropped, report.latency_median_ms, report.latency_p99_ms,
              report.latency_max_ms);
  const std::vector<nlohmann::json> record = ReadJsonLines(*dir_ / "live.jsonl");
  const std::vector<nlohmann::json> truth = ReadJsonLines(*seq_ / "truth/frames.jsonl");
  EXPECT_EQ(report.arrived, static_cast<int>(truth.size()));
  EXPECT_EQ(report.tracked + report.dropped, report.arrived);
  EXPECT_EQ(report.send_failures, 0);
  ASSERT_EQ(static_cast<int>(record.size()), report.tracked);
  EXPECT_GT(report.latency_p99_ms, 0.0);
  Heard& heard = receiver.heard();
  std::lock_guard lock(heard.mutex);
  ASSERT_EQ(heard.frames.size(), record.size());
  int joints_compared = 0, postures_compared = 0;
  for (size_t i = 0; i < record.size(); ++i) {
    const int f = record[i]["frame"];
    EXPECT_EQ(heard.frames[i], f);
    for (const auto& [name, p] : record[i]["joints3d"].items()) {
      if (!p.is_array()) {
        EXPECT_EQ(heard.joints[f].count(name), 0u) << f << " " << name;
        continue;
      }
      ASSERT_EQ(heard.joints[f].count(name), 1u) << f << " " << name;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(heard.joints[f][name][k], p[k].get<double>()) << f << " " << name;
      ++joints_compared;
    }
    if (record[i]["rest"].is_object()) {
      EXPECT_EQ(heard.rest[f]["right"], record[i]["rest"]["right"].get<bool>() ? 1 : 0) << f;
    }
    if (record[i]["posture"].is_object()) {
      const auto& pair = record[i]["posture"]["pair"];
      EXPECT_EQ(heard.posture[f], pair[0].get<std::string>() + "+" + pair[1].get<std::string>()) << f;
      ++postures_compared;
    }
  }
  EXPECT_GT(joints_compared, 10 * static_cast<int>(record.size()));
  EXPECT_GT(postures_compared, static_cast<int>(record.size()) / 2);  // the shipped posture atoms
  // Motion labels, each frame's sent once its window is in (or at the end):
  // what the shipped LDCRF's labeller makes of the recorded lines.
  if (fs::exists(DefaultMotionLabelModelPath(MotionModelKind::kLdcrf))) {
    const RestClassifier rest = RestClassifier::Load(DefaultRestModelPath());
    MotionLabeler labeler(std::make_shared<MotionLabelModel>(
        MotionLabelModel::Load(DefaultMotionLabelModelPath(MotionModelKind::kLdcrf))));
    std::map<int, std::array<std::string, 2>> expected;
    auto keep = [&](const std::vector<MotionLabeler::Labels>& labels) {
      for (const auto& l : labels) {
        if (l.arms) expected[l.frame] = *l.arms;
      }
    };
    for (const nlohmann::json& line : record) keep(labeler.Update(line["frame"], MotionObservationFromTrackLine(line, &rest)));
    keep(labeler.Finish());
    EXPECT_GT(expected.size(), record.size() / 2);
    EXPECT_EQ(heard.motion, expected);
  }
  // What was tracked tracks the person: the recorded track against the truth.
  const irbench::testing::TrackFigures figures = irbench::testing::UpperBodyFigures(record, truth);
  std::printf("live: tracked %.0f %% of the truth's frames, upper-body mean error %.2f cm\n", 100 * figures.Fraction(),
              figures.mean_error_cm);
  EXPECT_GT(figures.Fraction(), 0.8);
  EXPECT_LT(figures.mean_error_cm, 6.0);
}

TEST_F(LiveTest, FrameSetsArrivingFasterThanTheTrackerAreDroppedNotQueued) {
  Receiver receiver;
  LiveJobOptions options = Options(receiver.port(), "fast.jsonl");
  options.fps = 2000;  // far faster than a frame-set is tracked
  const LiveReport report = RunLiveJob(options);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_GT(report.dropped, 0);
  EXPECT_EQ(report.tracked + report.dropped, report.arrived);
  const std::vector<nlohmann::json> record = ReadJsonLines(*dir_ / "fast.jsonl");
  ASSERT_EQ(static_cast<int>(record.size()), report.tracked);
  for (size_t i = 1; i < record.size(); ++i) EXPECT_GT(record[i]["frame"], record[i - 1]["frame"]);
  std::lock_guard lock(receiver.heard().mutex);
  EXPECT_EQ(receiver.heard().frames.size(), record.size());
  // Each bundle says how many were dropped before it: never decreasing.
  int last = 0;
  for (int f : receiver.heard().frames) {
    EXPECT_GE(receiver.heard().dropped[f], last);
    last = receiver.heard().dropped[f];
  }
}

TEST_F(LiveTest, BadTargetsAndRecordsAreRefused) {
  EXPECT_THROW(ParseOscTarget("no-such-host.invalid:9000", "--osc"), InputError);
  EXPECT_THROW(ParseOscTarget("127.0.0.1:0", "--osc"), InputError);
  EXPECT_THROW(ParseOscTarget("127.0.0.1:70000", "--osc"), InputError);
  EXPECT_THROW(ParseOscTarget("127.0.0.1", "--osc"), InputError);
  EXPECT_NO_THROW(ParseOscTarget("localhost:9000", "--osc"));
  // An existing record file is not replaced without --force; one inside the
  // input is refused.
  irbench::testing::WriteText(*dir_ / "mine.jsonl", "keep\n");
  EXPECT_THROW(RunLiveJob(Options(9, "mine.jsonl")), InputError);
  EXPECT_EQ(irbench::testing::ReadText(*dir_ / "mine.jsonl"), "keep\n");
  LiveJobOptions inside = Options(9, "x.jsonl");
  inside.record = *seq_ / "frames" / "x.jsonl";
  EXPECT_THROW(RunLiveJob(inside), InputError);
  LiveJobOptions bad_fps = Options(9, "y.jsonl");
  bad_fps.fps = 0;
  EXPECT_THROW(RunLiveJob(bad_fps), InputError);
}

}  // namespace
}  // namespace irbench
