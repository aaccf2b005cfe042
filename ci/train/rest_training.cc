#include "ci/train/rest_training.h"

#include <algorithm>

#include "common/error.h"
#include "common/logging.h"
#include "common/progress.h"
#include "common/paths.h"
#include "sim/body/avatar.h"
#include "sim/motion/labels.h"
#include "sim/motion/library.h"
#include "sim/motion/session.h"
#include "sim/scene/scene.h"
#include "tracker/pose/rest_state.h"

namespace irbench {

namespace {

// The arm samples (features, truth rest labels) of `motions` played on
// `avatars`, every 1/sample_fps s.
struct ArmSamples {
  std::vector<std::array<float, 6>> features;
  std::vector<int> labels;
};

ArmSamples SampleArms(const std::vector<std::string>& avatars, const std::vector<std::string>& motions,
                      const char* avatars_option, const char* motions_option, const RestTrainingOptions& options,
                      const Scene& scene, Progress* progress, int* sampled) {
  const auto& names = TruthJointNames();
  auto index = [&](const std::string& n) {
    return static_cast<size_t>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  ArmSamples out;
  for (const std::string& avatar_name : avatars) {
    const std::filesystem::path avatar_file = ResolveDataFile("avatars", avatar_name, avatars_option);
    const Avatar avatar = LoadAvatar(avatar_file);
    for (const std::string& motion_name : motions) {
      MotionContext ctx;
      ctx.avatar = &avatar;
      ctx.scene = &scene;
      ctx.style = StyleFor(avatar.params.name, options.seed, avatar.params.style, avatar_file.string());
      const ResolvedMotion motion = ResolveMotion(motion_name, ctx, motions_option);
      const Labeler labeler(avatar, &scene, *motion.motion);
      const double duration = motion.motion->Duration();
      for (double t = 0; t <= duration; t += 1.0 / options.sample_fps) {
        const std::vector<Eigen::Vector3d> j =
            TruthJoints(avatar, ForwardKinematics(avatar.skeleton, motion.motion->At(t)));
        const nlohmann::json rest = labeler.Labels(t)["rest"];
        for (const char* side : {"right", "left"}) {
          if (!rest.contains(side) || !rest[side].is_boolean()) continue;
          const std::string s(side);
          out.features.push_back(RestFeatures(j[index("waist")], j[index("neck")], j[index("right_shoulder")],
                                              j[index("left_shoulder")], j[index(s + "_elbow")],
                                              j[index(s + "_wrist")], avatar.params.height_m, s == "left"));
          out.labels.push_back(rest[side].get<bool>() ? 1 : 0);
        }
      }
      Log().debug("train rest: {} on {}: {} samples so far", motion_name, avatar_name, out.features.size());
      progress->Set(++*sampled, "motions sampled");
    }
  }
  return out;
}

}  // namespace

RestTrainingResult RunRestTraining(const RestTrainingOptions& options) {
  if (!(options.sample_fps > 0)) throw InputError("", "--fps", "must be positive");
  if (options.folds < 2) throw InputError("", "--folds", "must be at least 2");
  if (options.avatars.empty()) throw InputError("", "--avatars", "needs at least one avatar");
  if (options.motions.empty()) throw InputError("", "--motions", "needs at least one motion");
  for (const std::string& a : options.test_motions.empty() ? std::vector<std::string>{} : options.test_avatars) {
    if (std::count(options.avatars.begin(), options.avatars.end(), a))
      throw InputError("", "--test-avatars", a + " is also trained on (--avatars)");
  }
  for (const std::string& m : options.test_motions) {
    if (std::count(options.motions.begin(), options.motions.end(), m))
      throw InputError("", "--test-motions", m + " is also trained on (--motions)");
  }
  if (!options.test_motions.empty() && options.test_avatars.empty())
    throw InputError("", "--test-avatars", "needs at least one avatar for --test-motions");
  const Scene scene = LoadScene(ResolveDataFile("scenes", "theater", "--scene"));
  const size_t test_runs = options.test_motions.empty() ? 0 : options.test_avatars.size() * options.test_motions.size();
  Progress progress("train rest", "motions",
                    static_cast<int>(options.avatars.size() * options.motions.size() + test_runs));
  int sampled = 0;
  const ArmSamples train =
      SampleArms(options.avatars, options.motions, "--avatars", "--motions", options, scene, &progress, &sampled);
  // Held out sampled before anything is written: a bad held-out motion
  // leaves no model behind.
  const ArmSamples test = test_runs > 0 ? SampleArms(options.test_avatars, options.test_motions, "--test-avatars",
                                                     "--test-motions", options, scene, &progress, &sampled)
                                        : ArmSamples{};
  const std::vector<std::array<float, 6>>& features = train.features;
  const std::vector<int>& labels = train.labels;
  RestTrainingResult result;
  result.samples = static_cast<int>(features.size());
  for (int l : labels) result.at_rest += l;
  RestClassifier classifier;
  try {
    classifier = RestClassifier::Train(features, labels, options.folds, &result.cv_accuracy);
  } catch (const std::invalid_argument& e) {
    throw InputError("", "--motions", e.what());
  }
  result.model = options.out.empty() ? DefaultRestModelPath() : options.out;
  if (result.model.has_parent_path()) std::filesystem::create_directories(result.model.parent_path());
  result.test_samples = static_cast<int>(test.features.size());
  int agree = 0;
  for (size_t i = 0; i < test.features.size(); ++i) {
    result.test_at_rest += test.labels[i];
    agree += classifier.AtRest(test.features[i]) == (test.labels[i] == 1);
  }
  if (result.test_samples > 0) result.test_accuracy = double(agree) / result.test_samples;
  classifier.Save(result.model);
  return result;
}

}  // namespace irbench
