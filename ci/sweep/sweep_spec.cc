#include "ci/sweep/sweep_spec.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <tuple>

#include <Eigen/Geometry>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/paths.h"
#include "ci/sweep/sweep_pose.h"
#include "ci/sweep/sweep_rig.h"
#include "sequence_format/calibration.h"
#include "sim/camera/rig.h"
#include "sim/scene/mesh.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

constexpr int kMaxSteps = 1000;
constexpr int kMaxPoints = 1000000;

// The scenario keys a value axis may take; `track.<setting>` as well.
const std::vector<std::string>& ValueKeys() {
  static const std::vector<std::string> keys = {"scene", "rig", "avatar", "motion", "sensor",
                                                "seed", "frames", "background_frames"};
  return keys;
}

int CheckSteps(const JsonNode& node) {
  const int steps = node.Int();
  if (steps < 1 || steps > kMaxSteps) node.Fail("must be in 1.." + std::to_string(kMaxSteps));
  return steps;
}

// `{"from": a, "to": b, "steps": n}` or one number (one step). A grid needs
// `steps` where from and to differ; random and search points fall anywhere
// between them.
SweepRange ReadRange(const JsonNode& node, bool grid) {
  SweepRange range;
  if (node.raw().is_number()) {
    range.from = range.to = node.Number();
    return range;
  }
  node.CheckKeys({"from", "to", "steps"});
  range.from = node.GetDouble("from");
  range.to = node.GetDouble("to");
  range.steps = node.Has("steps") ? CheckSteps(node["steps"]) : 1;
  if (!std::isfinite(range.from) || !std::isfinite(range.to)) node.Fail("from and to must be finite");
  if (grid && range.steps == 1 && range.from != range.to) node.Fail("from and to differ: give steps (a grid)");
  if (range.steps > 1 && range.from == range.to) node.Fail("an empty range: from equals to with several steps");
  return range;
}

PlacementAxis ReadPlacement(const JsonNode& a, bool grid) {
  a.CheckKeys({"camera", "along", "height", "look_at", "up", "pan", "tilt"});
  PlacementAxis p;
  p.camera = a.GetString("camera");
  const JsonNode along = a["along"];
  along.CheckKeys({"from", "to", "steps"});
  p.from = along["from"].Vec2();
  p.to = along["to"].Vec2();
  p.steps = along.Has("steps") ? CheckSteps(along["steps"]) : 1;
  if (p.steps > 1 && (p.from - p.to).norm() < 1e-9) along.Fail("an empty range: from equals to with several steps");
  if (grid && p.steps == 1 && (p.from - p.to).norm() >= 1e-9) along.Fail("from and to differ: give steps (a grid)");
  p.height = ReadRange(a["height"], grid);
  if (a.Has("look_at")) p.look_at = a["look_at"].Vec3();
  if (a.Has("up")) {
    p.has_up = true;
    p.up = a["up"].Vec3();
    if (!p.up.allFinite() || p.up.norm() < 1e-9) a["up"].Fail("a zero or non-finite vector");
  }
  for (const auto& [key, range, limit] : {std::tuple{"pan", &p.pan, 180.0}, std::tuple{"tilt", &p.tilt, 85.0}}) {
    if (!a.Has(key)) continue;
    p.aims = true;
    *range = ReadRange(a[key], grid);
    if (std::abs(range->from) > limit || std::abs(range->to) > limit) {
      a[key].Fail("degrees within ±" + std::to_string(int(limit)));
    }
  }
  return p;
}

// The spec's base scenario with `key` set to `value` ("track.x": the track
// object's x).
nlohmann::json WithValue(nlohmann::json base, const std::string& key, const nlohmann::json& value) {
  if (key.rfind("track.", 0) == 0) {
    base["track"][key.substr(6)] = value;
  } else {
    base[key] = value;
  }
  return base;
}

Scenario ScenarioOf(const nlohmann::json& keys, const fs::path& file) {
  const JsonNode node = ParseJsonString(keys.dump(), file.string());
  Scenario sc;
  ReadScenarioKeys(node, file, &sc);
  return sc;
}

// The rig file and the scene's bounds for a scenario.
struct RigPlace {
  fs::path rig_file;
  Rig rig;
  Eigen::Vector3d lo, hi;
  std::string scene;
};

