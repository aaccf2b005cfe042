// The sweep report's charts: gnuplot draws one per value axis with two or
// more values and one for a search's convergence; numeric axes are plotted
// in the values' order, named ones as labelled bars; the data stay beside
// the script.

#include "ci/sweep/sweep_plots.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "ci/report/plots.h"

namespace irbench {
namespace {
namespace fs = std::filesystem;

std::string Read(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SweepPlotsTest, DrawsConvergenceAndEachValueAxis) {
  const std::optional<fs::path> gnuplot = FindGnuplot();
  if (!gnuplot) GTEST_SKIP() << "no gnuplot (ci/install_deps.sh installs gnuplot-nox)";
  const fs::path dir = fs::temp_directory_path() / "irbench_sweep_plots_test";
  fs::remove_all(dir);
  const std::vector<ConvergenceRow> convergence = {{0, 6, 4.0, 5.5, 4.0}, {1, 12, 3.1, 3.9, 3.1}, {2, 18, 3.3, 3.5, 3.1}};
  const std::vector<AxisSummary> axes = {
      {"sensor.sensor.photons_per_ms", {{"2000", 2000.0, 2.5, 2.1, 2.9, 2}, {"250", 250.0, 6.0, 5.0, 7.0, 2},
                                        {"1000", 1000.0, 3.0, 2.6, 3.4, 2}}},
      {"avatar", {{"p1", std::nullopt, 2.0, 2.0, 2.0, 1}, {"p4_tall", std::nullopt, 3.0, 2.5, 3.5, 2}}},
      {"seed", {{"1", 1.0, 2.0, 2.0, 2.0, 1}}},  // one value: no chart
  };
  const std::map<std::string, std::string> svgs = DrawSweepPlots("arms_mean_cm", convergence, axes, *gnuplot, dir);
  ASSERT_EQ(svgs.size(), 3u);
  for (const char* name : {"convergence", "axis_0", "axis_1"}) {
    ASSERT_TRUE(svgs.count(name)) << name;
    EXPECT_EQ(svgs.at(name).rfind("<?xml", 0), 0u) << name;
    EXPECT_NE(svgs.at(name).find("</svg>"), std::string::npos) << name;
    EXPECT_EQ(svgs.at(name), Read(dir / (std::string(name) + ".svg"))) << name;
  }
  EXPECT_FALSE(fs::exists(dir / "axis_2.svg"));
  // Names and labels reach the pictures as written (no enhanced-text
  // subscripts for the underscores).
  EXPECT_NE(svgs.at("axis_0").find("sensor.sensor.photons_per_ms"), std::string::npos);
  EXPECT_NE(svgs.at("axis_1").find("p4_tall"), std::string::npos);
  EXPECT_NE(svgs.at("convergence").find("best so far"), std::string::npos);
  // A numeric axis is drawn in the values' order; the data rows say so.
  std::istringstream rows(Read(dir / "axis_0.tsv"));
  std::string line;
  std::vector<std::string> labels;
  while (std::getline(rows, line)) {
    if (!line.empty() && line[0] != '#') labels.push_back(line.substr(0, line.find('\t')));
  }
  EXPECT_EQ(labels, (std::vector<std::string>{"250", "1000", "2000"}));
  EXPECT_TRUE(fs::exists(dir / "sweep_plots.gp"));
  fs::remove_all(dir);
}

TEST(SweepPlotsTest, NothingToDrawWritesNothing) {
  const std::optional<fs::path> gnuplot = FindGnuplot();
  if (!gnuplot) GTEST_SKIP() << "no gnuplot";
  const fs::path dir = fs::temp_directory_path() / "irbench_sweep_plots_empty";
  fs::remove_all(dir);
  EXPECT_TRUE(DrawSweepPlots("arms_mean_cm", {}, {{"seed", {{"1", 1.0, 2, 2, 2, 1}}}}, *gnuplot, dir).empty());
  EXPECT_FALSE(fs::exists(dir));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace irbench
