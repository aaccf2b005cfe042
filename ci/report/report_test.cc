// report.html on a rendered sequence and track files made from its truth:
// the page's tables and viewer data say what the truth and the perturbation
// say, the plots are gnuplot's and count every kept sample, and the page opens
// in headless Chromium (Debian's package) without console errors and with a
// screenshot that is not blank. A page whose frame images are missing must be
// caught by the same check.

#include "ci/report/report.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>

#include "ci/report/plots.h"
#include "ci/score/score_job.h"
#include "sim/sequence/render_job.h"
#include "tests/render_session.h"
#include "tests/test_util.h"
#include "tracker/io/sequence_input.h"
#include "tracker/body_model/body_model.h"
#include "tracker/body_model/ellipse_projection.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

// The track's configured shoulder width (metres): wider than the fixed
// proportion's 0.3675 m at 1.75 m.
constexpr double kShoulderWidthM = 0.42;
using irbench::testing::ReadText;

class ReportTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = irbench::testing::FreshTempDir("report_" + std::to_string(::getpid()));
    truth_ = irbench::testing::RenderSession(dir_, R"([
      {"motion": "point", "target": "helicopter", "side": "right", "hold_s": 0.4}])");
    // The track: the truth, the right elbow 3 cm off, and the irbench model
    // (standing, 1.75 m) where the truth has the person.
    std::ofstream track(dir_ / "track.jsonl");
    for (const Json& t : truth_) {
      Json j = {{"frame", t["frame"]}, {"state", t["present"].get<bool>() ? "tracking" : "empty"},
                {"joints3d", t["joints3d"]}, {"rest", t["labels"]["rest"]}};
      j["joints3d"]["right_elbow"][0] = t["joints3d"]["right_elbow"][0].get<double>() + 0.03;
      // Postures as the truth's; a gesture the truth does not have, frames 5-15.
      j["posture"] = {{"pair", t["labels"]["posture"]}};
      const int f = t["frame"];
      if (f >= 5 && f <= 15) j["gesture"] = {{"label", "flap_both"}, {"score", 1.0}, {"start_frame", 5}};
      // Motion labels as the truth's, the right arm BACKWARD on frames 5-15.
      j["motion"] = t["labels"]["motion"];
      if (f >= 5 && f <= 15 && j["motion"].is_object()) j["motion"]["right"] = "BACKWARD";
      if (t["present"].get<bool>()) {
        const BodyShape shape = BodyShape::FromHeight(1.75);
        const BodyPose pose =
            StandingPose(shape, {t["joints3d"]["root"][0].get<double>(), t["joints3d"]["root"][1].get<double>()}, 0.0);
        j["dof"] = Json::object();
        for (int d = 0; d < kDofCount; ++d) j["dof"][BodyDofName(d)] = pose.dof[d];
        j["height_m"] = 1.75;
        j["girth"] = 1.0;
        j["shoulder_width_m"] = kShoulderWidthM;
      }
      track << j.dump() << "\n";
    }
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // Scores and reports into `out`; returns the page.
  static std::string Report(const fs::path& out) {
    ScoreJobOptions job;
    job.sequence = dir_ / "seq";
    job.track = dir_ / "track.jsonl";
    job.out = out;
    job.overwrite = true;
    RunScoreJob(job);
    return ReadText(out / "report.html");
  }
  static Json ViewerData(const std::string& html) {
    const std::string open = "<script type=\"application/json\" id=\"viewer-data\">";
    const size_t a = html.find(open);
    const size_t b = html.find("</script>", a);
    if (a == std::string::npos || b == std::string::npos) return Json();
    return Json::parse(html.substr(a + open.size(), b - a - open.size()));
  }

  static fs::path dir_;
  static std::vector<Json> truth_;
};
fs::path ReportTest::dir_;
std::vector<Json> ReportTest::truth_;

