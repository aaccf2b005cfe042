#pragma once
// A sweep report's charts, drawn by gnuplot as SVG (as the score report's
// are, ci/report/plots.h): the search's convergence, and the metric against
// each value axis (a line over numbers, bars over names), each value's mean
// over the other axes with the range of its points.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace irbench {

// One generation of a search.
struct ConvergenceRow {
  int generation = 0;
  int evaluations = 0;  // points done up to and including this generation
  double generation_best = 0, generation_mean = 0, best_so_far = 0;
};

// The metric at one value of an axis, over the points that have it.
struct AxisValueSummary {
  std::string label;       // the value, short
  std::optional<double> x;  // the value when it is a number
  double mean = 0, min = 0, max = 0;
  int points = 0;
};

struct AxisSummary {
  std::string name;  // the axis's key
  std::vector<AxisValueSummary> values;  // in the order they first appear among the measured points
};

// Writes the data, `sweep_plots.gp` and the SVGs into `workdir` (created if
// needed; the data and script stay so that a user can restyle them) and
// returns name -> SVG text: "convergence" when there are rows, and
// "axis_<i>" for summaries[i] with at least two values.
std::map<std::string, std::string> DrawSweepPlots(const std::string& metric, const std::vector<ConvergenceRow>& convergence,
                                                  const std::vector<AxisSummary>& summaries,
                                                  const std::filesystem::path& gnuplot,
                                                  const std::filesystem::path& workdir);

}  // namespace irbench
