// `irbench sweep collect`: the finished points merged into sweep.csv,
// sweep.md and report.html (sweep.h).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "ci/report/plots.h"
#include "ci/report/report.h"
#include "ci/score/score.h"
#include "ci/sweep/sweep.h"
#include "ci/sweep/sweep_plots.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/logging.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

struct Done {
  int index = 0;
  SweepPoint point;
  nlohmann::json coordinates;
  std::map<std::string, double> metrics;
  std::string report;  // relative to the cache
};

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

std::string Short(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

std::string CoordinateText(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number()) return Num(v.get<double>());
  if (v.is_array() && v.size() == 3 && v[0].is_number() && v[1].is_number() && v[2].is_number()) {
    return "(" + Short(v[0].get<double>()) + ", " + Short(v[1].get<double>()) + ", " + Short(v[2].get<double>()) + ")";
  }
  return v.dump();
}

// A pose's ranged components' names: "right_shoulder.z", "right.A2".
std::vector<std::string> PoseNames(const PoseAxis& pose) {
  std::vector<std::string> out;
  for (const PoseDim& d : pose.dims) out.push_back(d.Label());
  return out;
}

// A point's place on one axis, short.
std::string AxisText(const SweepAxis& axis, const AxisValue& at) {
  if (const auto* pose = std::get_if<PoseAxis>(&axis.axis)) {
    std::string out;
    const std::vector<std::string> names = PoseNames(*pose);
    for (size_t d = 0; d < names.size(); ++d) out += (d ? ", " : "") + names[d] + " " + Short(at.pose[d]);
    return out;
  }
  if (const auto* p = std::get_if<PlacementAxis>(&axis.axis)) {
    return CoordinateText(nlohmann::json{at.position.x(), at.position.y(), at.position.z()}) +
           (p->aims ? " pan " + Short(at.pan) + "° tilt " + Short(at.tilt) + "°" : "");
  }
  return CoordinateText(at.value);
}

// A point's place from its file's coordinates (a search point whose earlier
// generations are no longer all there cannot be drawn again).
SweepPoint FromCoordinates(const SweepSpec& spec, int index, const nlohmann::json& c) {
  SweepPoint point;
  point.index = index;
  point.at.resize(spec.axes.size());
  for (size_t k = 0; k < spec.axes.size(); ++k) {
    const std::string& name = spec.axes[k].name;
    AxisValue& at = point.at[k];
    if (const auto* pose = std::get_if<PoseAxis>(&spec.axes[k].axis)) {
      for (const std::string& dim : PoseNames(*pose)) at.pose.push_back(c.value(name + "." + dim, 0.0));
    } else if (std::holds_alternative<PlacementAxis>(spec.axes[k].axis)) {
      at.along = c.value(name + ".along", 0.0);
      at.height = c.value(name + ".height", 0.0);
      at.pan = c.value(name + ".pan", 0.0);
      at.tilt = c.value(name + ".tilt", 0.0);
      const nlohmann::json p = c.value(name + ".position", nlohmann::json::array({0, 0, 0}));
      at.position = {p[0].get<double>(), p[1].get<double>(), p[2].get<double>()};
    } else {
      at.value = c.value(name, nlohmann::json());
    }
  }
  return point;
}

