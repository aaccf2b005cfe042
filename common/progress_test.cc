#include "common/progress.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <sstream>

#include "common/logging.h"

namespace irbench {
namespace {

TEST(ProgressTest, LineGivesCountShareRateAndTimeLeft) {
  // 12 of 60 in 2 s: 6 per second, 48 left take 8 s.
  EXPECT_EQ(Progress::Line("render", "frame", 12, 60, 2.0, "frame-sets"),
            "render: frame 12/60 (20 %), 6.0 frame-sets/s, 0:08 left");
  // 10 of 1000 in 10 s: 990 s left.
  EXPECT_EQ(Progress::Line("track", "", 10, 1000, 10.0, "frame-sets"),
            "track: 10/1000 (1 %), 1.0 frame-sets/s, 16:30 left");
  // Done: no time left; nothing done yet: no rate.
  EXPECT_EQ(Progress::Line("suite s", "scenarios done", 3, 3, 30.0, "scenarios"),
            "suite s: scenarios done 3/3 (100 %), 0.1 scenarios/s");
  EXPECT_EQ(Progress::Line("render", "background", 0, 10, 0.0, "frame-sets"), "render: background 0/10 (0 %)");
  // An unknown total (a live capture): the count and the rate only.
  EXPECT_EQ(Progress::Line("live", "frame", 40, 0, 4.0, "frame-sets"), "live: frame 40, 10.0 frame-sets/s");
}

// Captures what the logger writes while it lives.
class LogCapture {
 public:
  LogCapture() : sink_(std::make_shared<spdlog::sinks::ostream_sink_mt>(text_)) { Log().sinks().push_back(sink_); }
  ~LogCapture() { Log().sinks().pop_back(); }
  std::string Text() const { return text_.str(); }

 private:
  std::ostringstream text_;
  std::shared_ptr<spdlog::sinks::ostream_sink_mt> sink_;
};

TEST(ProgressTest, NotOnATerminalItLogsAPlainLineEveryPeriodAndAtTheEnd) {
  LogCapture capture;
  {
    Progress progress("track", "frame-sets", 100, /*terminal=*/false, /*plain_period_s=*/3600);
    for (int done = 1; done <= 100; ++done) progress.Set(done, "frame");
  }
  const std::string text = capture.Text();
  // Only the last count: the period has not passed before it.
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  EXPECT_NE(text.find("track: frame 100/100 (100 %)"), std::string::npos) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;
}

TEST(ProgressTest, OnATerminalOneLineIsRewrittenAndEndedOnce) {
  ::testing::internal::CaptureStderr();
  {
    Progress progress("render", "frame-sets", 3, /*terminal=*/true, 5);
    for (int done = 1; done <= 3; ++done) progress.Set(done, "frame");
  }
  const std::string text = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(text.rfind("\r", 0), 0u) << text;
  EXPECT_NE(text.find("render: frame 3/3 (100 %)"), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;  // ended by the last count, not again
  EXPECT_EQ(text.back(), '\n');
}

TEST(ProgressTest, QuietScopesHideAllButTheProgressThatIgnoresThem) {
  LogCapture capture;
  {
    const QuietProgress quiet;
    Progress inner("render", "frame-sets", 2, false, 0);
    inner.Set(2);
    Progress outer("suite s", "scenarios", 1, false, 0);
    outer.IgnoreQuiet();
    outer.Set(1);
  }
  const std::string text = capture.Text();
  EXPECT_EQ(text.find("render"), std::string::npos) << text;
  EXPECT_NE(text.find("suite s: 1/1"), std::string::npos) << text;
}

}  // namespace
}  // namespace irbench
