#include "tracker/posture/posture_atoms.h"

#include <cmath>
#include <cstdio>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/paths.h"

namespace irbench {
namespace {

// Seven significant digits (about a float's precision), printed short.
double Round7(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.7g", v);
  return std::strtod(buf, nullptr);
}

// A descriptor-sized vector as its non-zero bins.
nlohmann::json SparseJson(const std::vector<float>& v) {
  nlohmann::json index = nlohmann::json::array(), value = nlohmann::json::array();
  for (size_t i = 0; i < v.size(); ++i) {
    if (v[i] == 0.0f) continue;
    index.push_back(i);
    value.push_back(Round7(v[i]));
  }
  return {{"bins", v.size()}, {"index", index}, {"value", value}};
}

std::vector<float> SparseFrom(const JsonNode& node, int bins) {
  node.CheckKeys({"bins", "index", "value"});
  if (node.GetInt("bins") != bins) {
    node["bins"].Fail("has " + std::to_string(node.GetInt("bins")) + " bins; the descriptor has " +
                      std::to_string(bins));
  }
  const JsonNode index = node["index"], value = node["value"];
  if (index.Size() != value.Size()) node["value"].Fail("must have as many entries as index");
  std::vector<float> v(bins, 0.0f);
  for (size_t i = 0; i < index.Size(); ++i) {
    const int k = index[i].Int();
    if (k < 0 || k >= bins) index[i].Fail("bin outside 0.." + std::to_string(bins - 1));
    const double x = value[i].Number();
    if (!std::isfinite(x)) value[i].Fail("must be finite");
    v[k] = static_cast<float>(x);
  }
  return v;
}

}  // namespace

const char* AtomWeightsName(AtomWeights w) {
  return w == AtomWeights::kMatchingPursuit ? "matching_pursuit" : "non_negative";
}

const char* PairRuleName(PairRule r) { return r == PairRule::kThresholds ? "thresholds" : "centroids"; }

void PostureAtoms::Check(const std::string& file) const {
  const size_t bins = static_cast<size_t>(descriptor.bin_count());
  if (names.size() < 2) throw InputError(file, "names", "needs the rest posture and at least one arm atom");
  if (rest.size() != bins) throw InputError(file, "rest", "must have the descriptor's bin count");
  if (arms.size() + 1 != names.size()) throw InputError(file, "arms", "needs one arm part per atom after the first");
  for (size_t k = 0; k < arms.size(); ++k) {
    if (arms[k].size() != bins) {
      throw InputError(file, "arms[" + std::to_string(k) + "]", "must have the descriptor's bin count");
    }
  }
  if (iterations < 1 || iterations > 16) throw InputError(file, "iterations", "must be in 1..16");
  if (!(overlap_threshold >= 0)) throw InputError(file, "overlap_threshold", "must be >= 0");
  if (!(presence > 0) || !(instance > presence)) {
    throw InputError(file, "instance", "must be above presence, and presence above 0");
  }
  if (rule == PairRule::kCentroids && centroids.empty()) throw InputError(file, "centroids", "needs at least one pair");
  if (!centroid_precision.empty() && centroid_precision.size() != arms.size() * arms.size()) {
    throw InputError(file, "centroid_precision", "needs K x K values for the K arm atoms");
  }
  for (size_t c = 0; c < centroids.size(); ++c) {
    if (centroids[c].second.size() != arms.size()) {
      throw InputError(file, "centroids[" + std::to_string(c) + "]", "needs one weight per arm atom");
    }
  }
}

PostureAtoms PostureAtoms::Load(const std::filesystem::path& path) {
  const JsonNode root = ParseJsonFile(path.string());
  root.CheckKeys({"format", "descriptor", "names", "rest", "arms", "weights", "iterations", "overlap_threshold", "rule",
                  "presence", "instance", "centroids", "centroid_precision", "pair_rest_state", "provenance"});
  if (root.GetString("format") != kFormat) {
    root["format"].Fail("must be " + std::string(kFormat) + " (got " + root.GetString("format") + ")");
  }
  PostureAtoms a;
  const JsonNode d = root["descriptor"];
  d.CheckKeys({"rings", "azimuths", "r_bins", "theta_bins", "phi_bins", "radius_per_height", "max_points",
               "smoothing_bins"});
  a.descriptor.rings = d.GetInt("rings");
  a.descriptor.azimuths = d.GetInt("azimuths");
  a.descriptor.r_bins = d.GetInt("r_bins");
  a.descriptor.theta_bins = d.GetInt("theta_bins");
  a.descriptor.phi_bins = d.GetInt("phi_bins");
  a.descriptor.radius_per_height = d.GetDouble("radius_per_height");
  a.descriptor.max_points = d.GetInt("max_points");
  a.descriptor.smoothing_bins = d.GetDouble("smoothing_bins");
  try {
    a.descriptor.Check();
  } catch (const InputError& e) {
    throw InputError(path.string(), "descriptor." + e.field(), e.message());
  }
  const int bins = a.descriptor.bin_count();
  for (size_t i = 0; i < root["names"].Size(); ++i) a.names.push_back(root["names"][i].String());
  a.rest = SparseFrom(root["rest"], bins);
  for (size_t k = 0; k < root["arms"].Size(); ++k) a.arms.push_back(SparseFrom(root["arms"][k], bins));
  const std::string weights = root.GetString("weights");
  if (weights == "matching_pursuit") {
    a.weights = AtomWeights::kMatchingPursuit;
  } else if (weights == "non_negative") {
    a.weights = AtomWeights::kNonNegative;
  } else {
    root["weights"].Fail("must be matching_pursuit or non_negative");
  }
  a.iterations = root.GetInt("iterations");
  a.overlap_threshold = root.GetDouble("overlap_threshold");
  const std::string rule = root.GetString("rule");
  if (rule == "thresholds") {
    a.rule = PairRule::kThresholds;
  } else if (rule == "centroids") {
    a.rule = PairRule::kCentroids;
  } else {
    root["rule"].Fail("must be thresholds or centroids");
  }
  a.presence = root.GetDouble("presence");
  a.instance = root.GetDouble("instance");
  const JsonNode centroids = root["centroids"];
  for (const std::string& pair : centroids.Keys()) a.centroids.emplace_back(pair, centroids[pair].Numbers());
  if (root.Has("centroid_precision")) a.centroid_precision = root["centroid_precision"].Numbers();
  a.pair_rest_state = root.GetBool("pair_rest_state", false);
  a.provenance = root.Has("provenance") ? root["provenance"].raw() : nlohmann::json::object();
  a.Check(path.string());
  return a;
}

void PostureAtoms::Save(const std::filesystem::path& path) const {
  Check(path.string());
  nlohmann::json j = nlohmann::json::object();
  j["format"] = kFormat;
  j["provenance"] = provenance;
  j["descriptor"] = {{"rings", descriptor.rings},
                     {"azimuths", descriptor.azimuths},
                     {"r_bins", descriptor.r_bins},
                     {"theta_bins", descriptor.theta_bins},
                     {"phi_bins", descriptor.phi_bins},
                     {"radius_per_height", descriptor.radius_per_height},
                     {"max_points", descriptor.max_points},
                     {"smoothing_bins", descriptor.smoothing_bins}};
  j["names"] = names;
  j["weights"] = AtomWeightsName(weights);
  j["iterations"] = iterations;
  j["overlap_threshold"] = overlap_threshold;
  j["rule"] = PairRuleName(rule);
  j["presence"] = presence;
  j["instance"] = instance;
  j["pair_rest_state"] = pair_rest_state;
  nlohmann::json c = nlohmann::json::object();
  for (const auto& [pair, w] : centroids) {
    nlohmann::json row = nlohmann::json::array();
    for (double x : w) row.push_back(Round7(x));
    c[pair] = row;
  }
  j["centroids"] = c;
  if (!centroid_precision.empty()) j["centroid_precision"] = centroid_precision;
  j["rest"] = SparseJson(rest);
  j["arms"] = nlohmann::json::array();
  for (const auto& arm : arms) j["arms"].push_back(SparseJson(arm));
  // One key a line, each value compact: a header a reader can scan.
  std::string text = "{\n";
  for (auto it = j.begin(); it != j.end(); ++it) {
    text += (it == j.begin() ? " " : ",\n ") + nlohmann::json(it.key()).dump() + ": " + it.value().dump();
  }
  AtomicWriteFile(path, text + "\n}\n");
}

std::filesystem::path DefaultPostureAtomsPath() { return DataRoot() / "tracker" / "models" / "posture_atoms.json"; }

}  // namespace irbench