std::vector<Done> ReadPoints(const SweepContext& sweep, std::vector<int>* missing) {
  std::vector<Done> out;
  const PointMetric metric_of = PointMetrics(sweep);
  for (int i = 0, n = PointCount(sweep.spec); i < n; ++i) {
    const fs::path file = PointFile(sweep, i);
    if (!fs::is_regular_file(file)) {
      missing->push_back(i);
      continue;
    }
    const JsonNode root = ParseJsonFile(file.string());
    if (root.GetString("format") != "irbench.sweep-point/1") root["format"].Fail("expected \"irbench.sweep-point/1\"");
    if (root.GetString("sweep") != sweep.spec.name) root["sweep"].Fail("a point of another sweep");
    if (root.GetInt("index") != i) root["index"].Fail("expected " + std::to_string(i));
    Done d;
    d.index = i;
    d.coordinates = root["coordinates"].raw();
    try {
      d.point = PointAt(sweep.spec, i, metric_of);
    } catch (const RuntimeError&) {
      d.point = FromCoordinates(sweep.spec, i, d.coordinates);
    }
    const JsonNode metrics = root["metrics"];
    for (const std::string& key : metrics.Keys()) d.metrics[key] = metrics[key].Number();
    d.report = root.GetString("report", "");
    out.push_back(std::move(d));
  }
  return out;
}

// Best first by the spec's metric (adversarial: the worst first); points
// without it last, by index.
void Rank(const SweepSpec& spec, std::vector<Done>* points) {
  const bool higher = SeeksHigh(spec);
  std::stable_sort(points->begin(), points->end(), [&](const Done& a, const Done& b) {
    const auto ia = a.metrics.find(spec.metric), ib = b.metrics.find(spec.metric);
    if (ia == a.metrics.end() || ib == b.metrics.end()) return ia != a.metrics.end() && ib == b.metrics.end();
    return higher ? ia->second > ib->second : ia->second < ib->second;
  });
}

std::vector<std::string> MetricColumns(const std::vector<Done>& points) {
  std::vector<std::string> out;
  for (const std::string& m : KnownMetrics()) {
    for (const Done& d : points) {
      if (d.metrics.count(m)) {
        out.push_back(m);
        break;
      }
    }
  }
  return out;
}

// RFC 4180: a field with a comma, quote or line break quoted, its quotes
// doubled (a list value such as rig.cameras' is JSON text).
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string Csv(const SweepSpec& spec, const std::vector<Done>& points, const std::vector<std::string>& metrics) {
  std::ostringstream out;
  out << "point";
  for (const SweepAxis& axis : spec.axes) {
    if (const auto* pose = std::get_if<PoseAxis>(&axis.axis)) {
      for (const std::string& dim : PoseNames(*pose)) out << "," << axis.name << "." << dim;
    } else if (const auto* p = std::get_if<PlacementAxis>(&axis.axis)) {
      for (const char* c : {".along", ".height", ".x", ".y", ".z"}) out << "," << axis.name << c;
      if (p->aims) out << "," << axis.name << ".pan," << axis.name << ".tilt";
    } else {
      out << "," << axis.name;
    }
  }
  for (const std::string& m : metrics) out << "," << m;
  out << "\n";
  for (const Done& d : points) {
    out << d.index;
    for (size_t k = 0; k < spec.axes.size(); ++k) {
      const AxisValue& at = d.point.at[k];
      if (std::holds_alternative<PoseAxis>(spec.axes[k].axis)) {
        for (const double v : at.pose) out << "," << Num(v);
      } else if (const auto* p = std::get_if<PlacementAxis>(&spec.axes[k].axis)) {
        out << "," << Num(at.along) << "," << Num(at.height) << "," << Num(at.position.x()) << ","
            << Num(at.position.y()) << "," << Num(at.position.z());
        if (p->aims) out << "," << Num(at.pan) << "," << Num(at.tilt);
      } else {
        out << "," << CsvField(CoordinateText(at.value));
      }
    }
    for (const std::string& m : metrics) {
      const auto it = d.metrics.find(m);
      out << "," << (it == d.metrics.end() ? "" : Num(it->second));
    }
    out << "\n";
  }
  return out.str();
}

std::string Value(const Done& d, const std::string& metric) {
  const auto it = d.metrics.find(metric);
  return it == d.metrics.end() ? "–" : Short(it->second);
}