RigPlace PlaceOf(const Scenario& sc) {
  const RenderInputs in = LoadRenderInputs(sc.render);
  RigPlace out;
  out.rig_file = in.rig_file;
  out.rig = in.rig;
  out.scene = in.scene.name;
  out.lo = Eigen::Vector3d::Constant(1e30);
  out.hi = Eigen::Vector3d::Constant(-1e30);
  for (const MeshVertex& v : in.scene.mesh.vertices) {
    const Eigen::Vector3d p = v.position.cast<double>();
    out.lo = out.lo.cwiseMin(p);
    out.hi = out.hi.cwiseMax(p);
  }
  return out;
}

Eigen::Vector3d PlacementPosition(const PlacementAxis& p, double along, double height) {
  const Eigen::Vector2d xy = p.from + along * (p.to - p.from);
  return {xy.x(), xy.y(), height};
}

std::string Vec(const Eigen::Vector3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "(%.3g, %.3g, %.3g)", v.x(), v.y(), v.z());
  return buf;
}

// The up a placed camera keeps: the placement's, else the rig's for it.
Eigen::Vector3d PlacedUp(const PlacementAxis& p, const Rig& rig) {
  if (p.has_up) return p.up;
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    if (rig.cameras[i].name == p.camera) return rig.up[i];
  }
  return Eigen::Vector3d(0, 0, 1);
}

// Every corner of a placement inside the scene's bounds, the camera in the rig.
void CheckPlacement(const JsonNode& a, const PlacementAxis& p, const RigPlace& place) {
  bool found = false;
  for (const Camera& c : place.rig.cameras) found |= c.name == p.camera;
  if (!found) {
    std::string names;
    for (const Camera& c : place.rig.cameras) names += (names.empty() ? "" : ", ") + c.name;
    a["camera"].Fail("no camera '" + p.camera + "' in rig " + place.rig.name + " (" + names + ")");
  }
  for (const double along : {0.0, 1.0}) {
    for (const double height : {p.height.from, p.height.to}) {
      const Eigen::Vector3d at = PlacementPosition(p, along, height);
      if ((at.array() <= place.lo.array()).any() || (at.array() >= place.hi.array()).any()) {
        a["along"].Fail("camera at " + Vec(at) + " lies outside the scene '" + place.scene +
                                                "' " + Vec(place.lo) + " to " + Vec(place.hi));
      }
      if ((at - p.look_at).norm() < 1e-6) a["look_at"].Fail("the camera at " + Vec(at) + " is at its look_at");
    }
  }
  if (!a.Has("tilt")) return;
  // Every view, tilted, stays within 85° of the horizontal (a pan about the
  // up keeps the elevation; a tilt past it would turn the camera over). The
  // view is steepest at the line's ends or where it passes nearest look_at.
  const Eigen::Vector3d up = PlacedUp(p, place.rig).normalized();
  const Eigen::Vector2d line = p.to - p.from;
  const double nearest =
      line.squaredNorm() > 0 ? std::clamp((p.look_at.head<2>() - p.from).dot(line) / line.squaredNorm(), 0.0, 1.0) : 0.0;
  for (const double along : {0.0, 1.0, nearest}) {
    for (const double height : {p.height.from, p.height.to}) {
      const Eigen::Vector3d at = PlacementPosition(p, along, height);
      const double elevation = std::asin(std::clamp((p.look_at - at).normalized().dot(up), -1.0, 1.0)) * 180 / M_PI;
      for (const double tilt : {p.tilt.from, p.tilt.to}) {
        if (std::abs(elevation + tilt) > 85) {
          char angles[96];
          std::snprintf(angles, sizeof(angles), " looks %.3g° above the horizontal; tilted %g° it would look at %.3g°",
                        elevation, tilt, elevation + tilt);
          a["tilt"].Fail("the camera at " + Vec(at) + angles + " (a tilted view stays within ±85° of the horizontal, " +
                         "up being " + Vec(up) + ")");
        }
      }
    }
  }
}

// One rig axis: its node in the spec's `axes` and its value axis.
struct RigAxisAt {
  JsonNode node;
  ValueAxis axis;
};