TEST_F(ReportTest, TablesPlotsAndViewerDataSayWhatTheTruthSays) {
  if (!FindGnuplot()) GTEST_SKIP() << "no gnuplot (ci/install_deps.sh installs gnuplot-nox)";
  const fs::path out = dir_ / "score";
  const std::string html = Report(out);
  // Tables: the 3 cm offset, the exact joints.
  EXPECT_NE(html.find("<tr><th>Right Elbow</th><td>3.00</td><td>0.00</td>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>Neck</th><td>0.00</td><td>0.00</td>"), std::string::npos);
  // Plots: two gnuplot SVGs embedded, and on disk.
  EXPECT_EQ(html.find("data:image/svg+xml;base64,") != std::string::npos, true);
  for (const char* svg : {"joint_histograms.svg", "errors_over_time.svg"}) {
    const std::string text = ReadText(out / "plots" / svg);
    EXPECT_NE(text.find("<svg"), std::string::npos) << svg;
    EXPECT_NE(text.find("gnuplot"), std::string::npos) << svg;  // gnuplot drew it
  }
  // The histogram counts every right-elbow sample once, all in the 3 cm bin.
  const Score score = ScoreTrack(dir_ / "seq/truth/frames.jsonl", dir_ / "track.jsonl");
  const ErrorStats& elbow = score.joints.at("right_elbow");
  ASSERT_GT(elbow.total, 5);
  std::istringstream bins(ReadText(out / "plots/hist_right_elbow.dat"));
  int counted = 0;
  for (double centre, n; bins >> centre >> n;) {
    counted += int(n);
    if (n > 0) {
      EXPECT_LT(std::abs(centre - 3.0), 0.2) << centre;
    }
  }
  EXPECT_EQ(counted, elbow.total - elbow.outliers);

  // The viewer: every frame; the truth's 2D joints as rendered; the tracked
  // joints projected where the truth's are (the elbow excepted); the model's
  // head outline about the projected head centre.
  const Json data = ViewerData(html);
  ASSERT_TRUE(data.is_object());
  const SequenceInput input = SequenceInput::Open(dir_ / "seq");
  ASSERT_EQ(data["frames"].size(), truth_.size());
  ASSERT_EQ(data["cameras"].size(), input.cameras().size());
  const std::vector<std::string> names = data["joints"];
  int compared = 0;
  // Pixels between the drawn upper arms' outlines' means and their centres
  // projected, for the configured and the fixed shoulders.
  double fixed_apart = 0, configured_apart = 0;
  for (const Json& t : truth_) {
    const int f = t["frame"];
    const Json& fr = data["frames"][f];
    EXPECT_EQ(fr["present"], t["present"]);
    for (size_t c = 0; c < input.cameras().size(); ++c) {
      const Camera& cam = input.cameras()[c];
      const Json& truth2d = t["joints2d"][cam.name];
      for (size_t j = 0; j < names.size(); ++j) {
        const Json& p = truth2d[names[j]];
        if (!p.is_array() || !p[0].is_number()) continue;
        EXPECT_NEAR(fr["t"][c][3 * j].get<double>(), p[0].get<double>(), 0.051);
        if (!t["present"].get<bool>() || names[j] == "right_elbow") continue;
        ASSERT_FALSE(fr["k"][c].is_null());
        EXPECT_NEAR(fr["k"][c][2 * j].get<double>(), p[0].get<double>(), 0.11) << names[j] << " " << cam.name;
        EXPECT_NEAR(fr["k"][c][2 * j + 1].get<double>(), p[1].get<double>(), 0.11) << names[j] << " " << cam.name;
        ++compared;
      }
      if (!t["present"].get<bool>()) {
        EXPECT_TRUE(fr["m"][c].empty());
        continue;
      }
      ASSERT_EQ(fr["m"][c].size(), 7u) << cam.name;  // seven ellipsoids
      // The head's outline (segment 2) and the upper arms' surround their
      // centres' projections, the arms hanging from the configured
      // shoulders (the track's shoulder_width_m).
      const BodyShape fixed = BodyShape::FromHeight(1.75);
      const BodyShape shape =
          BodyShape::FromHeight(1.75, 1.0, 1.0, kShoulderWidthM / (2 * fixed.shoulder_offset_m));
      const BodyPose pose =
          StandingPose(fixed, {t["joints3d"]["root"][0].get<double>(), t["joints3d"]["root"][1].get<double>()}, 0);
      const PosedBody body = PoseBody(fixed, pose), configured = PoseBody(shape, pose);
      for (const int seg : {int(kHeadSegment), int(kRightUpperArm), int(kLeftUpperArm)}) {
        const Eigen::Vector2d centre = cam.Project(configured.segments[seg].center);
        const Json& outline = fr["m"][c][seg];
        Eigen::Vector2d mean = Eigen::Vector2d::Zero();
        for (size_t i = 0; i < outline.size(); i += 2) mean += Eigen::Vector2d(outline[i], outline[i + 1]);
        mean /= double(outline.size() / 2);
        EXPECT_LT((mean - centre).norm(), 1.5) << cam.name << " " << BodySegmentName(seg);
        if (seg != kHeadSegment) {
          fixed_apart = std::max(fixed_apart, (mean - cam.Project(body.segments[seg].center)).norm());
          configured_apart = std::max(configured_apart, (mean - centre).norm());
        }
      }
    }
  }
  EXPECT_GT(compared, 100);
  // The fixed proportion's arms would have been drawn elsewhere.
  EXPECT_LT(configured_apart, 0.6);
  EXPECT_GT(fixed_apart, 1.5);
  // Worst frames first: the largest mean joint error leads.
  ASSERT_FALSE(data["worst"].empty());
  double worst = -1;
  for (const Json& fr : data["frames"]) {
    if (!fr["e"].is_null()) worst = std::max(worst, fr["e"].get<double>());
  }
  EXPECT_EQ(data["frames"][data["worst"][0].get<int>()]["e"].get<double>(), worst);
}