// Markdown: the points best first.
std::string RankTable(const SweepSpec& spec, const std::vector<Done>& ranked) {
  std::vector<std::string> shown = {spec.metric};
  for (const char* m : {"arms_mean_cm", "root_mean_cm", "tracked_fraction", "silhouette_iou_median"}) {
    if (m != spec.metric) shown.push_back(m);
  }
  std::ostringstream out;
  out << "| rank | point |";
  for (const SweepAxis& axis : spec.axes) out << " " << axis.name << " |";
  for (const std::string& m : shown) out << " " << m << " |";
  out << "\n|---|---|";
  for (size_t k = 0; k < spec.axes.size() + shown.size(); ++k) out << "---|";
  out << "\n";
  for (size_t r = 0; r < ranked.size(); ++r) {
    const Done& d = ranked[r];
    out << "| " << r + 1 << " | " << PointName(d.index) << " |";
    for (size_t k = 0; k < spec.axes.size(); ++k) out << " " << AxisText(spec.axes[k], d.point.at[k]) << " |";
    for (const std::string& m : shown) out << " " << Value(d, m) << " |";
    out << "\n";
  }
  return out.str();
}

// Per axis (value axes; on a grid also placements and poses), the metric
// over the points at each of its values, in the order they first appear.
std::vector<std::pair<size_t, AxisSummary>> AxisSummaries(const SweepSpec& spec, const std::vector<Done>& points) {
  std::vector<std::pair<size_t, AxisSummary>> out;
  for (size_t k = 0; k < spec.axes.size(); ++k) {
    const SweepAxis& axis = spec.axes[k];
    const auto* placed = std::get_if<PlacementAxis>(&axis.axis);
    if (!std::holds_alternative<ValueAxis>(axis.axis) && spec.mode != "grid") continue;  // continuous
    AxisSummary summary{axis.name, {}};
    std::map<std::string, size_t> row_of;
    for (const Done& d : points) {
      const auto it = d.metrics.find(spec.metric);
      if (it == d.metrics.end()) continue;
      const AxisValue& at = d.point.at[k];
      std::string key = AxisText(axis, at);
      if (placed) {
        key = "height " + Short(at.height) + " m, along " + Short(at.along) +
              (placed->aims ? ", pan " + Short(at.pan) + "°, tilt " + Short(at.tilt) + "°" : "");
      }
      const auto [row, added] = row_of.try_emplace(key, summary.values.size());
      if (added) {
        AxisValueSummary v;
        v.label = key;
        if (at.value.is_number()) v.x = at.value.get<double>();
        v.min = v.max = it->second;
        summary.values.push_back(v);
      }
      AxisValueSummary& v = summary.values[row->second];
      v.mean += it->second;  // a sum until the end
      v.min = std::min(v.min, it->second);
      v.max = std::max(v.max, it->second);
      ++v.points;
    }
    for (AxisValueSummary& v : summary.values) v.mean /= v.points;
    out.emplace_back(k, std::move(summary));
  }
  return out;
}

// Markdown: per axis, the metric's mean (and range) over the points at each
// of its values.
std::string AxisTables(const SweepSpec& spec, const std::vector<std::pair<size_t, AxisSummary>>& summaries) {
  std::ostringstream out;
  for (const auto& [k, summary] : summaries) {
    const bool placed = std::holds_alternative<PlacementAxis>(spec.axes[k].axis);
    out << "\n### " << summary.name << "\n\n| " << (placed ? "placement" : summary.name) << " | points | mean "
        << spec.metric << " | min | max |\n|---|---|---|---|---|\n";
    for (const AxisValueSummary& v : summary.values) {
      out << "| " << v.label << " | " << v.points << " | " << Short(v.mean) << " | " << Short(v.min) << " | "
          << Short(v.max) << " |\n";
    }
  }
  return out.str();
}

