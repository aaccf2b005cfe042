#include "tracker/frontend/camera_health.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "common/error.h"

namespace irbench {
namespace {

// A grey frame of mean `level` with seeded noise (a live camera never repeats).
cv::Mat Noisy(double level, int seed) {
  cv::Mat image(48, 64, CV_8U);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::NORMAL, level, 3.0);
  return image;
}

// A camera whose empty stage had mean `level`, with sensor noise.
CameraReference Ref(double level, bool noisy = true) { return {level, noisy}; }

TEST(CameraHealthTest, BlackFramesAreDarkAndTheCameraComesBack) {
  CameraHealthMonitor monitor({Ref(40), Ref(40)});
  // The thesis preset's flicker halves the light at worst: still ok.
  auto s = monitor.Update({Noisy(40, 1), Noisy(20, 2)});
  EXPECT_EQ(s[0].health, CameraHealth::kOk);
  EXPECT_EQ(s[1].health, CameraHealth::kOk);
  EXPECT_NEAR(s[1].mean_level, 20, 1);
  s = monitor.Update({Noisy(40, 3), cv::Mat::zeros(48, 64, CV_8U)});
  EXPECT_EQ(s[0].health, CameraHealth::kOk);
  EXPECT_EQ(s[1].health, CameraHealth::kDark);
  EXPECT_FALSE(s[1].usable());
  // A dead sensor's noise floor (a couple of grey levels) is dark too.
  s = monitor.Update({Noisy(40, 4), Noisy(2, 5)});
  EXPECT_EQ(s[1].health, CameraHealth::kDark);
  s = monitor.Update({Noisy(40, 6), Noisy(38, 7)});
  EXPECT_EQ(s[1].health, CameraHealth::kOk);
}

TEST(CameraHealthTest, ADarkStageIsNotABlackCamera) {
  // A stage whose empty frames are themselves near black (5 levels): a frame
  // of 4 is under the absolute bound but not under a fifth of the stage.
  CameraHealthMonitor dim({Ref(5)});
  EXPECT_EQ(dim.Update({Noisy(4, 1)})[0].health, CameraHealth::kOk);
  // A bright stage dimmed to a tenth (a light switched off) is not black:
  // above the absolute bound of 16 levels.
  CameraHealthMonitor bright({Ref(200)});
  EXPECT_EQ(bright.Update({Noisy(20, 1)})[0].health, CameraHealth::kOk);
}

TEST(CameraHealthTest, AFrozenCameraIsFoundOnlyWhileOthersChange) {
  CameraHealthOptions options;
  options.frozen_frames = 2;
  CameraHealthMonitor monitor({Ref(40), Ref(40), Ref(40)}, options);
  const cv::Mat still = Noisy(40, 99);
  EXPECT_EQ(monitor.Update({Noisy(40, 1), still, still})[1].health, CameraHealth::kOk);
  // Cameras 1 and 2 repeat while camera 0 changes: one repeat is tolerated...
  auto s = monitor.Update({Noisy(40, 2), still.clone(), Noisy(40, 3)});
  EXPECT_EQ(s[1].health, CameraHealth::kOk);
  // ...the second is a frozen camera.
  s = monitor.Update({Noisy(40, 4), still.clone(), Noisy(40, 5)});
  EXPECT_EQ(s[1].health, CameraHealth::kFrozen);
  EXPECT_EQ(s[0].health, CameraHealth::kOk);
  EXPECT_EQ(s[2].health, CameraHealth::kOk);
  // Back as soon as its frame changes.
  s = monitor.Update({Noisy(40, 6), Noisy(40, 7), Noisy(40, 8)});
  EXPECT_EQ(s[1].health, CameraHealth::kOk);
}

TEST(CameraHealthTest, AStillSceneInEveryCameraIsNotFrozen) {
  // A noise-free sensor over a still stage repeats in every camera: no fault.
  CameraHealthMonitor monitor({Ref(40), Ref(40)});
  const cv::Mat a = Noisy(40, 1), b = Noisy(40, 2);
  for (int i = 0; i < 5; ++i) {
    const auto s = monitor.Update({a.clone(), b.clone()});
    EXPECT_EQ(s[0].health, CameraHealth::kOk) << i;
    EXPECT_EQ(s[1].health, CameraHealth::kOk) << i;
  }
}

TEST(CameraHealthTest, ANoiseFreeCameraIsNeverCalledFrozen) {
  // The sim's clean preset: no sensor noise, so a camera that sees nothing
  // move repeats its frame while the others (seeing the person) change.
  std::vector<cv::Mat> still_stage(3, Noisy(40, 7));
  const CameraReference clean = ReferenceFromEmptyStage(still_stage);
  EXPECT_FALSE(clean.noisy);
  EXPECT_NEAR(clean.mean_level, 40, 1);
  const CameraReference noisy = ReferenceFromEmptyStage({Noisy(40, 1), Noisy(40, 2), Noisy(40, 3)});
  EXPECT_TRUE(noisy.noisy);
  EXPECT_FALSE(ReferenceFromEmptyStage({Noisy(40, 1)}).noisy);  // one frame tells nothing
  CameraHealthMonitor monitor({clean, noisy});
  const cv::Mat still = Noisy(40, 99);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(monitor.Update({still.clone(), Noisy(40, 100 + i)})[0].health, CameraHealth::kOk) << i;
  }
}

TEST(CameraHealthTest, MissingFramesAndBadInput) {
  CameraHealthMonitor monitor({Ref(40), Ref(40)});
  auto s = monitor.Update({Noisy(40, 1), cv::Mat()});
  EXPECT_EQ(s[1].health, CameraHealth::kMissing);
  EXPECT_STREQ(CameraHealthName(s[1].health), "missing");
  EXPECT_THROW(monitor.Update({Noisy(40, 1)}), InputError);
  CameraHealthOptions bad;
  bad.frozen_frames = 0;
  try {
    CameraHealthMonitor({Ref(40)}, bad);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "health.frozen_frames");
  }
}

}  // namespace
}  // namespace irbench
