// Closed loop: render a person raising an arm, feed the truth masks (the test
// may read truth; the library never does) and the calibration the tracker reads
// to the axis chain, and compare the 3D arm axis points with the true arm bones.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "sim/sequence/render_job.h"
#include "tracker/axis/axis3d.h"
#include "tracker/io/sequence_input.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double s = std::clamp((p - a).dot(b - a) / std::max(1e-12, (b - a).squaredNorm()), 0.0, 1.0);
  return (a + s * (b - a) - p).norm();
}

Eigen::Vector3d Joint(const nlohmann::json& frame, const std::string& name) {
  const auto& j = frame["joints3d"][name];
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

struct Distances {
  std::vector<double> arm_to_bones;  // m, every 3D arm point of every frame checked
  int frames = 0;
};

// Frames where a wrist is raised to within 10 cm below its shoulder or higher,
// up to `max_frames`
// of them spread over the sequence.
Distances ArmPointsAgainstTruth(const fs::path& seq, int max_frames) {
  const SequenceInput input = SequenceInput::Open(seq);
  std::vector<nlohmann::json> raised;
  std::ifstream truth(seq / "truth/frames.jsonl");
  for (std::string line; std::getline(truth, line);) {
    const auto frame = nlohmann::json::parse(line);
    for (const char* side : {"left", "right"}) {
      const std::string s(side);
      if (Joint(frame, s + "_wrist").z() > Joint(frame, s + "_shoulder").z() - 0.1) {
        raised.push_back(frame);
        break;
      }
    }
  }
  Distances out;
  if (raised.empty()) return out;
  const int step = std::max<int>(1, int(raised.size()) / max_frames);
  for (size_t r = 0; r < raised.size() && out.frames < max_frames; r += step) {
    const nlohmann::json& frame = raised[r];
    char file[32];
    std::snprintf(file, sizeof(file), "%06d.png", frame["frame"].get<int>());
    std::vector<cv::Mat> masks;
    for (const Camera& camera : input.cameras()) {
      masks.push_back(cv::imread((seq / "truth/masks" / camera.name / file).string(), cv::IMREAD_GRAYSCALE));
      EXPECT_FALSE(masks.back().empty()) << camera.name << " " << file;
      if (masks.back().empty()) return out;
    }
    std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> bones;
    for (const std::string side : {"left", "right"}) {
      bones.emplace_back(Joint(frame, side + "_shoulder"), Joint(frame, side + "_elbow"));
      bones.emplace_back(Joint(frame, side + "_elbow"), Joint(frame, side + "_wrist"));
      bones.emplace_back(Joint(frame, side + "_wrist"), Joint(frame, side + "_hand_tip"));
    }
    int arm_points = 0;
    for (const AxisPoint3d& p : ReconstructBodyAxes(input.cameras(), masks)) {
      if (p.part != BodyPart::kArm) continue;
      double nearest = 1e9;
      for (const auto& [a, b] : bones) nearest = std::min(nearest, DistanceToSegment(p.p_in_world, a, b));
      out.arm_to_bones.push_back(nearest);
      ++arm_points;
    }
    EXPECT_GT(arm_points, 10) << "frame " << file;
    ++out.frames;
  }
  return out;
}

double Quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, size_t(q * double(values.size())))];
}

void CheckRaisedArm(const std::string& rig, const std::string& avatar, const std::string& motion) {
  RenderJobOptions options;
  options.rig = rig;
  options.avatar = avatar;
  options.motion = motion;
  options.frames = 45;
  options.background_frames = 0;
  options.overwrite = true;
  options.out = fs::temp_directory_path() / ("irbench_test_axis_" + rig + "_" + avatar + "_" + motion);
  const fs::path seq = RunRenderJob(options);
  const Distances d = ArmPointsAgainstTruth(seq, 4);
  ASSERT_GE(d.frames, 2) << "too few frames with a raised arm";
  ASSERT_FALSE(d.arm_to_bones.empty());
  const double median = Quantile(d.arm_to_bones, 0.5), p90 = Quantile(d.arm_to_bones, 0.9);
  std::printf("[axis] %s %s %s: %d frames, %zu 3D arm points, distance to the arm bones median %.1f mm, "
              "p90 %.1f mm\n",
              rig.c_str(), avatar.c_str(), motion.c_str(), d.frames, d.arm_to_bones.size(), median * 1e3,
              p90 * 1e3);
  EXPECT_LT(median, 0.04);  // the bar
  fs::remove_all(seq);
}

TEST(AxisSequenceTest, RaisedArmAxisNearTheTrueBonesTheater4) { CheckRaisedArm("theater4", "p1", "raise_overhead"); }

TEST(AxisSequenceTest, HorizontalPointNearTheTrueBonesLab4) { CheckRaisedArm("lab4", "p4", "point_horizontal"); }

}  // namespace
}  // namespace irbench