// An SVG heat map of one placement axis: the metric (mean over the other
// axes; with aim ranges, at the position's best aim) at each position along
// the line and height; green best, red worst.
std::string HeatMap(const SweepSpec& spec, size_t k, const std::vector<Done>& points) {
  const auto& p = std::get<PlacementAxis>(spec.axes[k].axis);
  const bool higher = HigherIsBetter(spec.metric);
  struct Cell {
    double along, height;
    std::map<std::pair<double, double>, std::pair<double, int>> by_aim;  // (pan, tilt) -> (sum, count)
    double value = 0;
    std::pair<double, double> aim;  // the best
  };
  std::map<std::pair<long, long>, Cell> cells;
  for (const Done& d : points) {
    const auto it = d.metrics.find(spec.metric);
    if (it == d.metrics.end()) continue;
    const AxisValue& at = d.point.at[k];
    const std::pair<long, long> key = spec.mode == "grid" ? std::make_pair(long(at.along_step), long(at.height_step))
                                                            : std::make_pair(long(d.index), 0L);
    auto& [sum, n] = cells.try_emplace(key, Cell{at.along, at.height, {}, 0.0, {}}).first->second.by_aim[{at.pan, at.tilt}];
    sum += it->second;
    ++n;
  }
  if (cells.empty()) return "";
  for (auto& [key, c] : cells) {
    bool first = true;
    for (const auto& [aim, sum_n] : c.by_aim) {
      const double v = sum_n.first / sum_n.second;
      if (first || (higher ? v > c.value : v < c.value)) c.value = v, c.aim = aim;
      first = false;
    }
  }
  // Colour by rank (one outlier would wash out a linear scale).
  std::vector<double> values;
  for (const auto& [key, c] : cells) values.push_back(c.value);
  std::sort(values.begin(), values.end());
  const double lo = values.front(), hi = values.back();
  const auto badness = [&](double v) {
    if (values.size() < 2) return 0.0;
    const double rank = double(std::lower_bound(values.begin(), values.end(), v) - values.begin()) / (values.size() - 1);
    return higher ? 1 - rank : rank;
  };
  const double w = 480, h = 240, left = 60, top = 20, bottom = 50;
  const double hmin = std::min(p.height.from, p.height.to), hmax = std::max(p.height.from, p.height.to);
  const int cols = spec.mode == "grid" ? p.steps : 1, rows = spec.mode == "grid" ? p.height.steps : 1;
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << left + w + 20 << "\" height=\"" << top + h + bottom
      << "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  for (const auto& [key, c] : cells) {
    const double v = c.value;
    const double bad = badness(v);
    const std::string aim = p.aims ? " at pan " + Short(c.aim.first) + "°, tilt " + Short(c.aim.second) + "°" : "";
    char colour[32];
    std::snprintf(colour, sizeof(colour), "rgb(%d,%d,70)", int(40 + 200 * bad), int(190 - 150 * bad));
    const double fx = c.along, fy = hmax > hmin ? (c.height - hmin) / (hmax - hmin) : 0.5;
    if (spec.mode == "grid") {
      const double cw = w / cols, ch = h / rows;
      const double x = left + (cols > 1 ? fx * (cols - 1) : 0) * cw, y = top + h - ch - (rows > 1 ? fy * (rows - 1) : 0) * ch;
      svg << "<rect x=\"" << x << "\" y=\"" << y << "\" width=\"" << cw - 1 << "\" height=\"" << ch - 1
          << "\" fill=\"" << colour << "\"/><text x=\"" << x + cw / 2 << "\" y=\"" << y + ch / 2 + 4
          << "\" text-anchor=\"middle\" fill=\"white\">" << Short(v) << "<title>" << Short(v) << aim
          << "</title></text>\n";
    } else {
      svg << "<circle cx=\"" << left + fx * w << "\" cy=\"" << top + h - fy * h << "\" r=\"7\" fill=\"" << colour
          << "\"><title>" << Short(v) << aim << "</title></circle>\n";
    }
  }
  const Eigen::Vector3d a = {p.from.x(), p.from.y(), 0}, b = {p.to.x(), p.to.y(), 0};
  svg << "<text x=\"" << left << "\" y=\"" << top + h + 18 << "\">along: x, y = (" << Short(a.x()) << ", "
      << Short(a.y()) << ")</text><text x=\"" << left + w << "\" y=\"" << top + h + 18
      << "\" text-anchor=\"end\">(" << Short(b.x()) << ", " << Short(b.y()) << ")</text>\n"
      << "<text x=\"" << left + w / 2 << "\" y=\"" << top + h + 38 << "\" text-anchor=\"middle\">camera " << p.camera
      << ": " << spec.metric << (p.aims ? " at each position's best aim" : "") << ", coloured by rank (green best: " << Short(higher ? hi : lo) << ", red worst: "
      << Short(higher ? lo : hi) << ")</text>\n"
      << "<text x=\"" << left - 6 << "\" y=\"" << top + h << "\" text-anchor=\"end\">" << Short(hmin)
      << " m</text><text x=\"" << left - 6 << "\" y=\"" << top + 10 << "\" text-anchor=\"end\">" << Short(hmax)
      << " m</text>\n</svg>\n";
  return svg.str();
}