TEST_F(ReportTest, WithoutGnuplotThePageSaysSo) {
  ::setenv("IRBENCH_GNUPLOT", "", 1);
  const std::string html = Report(dir_ / "score_no_gnuplot");
  ::unsetenv("IRBENCH_GNUPLOT");
  EXPECT_NE(html.find("no gnuplot found"), std::string::npos);
  EXPECT_EQ(html.find("data:image/svg+xml"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "score_no_gnuplot/plots"));
  EXPECT_NE(html.find("<table id=\"joints\">"), std::string::npos);
  // Recognition: the postures' table, and the gesture timeline (inline SVG,
  // no gnuplot) with the recognised gesture where the track put it.
  EXPECT_NE(html.find("<table id=\"postures\">"), std::string::npos);
  EXPECT_NE(html.find("<svg id=\"gesture-timeline\""), std::string::npos);
  EXPECT_NE(html.find("<title>flap_both, frames 5–15</title>"), std::string::npos);
  // Motion labels: the table with per-label recall, and a timeline per arm.
  EXPECT_NE(html.find("<table id=\"motion-recall\">"), std::string::npos);
  EXPECT_NE(html.find("<svg id=\"motion-timeline-left\""), std::string::npos);
  const size_t right = html.find("<svg id=\"motion-timeline-right\"");
  ASSERT_NE(right, std::string::npos);
  EXPECT_NE(html.find("<title>BACKWARD, frames 5–15</title>", right), std::string::npos);
}

// Debian's Chromium, headless, as root: what the page printed to its console
// and a screenshot.
struct BrowserRun {
  int status = -1;
  std::vector<std::string> console;  // Chromium's CONSOLE log lines
  fs::path screenshot;
};

std::optional<fs::path> FindChromium() {
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"}) {
    if (::access(p, X_OK) == 0) return fs::path(p);
  }
  return std::nullopt;
}

BrowserRun OpenInChromium(const fs::path& chromium, const fs::path& page, const fs::path& work) {
  fs::create_directories(work);
  BrowserRun run;
  run.screenshot = work / "screenshot.png";
  const fs::path log = work / "chromium.log";
  const std::string command =
      "timeout 120 '" + chromium.string() +
      "' --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking"
      " --disable-component-update --disable-sync --user-data-dir='" + (work / "profile").string() +
      "' --enable-logging=stderr --v=0 --virtual-time-budget=5000 --window-size=1400,5000 --screenshot='" +
      run.screenshot.string() + "' 'file://" + fs::absolute(page).string() + "' > '" + log.string() + "' 2>&1";
  run.status = std::system(command.c_str());
  std::istringstream lines(ReadText(log));
  for (std::string line; std::getline(lines, line);) {
    if (line.find(":CONSOLE") != std::string::npos) run.console.push_back(line);
  }
  return run;
}