// The rig axes' values (sweep_rig.h) tried on every rig a point may have.
void CheckRigAxes(const SweepSpec& spec, const std::vector<RigAxisAt>& rig_axes, const std::vector<nlohmann::json>& rigs) {
  // The sensor presets a point may have, for the sensor knobs.
  std::vector<std::string> presets = {spec.base.value("sensor", std::string("thesis"))};
  for (const SweepAxis& axis : spec.axes) {
    const auto* v = std::get_if<ValueAxis>(&axis.axis);
    if (!v || v->key != "sensor") continue;
    presets.clear();
    for (const nlohmann::json& value : v->values) {
      if (value.is_string()) presets.push_back(value.get<std::string>());
    }
  }
  std::vector<fs::path> rig_files;
  for (const nlohmann::json& rig : rigs) {
    rig_files.push_back(PlaceOf(ScenarioOf(WithValue(spec.base, "rig", rig), spec.file)).rig_file);
  }
  std::vector<const RigAxisAt*> knobs;
  for (const RigAxisAt& at : rig_axes) {
    if (IsSensorKnobKey(at.axis.key)) knobs.push_back(&at);
    for (const fs::path& rig_file : rig_files) {
      for (size_t j = 0; j < at.axis.values.size(); ++j) {
        if (const std::string problem = RigAxisProblem(rig_file, {{at.axis.key, at.axis.values[j]}}, presets);
            !problem.empty()) {
          at.node["values"][j].Fail(problem);
        }
      }
    }
  }
  // Knobs bound to each other (tone_lift + tone_ceiling_drop, black_level_dn
  // and bit_depth): every combination of the knob axes' values, up to 256.
  size_t combinations = knobs.size() > 1 ? 1 : 0;
  for (const RigAxisAt* at : knobs) combinations = std::min<size_t>(combinations * at->axis.values.size(), 257);
  if (combinations == 0 || combinations > 256) return;
  for (size_t c = 0; c < combinations; ++c) {
    std::vector<std::pair<std::string, nlohmann::json>> values;
    std::string with;
    size_t rest = c, last_j = 0;
    for (const RigAxisAt* at : knobs) {
      last_j = rest % at->axis.values.size();
      rest /= at->axis.values.size();
      values.emplace_back(at->axis.key, at->axis.values[last_j]);
      if (at != knobs.back()) with += (with.empty() ? "" : ", ") + at->axis.key + " " + at->axis.values[last_j].dump();
    }
    for (const fs::path& rig_file : rig_files) {
      if (const std::string problem = RigAxisProblem(rig_file, values, presets); !problem.empty()) {
        knobs.back()->node["values"][last_j].Fail("with " + with + ": " + problem);
      }
    }
  }
}

// A placed camera must be among every `rig.cameras` value's.
void CheckPlacedCameraKept(const std::vector<RigAxisAt>& rig_axes, const JsonNode& a, const std::string& camera,
                           const Rig& rig) {
  nlohmann::json names = {{"cameras", nlohmann::json::array()}};
  for (const Camera& c : rig.cameras) names["cameras"].push_back({{"name", c.name}});
  for (const RigAxisAt& at : rig_axes) {
    if (at.axis.key != "rig.cameras") continue;
    for (const nlohmann::json& value : at.axis.values) {
      nlohmann::json kept = names;
      ApplyRigAxis(at.axis.key, value, &kept);
      const bool found = std::any_of(kept["cameras"].begin(), kept["cameras"].end(),
                                     [&](const nlohmann::json& c) { return c.value("name", "") == camera; });
      if (!found) a["camera"].Fail("camera '" + camera + "' is left out by rig.cameras " + value.dump());
    }
  }
}

uint64_t Mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// A uniform number in [0, 1) from (seed, index, axis, which): the same point
// whoever draws it, in any order.
double Uniform(uint64_t seed, int index, size_t axis, int which) {
  const uint64_t h = Mix(Mix(Mix(Mix(seed) ^ uint64_t(index)) ^ uint64_t(axis)) ^ uint64_t(which));
  return double(h >> 11) * (1.0 / 9007199254740992.0);
}