// A search's convergence, generation by generation.
std::vector<ConvergenceRow> ConvergenceRows(const SweepSpec& spec, const std::vector<Done>& points) {
  const bool higher = SeeksHigh(spec);
  std::vector<ConvergenceRow> rows;
  double best = higher ? -1e300 : 1e300;
  int evaluations = 0;
  for (int g = 0; g < GenerationCount(spec); ++g) {
    double gen_best = higher ? -1e300 : 1e300, sum = 0;
    int n = 0;
    for (const Done& d : points) {
      const auto it = d.metrics.find(spec.metric);
      if (GenerationOf(spec, d.index) != g || it == d.metrics.end()) continue;
      gen_best = higher ? std::max(gen_best, it->second) : std::min(gen_best, it->second);
      sum += it->second;
      ++n;
    }
    if (n == 0) break;
    evaluations += n;
    best = higher ? std::max(best, gen_best) : std::min(best, gen_best);
    rows.push_back({g, evaluations, gen_best, sum / n, best});
  }
  return rows;
}

// Markdown: the convergence table.
std::string Convergence(const std::vector<ConvergenceRow>& rows) {
  std::ostringstream out;
  out << "| generation | evaluations | generation's best | generation's mean | best so far |\n|---|---|---|---|---|\n";
  for (const ConvergenceRow& r : rows) {
    out << "| " << r.generation << " | " << r.evaluations << " | " << Short(r.generation_best) << " | "
        << Short(r.generation_mean) << " | " << Short(r.best_so_far) << " |\n";
  }
  return out.str();
}

// How to render, track and score the best point alone.
std::string ReproduceText(const SweepContext& sweep, const Done& best) {
  const Scenario sc = PointScenario(sweep.spec, best.point, sweep.out);
  const RenderJobOptions& r = sc.render;
  std::ostringstream out;
  out << "irbench render --rig " << r.rig << (r.scene.empty() ? "" : " --scene " + r.scene) << " --avatar "
      << r.avatar << " --motion " << r.motion << " --sensor " << r.sensor << " --seed " << r.seed
      << (r.frames ? " --frames " + std::to_string(*r.frames) : std::string()) << " --background-frames "
      << r.background_frames << " --out best && irbench track best && irbench score best";
  return out.str();
}

