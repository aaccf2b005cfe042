#include "ci/sweep/sweep_plots.h"

#include <algorithm>
#include <sstream>

#include "ci/report/plots.h"
#include "common/atomic_file.h"

namespace irbench {

namespace fs = std::filesystem;

namespace {

// A label for a tab-separated data file: no tabs or line breaks, no double
// quotes (gnuplot's string delimiter), no leading # (a comment line).
std::string Cell(std::string text) {
  std::replace_if(text.begin(), text.end(), [](char c) { return c == '\t' || c == '\n' || c == '\r'; }, ' ');
  std::replace(text.begin(), text.end(), '"', '\'');
  if (!text.empty() && text[0] == '#') text[0] = '_';
  return text.empty() ? "-" : text;
}

}  // namespace

std::map<std::string, std::string> DrawSweepPlots(const std::string& metric, const std::vector<ConvergenceRow>& convergence,
                                                  const std::vector<AxisSummary>& summaries, const fs::path& gnuplot,
                                                  const fs::path& workdir) {
  const bool any = !convergence.empty() || std::any_of(summaries.begin(), summaries.end(), [](const AxisSummary& a) {
                      return a.values.size() >= 2;
                    });
  if (!any) return {};
  fs::create_directories(workdir);
  std::vector<std::string> names;
  std::ostringstream gp;
  gp << "# irbench sweep charts; data beside this script. Run: gnuplot sweep_plots.gp\n"
     << "set terminal svg size 640,360 noenhanced font \"sans,11\" background rgb \"white\"\n"
     << "set datafile separator \"\\t\"\n"
     << "set grid ytics lc rgb \"#dddddd\"\n"
     << "set ylabel " << GnuplotQuoted(metric) << "\n";
  if (!convergence.empty()) {
    std::ostringstream data;
    data << "# generation\tevaluations\tgeneration's best\tgeneration's mean\tbest so far\n";
    for (const ConvergenceRow& r : convergence) {
      data << r.generation << "\t" << r.evaluations << "\t" << r.generation_best << "\t" << r.generation_mean << "\t"
           << r.best_so_far << "\n";
    }
    AtomicWriteFile(workdir / "convergence.tsv", data.str());
    gp << "set output \"convergence.svg\"\n"
       << "set title \"Search convergence\"\nset xlabel \"evaluations\"\nset key top right\n"
       << "plot \"convergence.tsv\" using 2:5 with linespoints pt 7 lw 2 lc rgb \"#1b9e77\" title \"best so far\", \\\n"
       << "     \"\" using 2:3 with points pt 9 ps 1.2 lc rgb \"#d95f02\" title \"generation's best\", \\\n"
       << "     \"\" using 2:4 with linespoints pt 6 dt 2 lc rgb \"#7570b3\" title \"generation's mean\"\n";
    names.push_back("convergence");
  }
  for (size_t i = 0; i < summaries.size(); ++i) {
    const AxisSummary& axis = summaries[i];
    if (axis.values.size() < 2) continue;
    const bool numeric = std::all_of(axis.values.begin(), axis.values.end(),
                                     [](const AxisValueSummary& v) { return v.x.has_value(); });
    std::vector<AxisValueSummary> rows = axis.values;
    if (numeric) std::stable_sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return *a.x < *b.x; });
    std::ostringstream data;
    data << "# value\tx\tmean\tmin\tmax\tpoints\n";
    for (const AxisValueSummary& v : rows) {
      data << Cell(v.label) << "\t" << (v.x ? *v.x : 0.0) << "\t" << v.mean << "\t" << v.min << "\t" << v.max << "\t"
           << v.points << "\n";
    }
    const std::string name = "axis_" + std::to_string(i), file = name + ".tsv";
    AtomicWriteFile(workdir / file, data.str());
    gp << "set output \"" << name << ".svg\"\n"
       << "set title " << GnuplotQuoted(metric + " against " + axis.name) << "\nset xlabel " << GnuplotQuoted(axis.name)
       << "\nset key off\n";
    if (numeric) {
      // Values spread over a factor of 8 or more (a light level, a count) on a log scale.
      const bool log = *rows.front().x > 0 && *rows.back().x >= 8 * *rows.front().x;
      gp << "set xtics autofreq\nset offsets graph 0.05, graph 0.05, 0, 0\n" << (log ? "set logscale x\n" : "")
         << "plot \"" << file << "\" using 2:3:4:5 with yerrorlines pt 7 lw 2 lc rgb \"#1f78b4\"\n"
         << (log ? "unset logscale x\n" : "");
    } else {
      gp << "set style fill solid 0.6 border rgb \"#1f4e79\"\nset boxwidth 0.6\nset xtics rotate by -20\n"
         << "set offsets 0.5, 0.5, 0, 0\n"
         << "plot [*:*] [0:*] \"" << file << "\" using 0:3:xticlabels(1) with boxes lc rgb \"#4f8fcf\", \\\n"
         << "     \"\" using 0:3:4:5 with yerrorbars pt 0 lc rgb \"#1f4e79\"\n"
         << "set xtics norotate\nset style fill empty\n";
    }
    gp << "set offsets 0, 0, 0, 0\n";
    names.push_back(name);
  }
  return DrawGnuplotSvgs(gnuplot, workdir, "sweep_plots.gp", gp.str(), names);
}

}  // namespace irbench
