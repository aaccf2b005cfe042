#include "ci/suite_runner/suite.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>
#include <nlohmann/json.hpp>
#include <fstream>
#include <sstream>

#include "ci/report/report.h"
#include "ci/suite_runner/scenario.h"
#include "ci/score/score.h"
#include "ci/score/score_job.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/logging.h"
#include "common/progress.h"
#include "common/paths.h"
#include "sequence_format/manifest.h"
#include "sim/sequence/render_job.h"
#include "tracker/pipeline/track_job.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

struct Bound {
  std::string kind;  // "max" or "min"
  double value = 0;
  double tolerance = 0;  // allowed drift from the baseline, absolute
};

struct SuiteScenario : Scenario {
  std::map<std::string, Bound> thresholds;
};

fs::path FindSuiteFile(const fs::path& suite) {
  return fs::is_regular_file(suite) ? suite : ResolveDataFile("ci/suites", suite.string(), "SUITE");
}

void ReadSuiteFile(const fs::path& file, std::vector<fs::path>* chain, std::vector<SuiteScenario>* out);

// `include`: the scenarios of other suites (names in ci/suites/ or files
// relative to this one), in order, before this suite's own.
void ReadIncludes(const JsonNode& list, const fs::path& file, std::vector<fs::path>* chain,
                  std::vector<SuiteScenario>* out) {
  for (size_t i = 0; i < list.Size(); ++i) {
    const std::string name = list[i].String();
    fs::path other = name;
    if (other.has_extension() || name.find('/') != std::string::npos) {
      other = file.parent_path() / other;
      if (!fs::is_regular_file(other)) list[i].Fail("no such suite file '" + other.string() + "'");
    } else {
      other = file.parent_path() / (name + ".json");
      if (!fs::is_regular_file(other)) other = FindSuiteFile(name);
    }
    for (const fs::path& seen : *chain) {
      if (fs::weakly_canonical(seen) == fs::weakly_canonical(other)) {
        list[i].Fail("includes '" + other.string() + "' again (a cycle)");
      }
    }
    ReadSuiteFile(other, chain, out);
  }
}

void ReadSuiteFile(const fs::path& file, std::vector<fs::path>* chain, std::vector<SuiteScenario>* out) {
  chain->push_back(file);
  const JsonNode root = ParseJsonFile(file.string());
  root.CheckKeys({"format", "name", "description", "include", "scenarios"});
  if (root.GetString("format") != "irbench.suite/1") root["format"].Fail("expected \"irbench.suite/1\"");
  if (root.Has("include")) ReadIncludes(root["include"], file, chain, out);
  const JsonNode list = root["scenarios"];
  if (list.Size() == 0 && !root.Has("include")) list.Fail("no scenarios");
  for (size_t i = 0; i < list.Size(); ++i) {
    const JsonNode s = list[i];
    std::vector<std::string> keys = ScenarioKeys();
    keys.insert(keys.end(), {"name", "thresholds"});
    s.CheckKeys(keys);
    SuiteScenario sc;
    sc.name = s.GetString("name");
    for (const SuiteScenario& other : *out) {
      if (other.name == sc.name) s["name"].Fail("'" + sc.name + "' appears twice (also in " + other.file + ")");
    }
    ReadScenarioKeys(s, file, &sc);
    const JsonNode th = s["thresholds"];
    for (const auto& [metric, value] : th.raw().items()) {
      if (std::find(KnownMetrics().begin(), KnownMetrics().end(), metric) == KnownMetrics().end()) {
        th[metric].Fail("unknown metric (" + KnownMetricsText() + ")");
      }
      const JsonNode b = th[metric];
      b.CheckKeys({"max", "min", "tolerance"});
      Bound bound;
      if (b.Has("max") == b.Has("min")) b.Fail("give exactly one of max or min");
      bound.kind = b.Has("max") ? "max" : "min";
      bound.value = b.GetDouble(bound.kind);
      bound.tolerance = b.GetDouble("tolerance", 0.0);
      if (bound.tolerance < 0) b["tolerance"].Fail("must be >= 0");
      sc.thresholds[metric] = bound;
    }
    out->push_back(sc);
  }
  chain->pop_back();
}