// A suite of the first `count` ranked points (an adversarial sweep's hardest
// poses), each scenario the point's render inputs with its saved motion and
// rig; a loose guard on its arms error (1.5 x the point's). Motion files are
// relative to the suite (in OUT beside motions/).
std::string HardestSuite(const SweepContext& sweep, const std::vector<Done>& ranked, size_t count) {
  nlohmann::json scenarios = nlohmann::json::array();
  for (size_t r = 0; r < std::min(count, ranked.size()); ++r) {
    const Done& d = ranked[r];
    const auto arms = d.metrics.find("arms_mean_cm");
    if (arms == d.metrics.end()) continue;
    const RenderJobOptions render = PointScenario(sweep.spec, d.point, sweep.out).render;
    const fs::path motion(render.motion);
    nlohmann::json sc = {{"name", sweep.spec.name + "_" + PointName(d.index)},
                         {"rig", render.rig},
                         {"avatar", render.avatar},
                         {"motion", motion.parent_path() == fs::absolute(sweep.out / "motions")
                                        ? "motions/" + motion.filename().string()
                                        : render.motion},
                         {"sensor", render.sensor},
                         {"seed", render.seed},
                         {"background_frames", render.background_frames},
                         {"thresholds", {{"arms_mean_cm", {{"max", std::ceil(1.5 * arms->second)}, {"tolerance", 1.0}}}}}};
    if (!render.scene.empty()) sc["scene"] = render.scene;
    if (render.frames) sc["frames"] = *render.frames;
    scenarios.push_back(sc);
  }
  const nlohmann::json suite = {
      {"format", "irbench.suite/1"},
      {"name", sweep.spec.name + "_hardest"},
      {"description", "The " + std::to_string(scenarios.size()) + " hardest points of sweep " + sweep.spec.name +
                          " by " + sweep.spec.metric + ", written by `irbench sweep collect`."},
      {"scenarios", scenarios}};
  return suite.dump(2) + "\n";
}

}  // namespace

