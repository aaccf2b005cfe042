// The tracker's front end against the truth on rendered sequences (thesis
// ch. 3): silhouettes from the background model on the `thesis` sensor preset
// (flicker, grain, soft shadows), shadow removal. The tracker's code reads only
// what a rig gives it (SequenceInput); this test reads the truth to score it.

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/sequence/render_job.h"
#include "tests/test_util.h"
#include "tracker/io/sequence_input.h"
#include "tracker/silhouette/background_model.h"
#include "tracker/silhouette/shadow_removal.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::WriteText;

cv::Mat TruthMask(const fs::path& seq, const std::string& cam, int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", frame);
  return cv::imread((seq / "truth/masks" / cam / name).string(), cv::IMREAD_UNCHANGED);
}

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const int u = cv::countNonZero(a | b);
  return u == 0 ? 1.0 : double(cv::countNonZero(a & b)) / u;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// Renders `person` on theater4 with the thesis preset: a few frames of the
// atom tour, time-warped so they span many arm postures.
fs::path RenderThesis(const fs::path& dir, const std::string& person, int frames) {
  const fs::path session = dir / "tour.json";
  WriteText(session, R"({"format": "irbench.session/1", "items": [{"motion": "atom_tour", "speed": 6}]})");
  RenderJobOptions options;
  options.rig = "theater4";
  options.avatar = person;
  options.motion = session.string();
  options.sensor = "thesis";
  options.frames = frames;
  options.background_frames = 12;
  options.seed = 7;
  options.out = dir / person;
  return RunRenderJob(options);
}

TEST(FrontendClosedLoopTest, SilhouettesOnTheThesisPreset) {
  const fs::path dir = FreshTempDir("frontend_silhouettes");
  std::vector<double> iou_flicker, iou_plain, iou_raw;
  long fp_before = 0, fp_after = 0, body_before = 0, body_after = 0;
  for (const std::string person : {"p1", "p2", "p3", "p4", "p5"}) {
    const fs::path seq = RenderThesis(dir, person, 4);
    const SequenceInput in = SequenceInput::Open(seq);
    for (size_t c = 0; c < in.cameras().size(); ++c) {
      const int cam = static_cast<int>(c);
      const std::vector<cv::Mat> background = in.Backgrounds(cam);
      BackgroundOptions plain_options;
      plain_options.model = "plain";
      const auto flicker = BackgroundModel::Train(background, {});
      const auto plain = BackgroundModel::Train(background, plain_options);
      const auto shadows = ShadowRemover::Train(background, {});
      ASSERT_TRUE(flicker && plain && shadows);
      for (int f = 0; f < in.frame_count(); ++f) {
        const cv::Mat frame = in.Frame(cam, f);
        const cv::Mat truth = TruthMask(seq, in.cameras()[c].name, f);
        const cv::Mat sil = flicker->Segment(frame).mask;
        const cv::Mat cleaned = shadows->Remove(frame, sil);
        iou_raw.push_back(IoU(sil, truth));
        iou_flicker.push_back(IoU(cleaned, truth));
        iou_plain.push_back(IoU(shadows->Remove(frame, plain->Segment(frame).mask), truth));
        fp_before += cv::countNonZero(sil & ~truth);
        fp_after += cv::countNonZero(cleaned & ~truth);
        body_before += cv::countNonZero(sil & truth);
        body_after += cv::countNonZero(cleaned & truth);
      }
    }
    fs::remove_all(seq);
  }
  std::printf("silhouette IoU, median over %zu camera-frames: flicker model %.3f (before shadow removal %.3f), "
              "thesis plain model %.3f\n",
              iou_flicker.size(), Median(iou_flicker), Median(iou_raw), Median(iou_plain));
  std::printf("false foreground pixels %ld -> %ld (%.0f%% fewer); body pixels lost %.2f%%\n", fp_before, fp_after,
              100.0 * (1 - double(fp_after) / std::max(1L, fp_before)),
              100.0 * (1 - double(body_after) / std::max(1L, body_before)));
  // Floors under today's figures (0.740, plain 0.423; 66% fewer false
  // foreground pixels, 8.2% of the body lost), so a regression fails. The
  // issue's bars — median IoU 0.92, shadows down 70% with at most 3% of the
  // body lost — are not met yet: clothing as grey as the wall behind it, and
  // the thesis preset's defocus blur, cost most of the difference.
  EXPECT_GE(Median(iou_flicker), 0.70);
  EXPECT_GE(Median(iou_flicker) - Median(iou_plain), 0.2);
  EXPECT_LE(double(fp_after), 0.45 * double(fp_before));
  EXPECT_LE(1 - double(body_after) / std::max(1L, body_before), 0.11);
}

}  // namespace
}  // namespace irbench