void ReadSearch(const JsonNode& search, SweepSpec* spec) {
  search.CheckKeys({"method", "population", "generations", "elite"});
  if (search.GetString("method", "cross_entropy") != "cross_entropy") search["method"].Fail("expected \"cross_entropy\"");
  spec->population = search.GetInt("population");
  if (spec->population < 2 || spec->population > 10000) search["population"].Fail("must be in 2..10000");
  spec->generations = search.GetInt("generations");
  if (spec->generations < 1 || spec->generations > 1000) search["generations"].Fail("must be in 1..1000");
  spec->elite = search.GetInt("elite", std::max(1, spec->population / 4));
  if (spec->elite < 1 || spec->elite > spec->population) search["elite"].Fail("must be in 1..population");
}

// A standard normal number from (seed, index, dim) (Box-Muller).
double Normal(uint64_t seed, int index, size_t dim) {
  const double u1 = std::max(Uniform(seed, index, dim, 2), 1e-300), u2 = Uniform(seed, index, dim, 3);
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * M_PI * u2);
}

// The cross-entropy method's sampling distribution, per unit coordinate
// (each placement: along 0..1, height 0..1 from `from` to `to`, and with aim
// ranges pan and tilt 0..1 likewise; each pose dimension 0..1 over its range).
struct Gaussian {
  std::vector<double> mean, sigma;
  // Point `index`'s unit coordinates: the mean itself, or drawn and clipped.
  std::vector<double> Draw(uint64_t seed, int index, bool at_mean) const {
    std::vector<double> x = mean;
    if (at_mean) return x;
    for (size_t d = 0; d < x.size(); ++d) x[d] = std::clamp(mean[d] + sigma[d] * Normal(seed, index, d), 0.0, 1.0);
    return x;
  }
};

// Point `index`'s unit coordinates in a search: the generations before it
// replayed, each drawn from the distribution that the elite of all points
// before it gives: their mean, their spread but shrinking to no less than
// 0.6 of the previous generation's (the elite of a small population would
// otherwise collapse it before the mean arrives), at least 0.02.
std::vector<double> SearchUnit(const SweepSpec& spec, int index, const PointMetric& metric_of) {
  size_t dims = 0;
  for (const SweepAxis& axis : spec.axes) {
    const auto* pose = std::get_if<PoseAxis>(&axis.axis);
    const auto* placed = std::get_if<PlacementAxis>(&axis.axis);
    dims += pose ? pose->dims.size() : placed && placed->aims ? 4 : 2;
  }
  const int generation = index / spec.population;
  const double sign = SeeksHigh(spec) ? -1 : 1;  // smaller is better below
  Gaussian dist{std::vector<double>(dims, 0.5), std::vector<double>(dims, 0.4)};
  std::vector<std::pair<double, std::vector<double>>> done;  // (signed metric, unit coordinates)
  for (int g = 0; g <= generation; ++g) {
    if (g > 0) {
      std::stable_sort(done.begin(), done.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      const size_t n = std::min<size_t>(spec.elite, done.size());
      for (size_t d = 0; d < dims; ++d) {
        double mean = 0, var = 0;
        for (size_t e = 0; e < n; ++e) mean += done[e].second[d] / n;
        for (size_t e = 0; e < n; ++e) var += (done[e].second[d] - mean) * (done[e].second[d] - mean) / n;
        dist.mean[d] = mean;
        dist.sigma[d] = std::max({std::sqrt(var), 0.6 * dist.sigma[d], 0.02});
      }
    }
    if (g == generation) return dist.Draw(spec.seed, index, g > 0 && index % spec.population == 0);
    for (int i = g * spec.population; i < (g + 1) * spec.population; ++i) {
      const std::optional<double> m = metric_of ? metric_of(i) : std::nullopt;
      if (!m) {
        throw RuntimeError("sweep " + spec.name + ": " + PointName(index) + " (generation " +
                           std::to_string(generation) + ") needs " + PointName(i) + " done first");
      }
      done.emplace_back(sign * *m, dist.Draw(spec.seed, i, g > 0 && i % spec.population == 0));
    }
  }
  return {};
}

size_t AxisSize(const SweepAxis& axis) {
  if (const auto* p = std::get_if<PlacementAxis>(&axis.axis)) {
    return size_t(p->steps) * p->height.steps * p->pan.steps * p->tilt.steps;
  }
  if (const auto* pose = std::get_if<PoseAxis>(&axis.axis)) {
    size_t n = 1;
    for (const PoseDim& d : pose->dims) n *= size_t(d.range.steps);
    return n;
  }
  return std::get<ValueAxis>(axis.axis).values.size();
}

}  // namespace