std::vector<SuiteScenario> ReadSuite(const fs::path& file, std::string* name) {
  *name = ParseJsonFile(file.string()).GetString("name", file.stem().string());
  std::vector<fs::path> chain;
  std::vector<SuiteScenario> out;
  ReadSuiteFile(file, &chain, &out);
  return out;
}

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.4g", v);
  return buf;
}

// The scenarios' figures pooled per group and person: each metric the mean
// over every sample of the scenarios in the row (a scenario's mean weighted
// by its sample count); arms the mean of the six pooled arm joints.
std::vector<PooledRow> Pool(const std::vector<Measured>& measured) {
  std::map<std::pair<std::string, std::string>, std::vector<const Measured*>> rows;
  for (const Measured& m : measured) {
    rows[{m.group, m.person}].push_back(&m);
    rows[{m.group, "all"}].push_back(&m);
  }
  std::vector<PooledRow> out;
  for (const auto& [key, members] : rows) {
    PooledRow row;
    row.group = key.first;
    row.person = key.second;
    row.scenarios = static_cast<int>(members.size());
    std::map<std::string, std::pair<double, double>> sums;  // metric -> (sum of value x weight, weight)
    for (const Measured* m : members) {
      for (const auto& [metric, w] : m->weights) {
        sums[metric].first += m->metrics.at(metric) * w;
        sums[metric].second += w;
      }
    }
    for (const auto& [metric, sw] : sums) {
      if (sw.second > 0) row.metrics[metric] = sw.first / sw.second;
    }
    double arms = 0;
    int arm_joints = 0;
    for (const char* side : {"left_", "right_"}) {
      for (const char* joint : {"shoulder", "elbow", "wrist"}) {
        const auto it = row.metrics.find(std::string(side) + joint + "_mean_cm");
        if (it == row.metrics.end()) continue;
        arms += it->second;
        ++arm_joints;
      }
    }
    if (arm_joints) row.metrics["arms_mean_cm"] = arms / arm_joints;
    row.frames = sums.count("tracked_fraction") ? static_cast<int>(sums["tracked_fraction"].second) : 0;
    out.push_back(row);
  }
  // "all" last within each group.
  std::stable_sort(out.begin(), out.end(), [](const PooledRow& a, const PooledRow& b) {
    return a.group != b.group ? a.group < b.group : (a.person == "all") < (b.person == "all");
  });
  return out;
}

}  // namespace

std::string SuiteResult::Table() const {
  std::ostringstream out;
  out << "| scenario | metric | value | threshold | baseline | result |\n|---|---|---|---|---|---|\n";
  for (const MetricResult& r : rows) {
    out << "| " << r.scenario << " | " << r.metric << " | " << Number(r.value) << " | " << r.bound << " | "
        << r.baseline << " | " << (r.pass ? "pass" : "**FAIL**: " + r.why) << " |\n";
  }
  return out.str();
}

namespace {

// <dir>/summary.md and <dir>/report.html: the scenarios' table, the pooled
// table, and each scenario's own report.html linked.
void WriteSummary(SuiteResult& result, const fs::path& dir) {
  fs::create_directories(dir);
  std::ostringstream md, html;
  md << "# suite " << result.name << "\n\n" << result.Table() << "\n## pooled\n\n" << result.PooledTable();
  html << "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>suite " << HtmlEscape(result.name)
       << "</title><style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse;margin:1em 0}"
          "td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}th{background:#eee}</style></head><body>\n"
       << "<h1>suite " << HtmlEscape(result.name) << (result.pass ? "" : " — <b>FAILED</b>") << "</h1>\n"
       << "<h2>Pooled <small>(cm; the mean over all samples of the scenarios in a row; arms: the six arm "
          "joints)</small></h2>\n"
       << MarkdownTableHtml(result.PooledTable()) << "<h2>Scenarios</h2>\n" << MarkdownTableHtml(result.Table())
       << "<h2>Each scenario's report</h2>\n<ul>\n";
  for (const auto& [scenario, report] : result.reports) {
    const std::string link = fs::relative(report, dir).generic_string();
    html << "<li><a href=\"" << HtmlEscape(link) << "\">" << HtmlEscape(scenario) << "</a></li>\n";
  }
  html << "</ul>\n";
  if (!result.skipped.empty()) {
    md << "\n## skipped (optional, data absent)\n\n";
    html << "<h2>Skipped <small>(optional, data absent)</small></h2>\n<ul>\n";
    for (const auto& [scenario, why] : result.skipped) {
      md << "- " << scenario << ": " << why << "\n";
      html << "<li>" << HtmlEscape(scenario) << ": " << HtmlEscape(why) << "</li>\n";
    }
    html << "</ul>\n";
  }
  html << "</body></html>\n";
  AtomicWriteFile(dir / "summary.md", md.str());
  AtomicWriteFile(dir / "report.html", html.str());
  result.summary = dir;
}

}  // namespace

