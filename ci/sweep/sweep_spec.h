#pragma once
// A sweep spec (irbench.sweep/1, docs/sweeps.md): a base scenario in a
// suite's terms, axes — camera placements along a wall or ceiling line, over
// heights, pans and tilts; lists of values for a scenario key (rig, avatar,
// motion, sensor, seed, frames, track.<setting>) or for the point's rig
// (rig.cameras, rig.resolution, rig.focal_scale, rig.dist and the sensor
// knobs sensor.<group>.<knob>: sweep_rig.h); arm poses — and a mode: `grid`
// (every combination), seeded `random` samples, or `search`: the
// cross-entropy method over the placements, generation by generation, each
// generation drawn around the best points of the ones before. Points are
// numbered; a point's coordinates depend only on the spec, its index and
// (search) the metrics of the earlier generations' points, so any process (a
// local worker, a Slurm array task) can run point i alone.

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "ci/suite_runner/scenario.h"

namespace irbench {

// `from` to `to` in `steps` even steps, both ends included (steps 1: `from`).
struct SweepRange {
  double from = 0, to = 0;
  int steps = 1;
  double At(int step) const { return steps <= 1 ? from : from + (to - from) * step / (steps - 1); }
};

// One camera moved along a line on a wall or the ceiling (x, y in metres, at
// each height), aimed at `look_at`, then turned by `pan` degrees about its up
// (positive: to the left, counter-clockwise seen from above) and tilted by
// `tilt` degrees towards its up: a tripod head's two angles.
struct PlacementAxis {
  std::string camera;
  Eigen::Vector2d from = Eigen::Vector2d::Zero(), to = Eigen::Vector2d::Zero();
  int steps = 1;  // positions along the line
  SweepRange height;
  Eigen::Vector3d look_at = Eigen::Vector3d(0, 0, 1);
  bool has_up = false;
  Eigen::Vector3d up = Eigen::Vector3d(0, 0, 1);
  bool aims = false;  // the spec gives `pan` or `tilt`
  SweepRange pan, tilt;
};

// An arm pose held (sweep_pose.h), in one of two spaces: `joints`, joint
// rotations in the keyframe convention (docs/formats.md: [x, y, z] degrees,
// ZXY), each component fixed or a range; or `atoms`, per arm the posture
// atoms' weights (the library's `posture` motion: the rest posture A0 plus
// each weight times its atom's departure from it), each fixed or a range.
// A point's motion stands, moves into the pose in `move_s`, holds it
// `hold_s`.
struct PoseDim {
  std::string joint;  // joints: the joint; atoms: the arm, "right" or "left"
  int component = 0;  // joints: 0 x, 1 y, 2 z; atoms: the atom, 0..4
  SweepRange range;
  bool atom = false;
  // Its name in the outputs: "right_shoulder.z", "right.A2".
  std::string Label() const {
    return joint + "." + (atom ? "A" + std::to_string(component) : std::string(1, "xyz"[component]));
  }
};
struct PoseAxis {
  bool atoms = false;                            // the space: atoms' weights, else joint rotations
  std::map<std::string, Eigen::Vector3d> fixed;  // joints: every listed joint's components, ranges at their `from`
  std::map<std::string, std::array<double, 5>> weights;  // atoms: per listed arm, A0..A4, ranges at their `from`
  std::vector<PoseDim> dims;                     // the ranged components
  double move_s = 1.0, hold_s = 2.0;
};

// A scenario key (`rig`, `motion`, `track.rest_model` ...) taking each value.
struct ValueAxis {
  std::string key;
  std::vector<nlohmann::json> values;
};

struct SweepAxis {
  std::string name;  // the camera's name or the key
  std::variant<PlacementAxis, ValueAxis, PoseAxis> axis;
};

struct SweepSpec {
  std::string name, description;
  std::filesystem::path file;
  nlohmann::json base;  // the base scenario's keys as written
  std::vector<SweepAxis> axes;
  std::string mode = "grid";  // grid | random | search | adversarial (a search for the worst)
  int samples = 0;            // random: points
  uint64_t seed = 1;          // random, search: the sampler's seed
  // search (the cross-entropy method): `population` points per generation,
  // `generations` of them; each generation draws around the mean and spread
  // of the `elite` best points of all generations before it (its first point
  // is that mean itself).
  int population = 0, generations = 0, elite = 0;
  std::string metric = "arms_mean_cm";  // ranks the points (KnownMetrics())
  std::vector<std::filesystem::path> inputs;  // the data files the points read (rigs, avatars, motions ...)
  std::string canonical;  // the spec as parsed, one JSON text: what OUT/spec.json holds
};

// Where a point sits on one axis.
struct AxisValue {
  double along = 0;   // placement: 0..1 from `from` to `to`
  double height = 0;  // placement: metres
  double pan = 0, tilt = 0;  // placement: degrees
  int along_step = -1, height_step = -1;  // grid: the steps; random: -1
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  nlohmann::json value;  // value axis
  std::vector<double> pose;  // pose axis: per dim, degrees
};

struct SweepPoint {
  int index = 0;
  std::vector<AxisValue> at;  // per axis
};

// Reads and checks a spec: every field named in errors (InputError), every
// value axis's values and every placement's corners tried against the scene
// (a camera outside the scene's bounds, an unknown camera, an empty range).
SweepSpec LoadSweepSpec(const std::filesystem::path& file);

// grid: the product of the axes' sizes; random: `samples`; search:
// population x generations.
int PointCount(const SweepSpec& spec);

// A point's generation (search: index / population; otherwise 0) and how
// many generations there are: a generation's points need the ones before done.
int GenerationOf(const SweepSpec& spec, int index);
int GenerationCount(const SweepSpec& spec);

// The spec's metric of a finished point; nullopt when it is not done (or
// measured nothing).
using PointMetric = std::function<std::optional<double>(int index)>;

// Where a camera at `position` aimed at `look_at` with `up` looks after the
// placement's pan and tilt (degrees; PlacementAxis): the point at the same
// distance along the turned direction; `look_at` itself when both are 0.
Eigen::Vector3d AimedLookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& look_at,
                            const Eigen::Vector3d& up, double pan_deg, double tilt_deg);

// Point `index` (0 <= index < PointCount): grid in row-major order over the
// axes (the last axis fastest); random from a hash of (seed, index, axis);
// search from the seed and the earlier generations' metrics (`metric_of`;
// RuntimeError naming the point when one of them is not done).
SweepPoint PointAt(const SweepSpec& spec, int index, const PointMetric& metric_of = {});

// {"<camera>.along": .., "<camera>.height": .., "<camera>.position": [x,y,z],
// (a placement with aim ranges) "<camera>.pan": .., "<camera>.tilt": ..,
// "<key>": value, ...}
nlohmann::json PointCoordinates(const SweepSpec& spec, const SweepPoint& point);

// The point's scenario: the base with the point's values; a placement writes
// the moved rig to <out>/rigs/pNNNN.json, a pose its motion to
// <out>/motions/pNNNN.json (those files render the point alone).
Scenario PointScenario(const SweepSpec& spec, const SweepPoint& point, const std::filesystem::path& out);

// "p0007"
std::string PointName(int index);

// Whether the mode seeks high values of the metric: a search seeks the best
// (high for fractions, low for errors), `adversarial` the worst.
bool SeeksHigh(const SweepSpec& spec);

}  // namespace irbench