Eigen::Vector3d AimedLookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& look_at,
                            const Eigen::Vector3d& up, double pan_deg, double tilt_deg) {
  if (pan_deg == 0 && tilt_deg == 0) return look_at;
  const Eigen::Vector3d to = look_at - position;
  const double distance = to.norm();
  const Eigen::Vector3d u = up.normalized();
  // Pan about the up; then tilt about the right (view x up), which turns the
  // view towards the up.
  Eigen::Vector3d view = Eigen::AngleAxisd(pan_deg * M_PI / 180, u) * (to / distance);
  const Eigen::Vector3d right = view.cross(u);
  if (right.norm() > 1e-12) view = Eigen::AngleAxisd(tilt_deg * M_PI / 180, right.normalized()) * view;
  return position + distance * view;
}

std::string PointName(int index) {
  char buf[24];
  std::snprintf(buf, sizeof(buf), "p%04d", index);
  return buf;
}

SweepSpec LoadSweepSpec(const fs::path& file) {
  const JsonNode root = ParseJsonFile(file.string());
  root.CheckKeys({"format", "name", "description", "base", "axes", "mode", "samples", "seed", "search", "metric"});
  if (root.GetString("format") != "irbench.sweep/1") root["format"].Fail("expected \"irbench.sweep/1\"");
  SweepSpec spec;
  spec.file = file;
  spec.name = root.GetString("name");
  if (const std::string problem = CameraNameProblem(spec.name); !problem.empty()) root["name"].Fail(problem);
  spec.description = root.GetString("description", "");
  const JsonNode base = root["base"];
  base.CheckKeys(ScenarioKeys());
  if (base.Has("optional")) base["optional"].Fail("a sweep's base is not optional");
  spec.base = base.raw();
  const Scenario base_scenario = ScenarioOf(spec.base, file);  // checks the base's keys
  spec.inputs = ScenarioInputFiles(base_scenario.render);       // and its files
  spec.mode = root.GetString("mode", "grid");
  if (spec.mode != "grid" && spec.mode != "random" && spec.mode != "search" && spec.mode != "adversarial") {
    root["mode"].Fail("expected \"grid\", \"random\", \"search\" or \"adversarial\"");
  }
  const bool searches = spec.mode == "search" || spec.mode == "adversarial";
  spec.seed = static_cast<uint64_t>(root.GetInt("seed", 1));
  if (spec.mode == "random") {
    spec.samples = root.GetInt("samples");
    if (spec.samples < 1 || spec.samples > kMaxPoints) root["samples"].Fail("must be in 1..1000000");
  } else if (root.Has("samples")) {
    root["samples"].Fail("only for mode \"random\"");
  }
  if (searches) {
    ReadSearch(root["search"], &spec);
  } else if (root.Has("search")) {
    root["search"].Fail("only for modes \"search\" and \"adversarial\"");
  }
  spec.metric = root.GetString("metric", "arms_mean_cm");
  const auto& metrics = KnownMetrics();
  if (std::find(metrics.begin(), metrics.end(), spec.metric) == metrics.end()) {
    root["metric"].Fail("unknown metric (" + KnownMetricsText() + ")");
  }
  const JsonNode axes = root["axes"];
  if (axes.Size() == 0) axes.Fail("no axes");
  std::set<std::string> names;
  std::vector<nlohmann::json> rigs = {spec.base.value("rig", std::string("theater4"))};
  std::vector<RigAxisAt> rig_axes;
  // Value axes first: a placement is checked against every rig a point may have.
  for (size_t i = 0; i < axes.Size(); ++i) {
    const JsonNode a = axes[i];
    if (a.Has("camera") || a.Has("pose")) continue;
    if (searches) a.Fail("a search moves cameras and poses only: give other values in the base");
    a.CheckKeys({"key", "values"});
    ValueAxis v;
    v.key = a.GetString("key");
    const bool track_key = v.key.rfind("track.", 0) == 0 && v.key.size() > 6;
    if (!track_key && !IsRigAxisKey(v.key) && std::find(ValueKeys().begin(), ValueKeys().end(), v.key) == ValueKeys().end()) {
      a["key"].Fail("not a key a sweep can vary (scene, rig, avatar, motion, sensor, seed, frames, "
                    "background_frames, track.<setting>, rig.cameras, rig.resolution, rig.focal_scale, rig.dist, "
                    "sensor.<group>.<knob>)");
    }
    if (!names.insert(v.key).second) a["key"].Fail("'" + v.key + "' is swept twice");
    const JsonNode values = a["values"];
    if (values.Size() == 0) values.Fail("an empty list");
    for (size_t j = 0; j < values.Size(); ++j) {
      v.values.push_back(values[j].raw());
      if (IsRigAxisKey(v.key)) continue;  // checked against every rig below
      try {
        for (const fs::path& f : ScenarioInputFiles(ScenarioOf(WithValue(spec.base, v.key, values[j].raw()), file).render)) {
          spec.inputs.push_back(f);
        }
      } catch (const InputError& e) {
        values[j].Fail(e.message());
      }
    }
    if (v.key == "rig") rigs = v.values;
    if (IsRigAxisKey(v.key)) rig_axes.push_back({a, v});
    spec.axes.push_back({v.key, v});
  }
  CheckRigAxes(spec, rig_axes, rigs);
  std::vector<SweepAxis> placements;
  for (size_t i = 0; i < axes.Size(); ++i) {
    const JsonNode a = axes[i];
    if (a.Has("pose")) {
      const std::string name = a.GetString("pose");
      if (const std::string problem = CameraNameProblem(name); !problem.empty()) a["pose"].Fail(problem);
      if (!names.insert(name).second) a["pose"].Fail("'" + name + "' is swept twice");
      if (names.count("motion")) a["pose"].Fail("a pose is the point's motion: the spec also sweeps `motion`");
      placements.push_back({name, ReadPoseAxis(a, spec.mode == "grid")});
      continue;
    }
    if (!a.Has("camera")) continue;
    PlacementAxis p = ReadPlacement(a, spec.mode == "grid");
    if (!names.insert(p.camera).second) a["camera"].Fail("camera '" + p.camera + "' is placed twice");
    for (const nlohmann::json& rig : rigs) {
      const RigPlace place = PlaceOf(ScenarioOf(WithValue(spec.base, "rig", rig), file));
      CheckPlacement(a, p, place);
      CheckPlacedCameraKept(rig_axes, a, p.camera, place.rig);
    }
    placements.push_back({p.camera, p});
  }
  // Placements first in the point order, as written.
  spec.axes.insert(spec.axes.begin(), placements.begin(), placements.end());
  double count = spec.mode == "random" ? spec.samples : 1;
  if (spec.mode == "grid") {
    for (const SweepAxis& axis : spec.axes) count *= double(AxisSize(axis));
  }
  if (searches) count = double(spec.population) * spec.generations;
  if (count > kMaxPoints) axes.Fail("a grid of " + std::to_string(count) + " points (at most 1000000)");
  spec.canonical = root.raw().dump(2) + "\n";
  return spec;
}