std::string SuiteResult::PooledTable() const {
  std::ostringstream out;
  out << "| motion | person | scenarios | present frames | root | waist | neck | shoulders | elbows | wrists | arms | "
         "rest | tracked | postures | gestures | motion labels |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  const auto cm = [](const PooledRow& r, const std::string& m) {
    const auto it = r.metrics.find(m);
    return it == r.metrics.end() ? std::string("–") : Fixed(it->second, 2);
  };
  const auto pair = [&](const PooledRow& r, const std::string& joint) {
    const auto l = r.metrics.find("left_" + joint + "_mean_cm"), rr = r.metrics.find("right_" + joint + "_mean_cm");
    if (l == r.metrics.end() || rr == r.metrics.end()) return std::string("–");
    return Fixed((l->second + rr->second) / 2, 2);
  };
  const auto pct = [](const PooledRow& r, const std::string& m) {
    const auto it = r.metrics.find(m);
    return it == r.metrics.end() ? std::string("–") : Fixed(100 * it->second, 1) + " %";
  };
  for (const PooledRow& r : pooled) {
    out << "| " << r.group << " | " << r.person << " | " << r.scenarios << " | " << r.frames << " | "
        << cm(r, "root_mean_cm") << " | " << cm(r, "waist_mean_cm") << " | " << cm(r, "neck_mean_cm") << " | "
        << pair(r, "shoulder") << " | " << pair(r, "elbow") << " | " << pair(r, "wrist") << " | "
        << cm(r, "arms_mean_cm") << " | " << pct(r, "rest_accuracy") << " | " << pct(r, "tracked_fraction") << " | "
        << pct(r, "posture_accuracy") << " | " << pct(r, "gesture_identification") << " | "
        << pct(r, "motion_mean_recall") << " |\n";
  }
  return out.str();
}