TEST_F(ReportTest, OpensInHeadlessChromiumWithoutConsoleErrors) {
  const std::optional<fs::path> chromium = FindChromium();
  if (!chromium) GTEST_SKIP() << "no Chromium (ci/install_deps.sh installs Debian's chromium)";
  const fs::path out = dir_ / "score_browser";
  Report(out);
  const BrowserRun run = OpenInChromium(*chromium, out / "report.html", dir_ / "browser");
  ASSERT_EQ(run.status, 0) << ReadText(dir_ / "browser/chromium.log");
  EXPECT_TRUE(run.console.empty()) << run.console.front();
  const cv::Mat shot = cv::imread(run.screenshot.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(shot.empty());
  cv::Scalar mean, stddev;
  cv::meanStdDev(shot, mean, stddev);
  EXPECT_GT(stddev[0], 20.0);  // not one colour
  // The frame viewer drew the dark IR frames: many dark pixels in the page.
  EXPECT_GT(cv::countNonZero(shot < 80), shot.total() / 20);

  // The same page away from its sequence: the frames cannot load, and the
  // check must say so.
  const fs::path moved = dir_ / "moved";
  fs::create_directories(moved / "elsewhere");
  fs::copy_file(out / "report.html", moved / "elsewhere/report.html", fs::copy_options::overwrite_existing);
  const BrowserRun broken = OpenInChromium(*chromium, moved / "elsewhere/report.html", dir_ / "browser_broken");
  ASSERT_FALSE(broken.console.empty());
  EXPECT_NE(broken.console.front().find("report: cannot load"), std::string::npos) << broken.console.front();
}

// The viewer's silhouette overlay: a track whose silhouettes are the truth
// masks moved 4 px to the right. With the overlay on, the page loads the
// masks without a console message and draws the agreement yellow, the false
// foreground red and the missed body green.
TEST_F(ReportTest, SilhouetteOverlayDrawsAgreementAndErrors) {
  const std::optional<fs::path> chromium = FindChromium();
  if (!chromium) GTEST_SKIP() << "no Chromium (ci/install_deps.sh installs Debian's chromium)";
  const fs::path folder = dir_ / "with_silhouettes";
  fs::create_directories(folder);
  fs::copy_file(dir_ / "track.jsonl", folder / "track.jsonl", fs::copy_options::overwrite_existing);
  for (const auto& camera : fs::directory_iterator(dir_ / "seq/truth/masks")) {
    fs::create_directories(folder / "silhouettes" / camera.path().filename());
    for (const auto& file : fs::directory_iterator(camera.path())) {
      const cv::Mat mask = cv::imread(file.path().string(), cv::IMREAD_GRAYSCALE);
      ASSERT_FALSE(mask.empty());
      cv::Mat moved = cv::Mat::zeros(mask.size(), CV_8U);
      mask.colRange(0, mask.cols - 4).copyTo(moved.colRange(4, mask.cols));
      cv::imwrite((folder / "silhouettes" / camera.path().filename() / file.path().filename()).string(), moved);
    }
  }
  ScoreJobOptions job;
  job.sequence = dir_ / "seq";
  job.track = folder / "track.jsonl";
  job.out = dir_ / "score_overlay";
  job.overwrite = true;
  RunScoreJob(job);
  std::string page = ReadText(job.out / "report.html");
  const Json data = ViewerData(page);
  ASSERT_TRUE(data["cameras"][0].contains("silhouettes"));
  EXPECT_EQ(data["cameras"][0]["silhouettes"].get<std::string>(),
            "../with_silhouettes/silhouettes/" + data["cameras"][0]["name"].get<std::string>() + "/");
  // Turn the overlay on, as a click would.
  const std::string box = "id=\"show-silhouettes\">";
  const size_t at = page.find(box);
  ASSERT_NE(at, std::string::npos);
  page.replace(at, box.size(), "id=\"show-silhouettes\" checked>");
  irbench::testing::WriteText(job.out / "overlay.html", page);
  // Pixels of the three colours, with the overlay and without it (the
  // skeletons and the model have greens and oranges of their own).
  const auto colours = [&](const fs::path& html, const fs::path& work) {
    const BrowserRun run = OpenInChromium(*chromium, html, work);
    EXPECT_EQ(run.status, 0) << ReadText(work / "chromium.log");
    EXPECT_TRUE(run.console.empty()) << run.console.front();
    const cv::Mat shot = cv::imread(run.screenshot.string(), cv::IMREAD_COLOR);
    std::array<int, 3> count = {0, 0, 0};  // yellow, red, green
    for (int y = 0; y < shot.rows; ++y) {
      for (int x = 0; x < shot.cols; ++x) {
        const cv::Vec3b p = shot.at<cv::Vec3b>(y, x);  // B, G, R
        count[0] += p[2] > 150 && p[1] > 150 && p[0] < 110;
        count[1] += p[2] > 150 && p[1] < 110 && p[0] < 110;
        count[2] += p[1] > 140 && p[2] < 110 && p[0] < 110;
      }
    }
    return count;
  };
  const std::array<int, 3> on = colours(job.out / "overlay.html", dir_ / "browser_overlay");
  const std::array<int, 3> off = colours(job.out / "report.html", dir_ / "browser_no_overlay");
  std::printf("yellow, red, green pixels: with the overlay %d, %d, %d; without %d, %d, %d\n", on[0], on[1], on[2],
              off[0], off[1], off[2]);
  EXPECT_GT(on[0] - off[0], 500);
  EXPECT_GT(on[1] - off[1], 100);
  EXPECT_GT(on[2] - off[2], 100);
}

}  // namespace
}  // namespace irbench