int PointCount(const SweepSpec& spec) {
  if (spec.mode == "random") return spec.samples;
  if (spec.mode == "search" || spec.mode == "adversarial") return spec.population * spec.generations;
  size_t count = 1;
  for (const SweepAxis& axis : spec.axes) count *= AxisSize(axis);
  return static_cast<int>(count);
}

int GenerationOf(const SweepSpec& spec, int index) {
  return spec.population > 0 ? index / spec.population : 0;
}

int GenerationCount(const SweepSpec& spec) { return spec.population > 0 ? spec.generations : 1; }

bool SeeksHigh(const SweepSpec& spec) { return HigherIsBetter(spec.metric) != (spec.mode == "adversarial"); }

SweepPoint PointAt(const SweepSpec& spec, int index, const PointMetric& metric_of) {
  if (index < 0 || index >= PointCount(spec)) {
    throw InputError(spec.file.string(), "INDEX",
                     "point " + std::to_string(index) + " of 0.." + std::to_string(PointCount(spec) - 1));
  }
  SweepPoint point;
  point.index = index;
  point.at.resize(spec.axes.size());
  if (spec.population > 0) {
    const std::vector<double> unit = SearchUnit(spec, index, metric_of);
    size_t u = 0;
    for (size_t k = 0; k < spec.axes.size(); ++k) {
      AxisValue& at = point.at[k];
      if (const auto* pose = std::get_if<PoseAxis>(&spec.axes[k].axis)) {
        for (const PoseDim& d : pose->dims) at.pose.push_back(d.range.from + (d.range.to - d.range.from) * unit[u++]);
        continue;
      }
      const auto& p = std::get<PlacementAxis>(spec.axes[k].axis);
      at.along = unit[u++];
      at.height = p.height.from + (p.height.to - p.height.from) * unit[u++];
      if (p.aims) {
        at.pan = p.pan.from + (p.pan.to - p.pan.from) * unit[u++];
        at.tilt = p.tilt.from + (p.tilt.to - p.tilt.from) * unit[u++];
      }
      at.position = PlacementPosition(p, at.along, at.height);
    }
    return point;
  }
  size_t rest = static_cast<size_t>(index);
  for (size_t k = spec.axes.size(); k-- > 0;) {
    const SweepAxis& axis = spec.axes[k];
    AxisValue& at = point.at[k];
    size_t cell = 0;
    const bool grid = spec.mode == "grid";
    if (grid) {
      cell = rest % AxisSize(axis);
      rest /= AxisSize(axis);
    }
    if (const auto* pose = std::get_if<PoseAxis>(&axis.axis)) {
      // Grid: the cell's steps, the last dim fastest; random: anywhere.
      at.pose.resize(pose->dims.size());
      for (size_t d = pose->dims.size(); d-- > 0;) {
        const SweepRange& r = pose->dims[d].range;
        if (grid) {
          at.pose[d] = r.At(static_cast<int>(cell % r.steps));
          cell /= r.steps;
        } else {
          at.pose[d] = r.from + (r.to - r.from) * Uniform(spec.seed, index, k, static_cast<int>(d));
        }
      }
    } else if (const auto* p = std::get_if<PlacementAxis>(&axis.axis)) {
      if (grid) {
        // Along fastest, then height, pan, tilt.
        at.along_step = static_cast<int>(cell % p->steps);
        cell /= p->steps;
        at.height_step = static_cast<int>(cell % p->height.steps);
        cell /= p->height.steps;
        at.along = p->steps <= 1 ? 0.0 : double(at.along_step) / (p->steps - 1);
        at.height = p->height.At(at.height_step);
        at.pan = p->pan.At(static_cast<int>(cell % p->pan.steps));
        at.tilt = p->tilt.At(static_cast<int>(cell / p->pan.steps));
      } else {
        at.along = Uniform(spec.seed, index, k, 0);
        at.height = p->height.from + (p->height.to - p->height.from) * Uniform(spec.seed, index, k, 1);
        if (p->aims) {
          at.pan = p->pan.from + (p->pan.to - p->pan.from) * Uniform(spec.seed, index, k, 2);
          at.tilt = p->tilt.from + (p->tilt.to - p->tilt.from) * Uniform(spec.seed, index, k, 3);
        }
      }
      at.position = PlacementPosition(*p, at.along, at.height);
    } else {
      const ValueAxis& v = std::get<ValueAxis>(axis.axis);
      if (!grid) cell = std::min(v.values.size() - 1, size_t(Uniform(spec.seed, index, k, 0) * v.values.size()));
      at.value = v.values[cell];
    }
  }
  return point;
}