SuiteResult RunSuite(const SuiteRunOptions& options) {
  const fs::path file = FindSuiteFile(options.suite);
  SuiteResult result;
  std::vector<SuiteScenario> scenarios = ReadSuite(file, &result.name);
  // Optional scenarios whose data is absent (the CMU clips beside the
  // checkout) are skipped, said once each.
  for (auto it = scenarios.begin(); it != scenarios.end();) {
    if (it->missing.empty()) {
      ++it;
      continue;
    }
    Log().warn("suite {}: {}: skipped: {}", result.name, it->name, it->missing);
    result.skipped.emplace_back(it->name, it->missing);
    it = scenarios.erase(it);
  }
  const fs::path baselines_dir = options.baselines.empty() ? DataRoot() / "ci" / "baselines" : options.baselines;
  const fs::path baseline_file = baselines_dir / (result.name + ".json");
  nlohmann::json baseline = nlohmann::json::object();
  if (fs::is_regular_file(baseline_file)) baseline = ParseJsonFile(baseline_file.string()).raw();
  const fs::path cache = options.cache.empty() ? OutputRoot() / "renders" / "cache" : options.cache;
  // The cache holds what the suite writes; it may not hold or lie in what it
  // reads (the suite file, the baselines, the scenarios' data files).
  std::vector<fs::path> inputs = {file, baselines_dir};
  for (const SuiteScenario& sc : scenarios) {
    for (const fs::path& f : ScenarioInputFiles(sc.render)) inputs.push_back(f);
  }
  CheckOutputApart(cache, inputs, "--cache");
  fs::create_directories(cache);
  // Scenarios in parallel, up to --jobs workers (default: the core count).
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const size_t workers = std::min<size_t>(scenarios.size(), options.jobs > 0 ? size_t(options.jobs) : cores);
  Log().info("suite {}: {} scenario(s), {} at a time", result.name, scenarios.size(), workers);
  std::vector<Measured> measured(scenarios.size());
  std::vector<std::exception_ptr> errors(scenarios.size());
  std::vector<fs::path> reports(scenarios.size());
  std::atomic<size_t> next{0};
  std::mutex render_mutex;
  // One progress line for the suite; the scenarios' renders and tracks run
  // on several threads and keep theirs quiet.
  const QuietProgress quiet;
  Progress progress("suite " + result.name, "scenarios", static_cast<int>(scenarios.size()));
  progress.IgnoreQuiet();
  std::mutex progress_mutex;
  int finished = 0;
  const auto work = [&] {
    for (size_t i; (i = next++) < scenarios.size();) {
      try {
        Log().debug("suite {}: scenario {}/{}: {}", result.name, i + 1, scenarios.size(), scenarios[i].name);
        measured[i] = RunScenario(scenarios[i], "suite " + result.name, cache, &render_mutex, &reports[i]);
        const std::lock_guard<std::mutex> lock(progress_mutex);
        progress.Set(++finished, "scenarios done");
      } catch (...) {
        errors[i] = std::current_exception();
        next = scenarios.size();  // start no more
      }
    }
  };
  std::vector<std::thread> pool;
  for (size_t w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }

  nlohmann::json blessed = nlohmann::json::object();
  for (size_t i = 0; i < scenarios.size(); ++i) {
    const SuiteScenario& sc = scenarios[i];
    const std::map<std::string, double>& metrics = measured[i].metrics;
    result.reports.emplace_back(sc.name, reports[i]);
    for (const auto& [metric, bound] : sc.thresholds) {
      MetricResult r;
      r.scenario = sc.name;
      r.metric = metric;
      r.bound = bound.kind + " " + Number(bound.value);
      const auto it = metrics.find(metric);
      if (it == metrics.end()) {
        r.pass = false;
        r.why = "not measured (nothing scored)";
        result.rows.push_back(r);
        continue;
      }
      r.value = it->second;
      blessed[sc.name][metric] = r.value;
      const bool higher_better = bound.kind == "min";
      if (higher_better ? r.value < bound.value : r.value > bound.value) {
        r.pass = false;
        r.why = "beyond the threshold";
      }
      if (baseline.contains(sc.name) && baseline[sc.name].contains(metric) && baseline[sc.name][metric].is_number()) {
        const double base = baseline[sc.name][metric];
        r.baseline = Number(base) + " ± " + Number(bound.tolerance);
        const bool worse = higher_better ? r.value < base - bound.tolerance : r.value > base + bound.tolerance;
        if (worse && !options.bless) {
          r.pass = false;
          r.why = r.why.empty() ? "regressed from the baseline" : r.why + "; regressed from the baseline";
        }
      } else {
        r.baseline = "none";
      }
      result.rows.push_back(r);
    }
  }
  for (const MetricResult& r : result.rows) result.pass &= r.pass;
  result.pooled = Pool(measured);
  WriteSummary(result, cache / ("suite-" + result.name));
  if (options.bless) {
    // A skipped scenario keeps its blessed figures: blessing on a machine
    // without the optional data must not drop them.
    for (const auto& [scenario, why] : result.skipped) {
      if (baseline.contains(scenario)) blessed[scenario] = baseline[scenario];
    }
    fs::create_directories(baselines_dir);
    AtomicWriteFile(baseline_file, blessed.dump(2) + "\n");
    Log().info("suite {}: baseline written to {}", result.name, baseline_file.string());
  }
  return result;
}

}  // namespace irbench
