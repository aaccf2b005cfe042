// `irbench train rest` with held-out motions: the SVM is scored on motions
// and avatars it was not trained on, and the held-out set leaves the trained
// model untouched; a held-out motion or avatar that is also trained on is
// refused before anything is written.

#include "ci/train/rest_training.h"

#include <gtest/gtest.h>

#include "common/error.h"
#include "tests/test_util.h"

namespace irbench {
namespace {

RestTrainingOptions SmallTraining(const std::filesystem::path& out) {
  RestTrainingOptions o;
  o.avatars = {"p2"};
  o.motions = {"rest", "point_horizontal", "raise_overhead", "flap_both"};
  o.sample_fps = 5;
  o.folds = 3;
  o.out = out;
  return o;
}

TEST(RestTraining, HeldOutMotionsAreScoredAndNotTrainedOn) {
  const auto dir = testing::FreshTempDir("rest_training");
  const RestTrainingResult plain = RunRestTraining(SmallTraining(dir / "plain.yml"));
  EXPECT_EQ(plain.test_samples, 0);
  RestTrainingOptions held = SmallTraining(dir / "held.yml");
  held.test_avatars = {"p6", "p7"};
  held.test_motions = {"flap_one"};
  const RestTrainingResult r = RunRestTraining(held);
  // Training is the same with or without the held-out set.
  EXPECT_EQ(r.samples, plain.samples);
  EXPECT_EQ(testing::ReadText(dir / "held.yml"), testing::ReadText(dir / "plain.yml"));
  // flap_one: one arm flaps while the other rests, so both labels are held
  // out; an SVM of the other library motions gets nearly all of them.
  ASSERT_GT(r.test_samples, 0);
  EXPECT_EQ(r.test_samples % 2, 0);  // both arms of every sampled instant
  EXPECT_GT(r.test_at_rest, r.test_samples / 10);
  EXPECT_LT(r.test_at_rest, r.test_samples * 9 / 10);
  EXPECT_GT(r.test_accuracy, 0.9);
  EXPECT_LE(r.test_accuracy, 1.0);
}

TEST(RestTraining, AHeldOutMotionOrAvatarAlsoTrainedOnIsRefused) {
  const auto dir = testing::FreshTempDir("rest_training_bad");
  RestTrainingOptions motion = SmallTraining(dir / "m.yml");
  motion.test_motions = {"flap_one", "rest"};
  try {
    RunRestTraining(motion);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--test-motions"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rest"), std::string::npos) << e.what();
  }
  RestTrainingOptions avatar = SmallTraining(dir / "a.yml");
  avatar.test_avatars = {"p6", "p2"};
  avatar.test_motions = {"flap_one"};
  try {
    RunRestTraining(avatar);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--test-avatars"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("p2"), std::string::npos) << e.what();
  }
  // A held-out motion that does not load leaves no model behind.
  RestTrainingOptions missing = SmallTraining(dir / "x.yml");
  missing.test_avatars = {"p6"};
  missing.test_motions = {(dir / "no_such.bvh").string()};
  EXPECT_THROW(RunRestTraining(missing), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.yml"));
  EXPECT_FALSE(std::filesystem::exists(dir / "m.yml"));
  EXPECT_FALSE(std::filesystem::exists(dir / "a.yml"));
}

}  // namespace
}  // namespace irbench