nlohmann::json PointCoordinates(const SweepSpec& spec, const SweepPoint& point) {
  nlohmann::json out = nlohmann::json::object();
  for (size_t k = 0; k < spec.axes.size(); ++k) {
    const SweepAxis& axis = spec.axes[k];
    const AxisValue& at = point.at[k];
    if (const auto* pose = std::get_if<PoseAxis>(&axis.axis)) {
      for (size_t d = 0; d < pose->dims.size(); ++d) {
        out[axis.name + "." + pose->dims[d].Label()] = at.pose[d];
      }
    } else if (const auto* p = std::get_if<PlacementAxis>(&axis.axis)) {
      out[axis.name + ".along"] = at.along;
      out[axis.name + ".height"] = at.height;
      out[axis.name + ".position"] = {at.position.x(), at.position.y(), at.position.z()};
      if (p->aims) {
        out[axis.name + ".pan"] = at.pan;
        out[axis.name + ".tilt"] = at.tilt;
      }
    } else {
      out[axis.name] = at.value;
    }
  }
  return out;
}

Scenario PointScenario(const SweepSpec& spec, const SweepPoint& point, const fs::path& out) {
  const fs::path rigs = out / "rigs";
  nlohmann::json keys = spec.base;
  bool moved = false;
  for (size_t k = 0; k < spec.axes.size(); ++k) {
    if (const auto* v = std::get_if<ValueAxis>(&spec.axes[k].axis)) {
      if (IsRigAxisKey(v->key)) {
        moved = true;
      } else {
        keys = WithValue(keys, v->key, point.at[k].value);
      }
    }
    moved |= std::holds_alternative<PlacementAxis>(spec.axes[k].axis);
    if (const auto* pose = std::get_if<PoseAxis>(&spec.axes[k].axis)) {
      const fs::path file = fs::absolute(out / "motions" / (PointName(point.index) + ".json"));
      nlohmann::json held = nlohmann::json::object();
      for (size_t d = 0; d < pose->dims.size(); ++d) {
        held[pose->dims[d].Label()] = point.at[k].pose[d];
      }
      WritePoseMotion(*pose, point.at[k].pose, spec.name + "-" + PointName(point.index),
                      "Sweep " + spec.name + " point " + std::to_string(point.index) + ", pose " + spec.axes[k].name +
                          (pose->atoms ? " (atoms' weights, docs/motion.md): " : " (degrees, docs/formats.md): ") + held.dump(),
                      file);
      keys["motion"] = file.string();
    }
  }
  if (moved) {
    // The point's rig: the base rig's file with the placed cameras moved.
    const Scenario unmoved = ScenarioOf(keys, spec.file);
    const RenderInputs unmoved_inputs = LoadRenderInputs(unmoved.render);
    const fs::path& rig_file = unmoved_inputs.rig_file;
    std::ifstream in(rig_file);
    nlohmann::json rig = nlohmann::json::parse(in);
    rig["name"] = rig.value("name", rig_file.stem().string()) + "-" + spec.name + "-" + PointName(point.index);
    rig["description"] = "Sweep " + spec.name + " point " + std::to_string(point.index) + " of " +
                         rig_file.filename().string() + ": " + PointCoordinates(spec, point).dump();
    for (size_t k = 0; k < spec.axes.size(); ++k) {
      const auto* p = std::get_if<PlacementAxis>(&spec.axes[k].axis);
      if (!p) continue;
      for (nlohmann::json& camera : rig["cameras"]) {
        if (camera.value("name", "") != p->camera) continue;
        const Eigen::Vector3d& at = point.at[k].position;
        const Eigen::Vector3d look_at =
            AimedLookAt(at, p->look_at, PlacedUp(*p, unmoved_inputs.rig), point.at[k].pan, point.at[k].tilt);
        camera["position"] = {at.x(), at.y(), at.z()};
        camera["look_at"] = {look_at.x(), look_at.y(), look_at.z()};
        if (p->has_up) camera["up"] = {p->up.x(), p->up.y(), p->up.z()};
      }
    }
    // Then the rig axes, in RigAxisKeys()'s order, then the sensor knobs.
    for (const std::string& key : RigAxisKeys()) {
      for (size_t k = 0; k < spec.axes.size(); ++k) {
        const auto* v = std::get_if<ValueAxis>(&spec.axes[k].axis);
        if (v && v->key == key) ApplyRigAxis(key, point.at[k].value, &rig);
      }
    }
    for (size_t k = 0; k < spec.axes.size(); ++k) {
      const auto* v = std::get_if<ValueAxis>(&spec.axes[k].axis);
      if (v && IsSensorKnobKey(v->key)) ApplyRigAxis(v->key, point.at[k].value, &rig);
    }
    fs::create_directories(rigs);
    const fs::path file = fs::absolute(rigs / (PointName(point.index) + ".json"));
    AtomicWriteFile(file, rig.dump(2) + "\n");
    keys["rig"] = file.string();
  }
  Scenario sc = ScenarioOf(keys, spec.file);
  sc.name = spec.name + "-" + PointName(point.index);
  return sc;
}

}  // namespace irbench