SweepCollected CollectSweep(const SweepOptions& options) {
  const SweepContext sweep = OpenSweep(options);
  const SweepSpec& spec = sweep.spec;
  SweepCollected out;
  out.total = PointCount(spec);
  std::vector<Done> points = ReadPoints(sweep, &out.missing);
  out.done = static_cast<int>(points.size());
  const std::vector<std::string> metrics = MetricColumns(points);
  out.csv = sweep.out / "sweep.csv";
  AtomicWriteFile(out.csv, Csv(spec, points, metrics));
  std::vector<Done> ranked = points;
  Rank(spec, &ranked);
  std::ostringstream md;
  md << "# sweep " << spec.name << "\n\n" << spec.description << "\n\n" << out.done << " of " << out.total
     << " points done (mode " << spec.mode << "), ranked by " << spec.metric << " ("
     << (HigherIsBetter(spec.metric) ? "higher" : "lower") << " is better"
     << (spec.mode == "adversarial" ? "; adversarial: the worst first" : "") << ").\n";
  if (!out.missing.empty()) {
    md << "Not done: " << out.missing.size() << " point(s); `irbench sweep run` or `submit` again runs only them.\n";
  }
  std::string best_text;
  if (!ranked.empty() && ranked.front().metrics.count(spec.metric)) {
    const Done& best = ranked.front();
    out.best = best.index;
    best_text = std::string(spec.mode == "adversarial" ? "## Hardest: " : "## Best: ") + PointName(best.index) + ", " + spec.metric + " " + Short(best.metrics.at(spec.metric)) +
                "\n\nAt " + best.coordinates.dump() + ".\n\nAlone: `" + ReproduceText(sweep, best) + "`\n";
    md << "\n" << best_text;
  }
  const std::vector<std::pair<size_t, AxisSummary>> summaries = AxisSummaries(spec, points);
  const std::vector<ConvergenceRow> convergence_rows =
      spec.population > 0 ? ConvergenceRows(spec, points) : std::vector<ConvergenceRow>();
  const std::string rank_table = RankTable(spec, ranked), axis_tables = AxisTables(spec, summaries);
  const std::string convergence = convergence_rows.empty() ? std::string() : Convergence(convergence_rows);
  // Charts of the value axes and the convergence (gnuplot; without it, the tables alone).
  std::map<std::string, std::string> charts;
  std::vector<AxisSummary> value_summaries;
  for (const auto& [k, summary] : summaries) {
    if (std::holds_alternative<ValueAxis>(spec.axes[k].axis)) value_summaries.push_back(summary);
  }
  if (const std::optional<fs::path> gnuplot = FindGnuplot()) {
    charts = DrawSweepPlots(spec.metric, convergence_rows, value_summaries, *gnuplot, sweep.out / "plots");
  } else if (!convergence_rows.empty() || !value_summaries.empty()) {
    Log().warn("sweep collect: no gnuplot found (install Debian's gnuplot-nox, or set IRBENCH_GNUPLOT): "
               "report.html has tables but no charts");
  }
  if (!convergence.empty()) md << "\n## Search convergence\n\n" << convergence;
  md << "\n## Points, best first\n\n" << rank_table << "\n## " << spec.metric << " by axis\n" << axis_tables;
  out.md = sweep.out / "sweep.md";
  AtomicWriteFile(out.md, md.str());
  std::ostringstream html;
  html << "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>sweep " << HtmlEscape(spec.name)
       << "</title><style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse;margin:1em 0}"
          "td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}th{background:#eee}</style></head><body>\n"
       << "<h1>sweep " << HtmlEscape(spec.name) << "</h1>\n<p>" << HtmlEscape(spec.description) << "</p>\n<p>"
       << out.done << " of " << out.total << " points done; ranked by " << HtmlEscape(spec.metric) << ".</p>\n";
  if (out.best) {
    html << "<h2>" << (spec.mode == "adversarial" ? "Hardest: " : "Best: ") << PointName(*out.best) << "</h2>\n<p><code>" << HtmlEscape(ReproduceText(sweep, ranked.front()))
         << "</code></p>\n";
  }
  for (size_t k = 0; k < spec.axes.size(); ++k) {
    if (!std::holds_alternative<PlacementAxis>(spec.axes[k].axis)) continue;
    html << "<h2>Placement of " << HtmlEscape(spec.axes[k].name) << "</h2>\n" << HeatMap(spec, k, points);
  }
  if (!convergence.empty()) {
    html << "<h2>Search convergence</h2>\n" << (charts.count("convergence") ? charts.at("convergence") : "")
         << MarkdownTableHtml(convergence);
  }
  html << "<h2>Points, best first</h2>\n" << MarkdownTableHtml(rank_table) << "<h2>" << HtmlEscape(spec.metric)
       << " by axis</h2>\n";
  if (charts.size() > (charts.count("convergence") ? 1u : 0u)) {
    html << "<p>Each chart: the metric's mean over the points at each value of the axis (over every other axis), "
            "the bars their range. Points that measured nothing (the person never tracked) are left out; the "
            "table above lists them with a dash.</p>\n";
  }
  for (size_t i = 0; i < value_summaries.size(); ++i) {
    if (const auto chart = charts.find("axis_" + std::to_string(i)); chart != charts.end()) html << chart->second;
  }
  html << MarkdownTableHtml(axis_tables) << "<h2>Each point's report, worst first</h2>\n<ul>\n";
  for (auto it = ranked.rbegin(); it != ranked.rend(); ++it) {
    if (it->report.empty()) continue;
    const std::string link = fs::relative(sweep.cache / it->report, sweep.out).generic_string();
    html << "<li><a href=\"" << HtmlEscape(link) << "\">" << PointName(it->index) << "</a> " << HtmlEscape(spec.metric)
         << " " << Value(*it, spec.metric) << "</li>\n";
  }
  html << "</ul>\n</body></html>\n";
  if (spec.mode == "adversarial" && !ranked.empty()) {
    out.suite = sweep.out / "suite.json";
    AtomicWriteFile(out.suite, HardestSuite(sweep, ranked, 5));
  }
  out.html = sweep.out / "report.html";
  AtomicWriteFile(out.html, html.str());
  return out;
}

}  // namespace irbench
