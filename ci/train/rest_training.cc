#include "ci/train/rest_training.h"

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

RestTrainingResult RunRestTraining(const RestTrainingOptions& options) {
  if (!(options.sample_fps > 0)) throw InputError("", "--fps", "must be positive");
  if (options.folds < 2) throw InputError("", "--folds", "must be at least 2");
  if (options.avatars.empty()) throw InputError("", "--avatars", "needs at least one avatar");
  if (options.motions.empty()) throw InputError("", "--motions", "needs at least one motion");
  const Scene scene = LoadScene(ResolveDataFile("scenes", "theater", "--scene"));
  const auto& names = TruthJointNames();
  auto index = [&](const std::string& n) {
    return static_cast<size_t>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  std::vector<std::array<float, 6>> features;
  std::vector<int> labels;
  Progress progress("train rest", "motions",
                    static_cast<int>(options.avatars.size() * options.motions.size()));
  int sampled = 0;
  for (const std::string& avatar_name : options.avatars) {
    const std::filesystem::path avatar_file = ResolveDataFile("avatars", avatar_name, "--avatars");
    const Avatar avatar = LoadAvatar(avatar_file);
    for (const std::string& motion_name : options.motions) {
      MotionContext ctx;
      ctx.avatar = &avatar;
      ctx.scene = &scene;
      ctx.style = StyleFor(avatar.params.name, options.seed, avatar.params.style, avatar_file.string());
      const ResolvedMotion motion = ResolveMotion(motion_name, ctx, "--motions");
      const Labeler labeler(avatar, &scene, *motion.motion);
      const double duration = motion.motion->Duration();
      for (double t = 0; t <= duration; t += 1.0 / options.sample_fps) {
        const std::vector<Eigen::Vector3d> j =
            TruthJoints(avatar, ForwardKinematics(avatar.skeleton, motion.motion->At(t)));
        const nlohmann::json rest = labeler.Labels(t)["rest"];
        for (const char* side : {"right", "left"}) {
          if (!rest.contains(side) || !rest[side].is_boolean()) continue;
          const std::string s(side);
          features.push_back(RestFeatures(j[index("waist")], j[index("neck")], j[index("right_shoulder")],
                                          j[index("left_shoulder")], j[index(s + "_elbow")], j[index(s + "_wrist")],
                                          avatar.params.height_m, s == "left"));
          labels.push_back(rest[side].get<bool>() ? 1 : 0);
        }
      }
      Log().debug("train rest: {} on {}: {} samples so far", motion_name, avatar_name, features.size());
      progress.Set(++sampled, "motions sampled");
    }
  }
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
  classifier.Save(result.model);
  return result;
}

}  // namespace irbench
