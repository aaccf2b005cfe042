#include "ci/report/plots.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/file_bytes.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

// A readable bin width: 1, 2 or 5 times a power of ten, about `span` / 20.
double BinWidth(double span) {
  const double raw = std::max(span / 20.0, 0.05);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10 * p;
}

// One series per file, "frame value" rows; a blank line where frames are
// skipped so that gnuplot breaks the line there.
void WriteSeries(const fs::path& path, const std::vector<std::tuple<int, double, bool>>& rows) {
  std::ostringstream out;
  int last = -2;
  for (const auto& [frame, error, outlier] : rows) {
    if (last >= 0 && frame != last + 1) out << "\n";
    out << frame << " " << error << "\n";
    last = frame;
  }
  AtomicWriteFile(path, out.str());
}

}  // namespace

std::string GnuplotQuoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::optional<fs::path> FindGnuplot() {
  if (const char* env = std::getenv("IRBENCH_GNUPLOT")) {
    if (*env == '\0') return std::nullopt;
    return fs::path(env);
  }
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (dir.empty()) continue;
    const fs::path candidate = fs::path(dir) / "gnuplot";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

void RunGnuplot(const fs::path& gnuplot, const fs::path& workdir, const std::string& script_file) {
  const fs::path err = workdir / "gnuplot.log";
  const pid_t pid = ::fork();
  if (pid < 0) throw RuntimeError("cannot start gnuplot: fork failed");
  if (pid == 0) {
    // The child: only async-signal-safe calls until exec.
    if (::chdir(workdir.c_str()) != 0) ::_exit(126);
    const int fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    const int null_in = ::open("/dev/null", O_RDONLY);
    if (null_in >= 0) ::dup2(null_in, 0);
    ::execl(gnuplot.c_str(), "gnuplot", script_file.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw RuntimeError("cannot wait for gnuplot");
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    throw RuntimeError(gnuplot.string() + " failed (exit " + std::to_string(code) + ") on " +
                       (workdir / script_file).string() + ": " +
                       (code == 127 ? std::string("cannot run it") : ReadFileBytes(err)));
  }
}

std::map<std::string, std::string> DrawGnuplotSvgs(const fs::path& gnuplot, const fs::path& workdir,
                                                   const std::string& script_file, const std::string& script,
                                                   const std::vector<std::string>& names) {
  AtomicWriteFile(workdir / script_file, script);
  RunGnuplot(gnuplot, workdir, script_file);
  std::map<std::string, std::string> svgs;
  for (const std::string& name : names) {
    const fs::path file = workdir / (name + ".svg");
    if (!fs::is_regular_file(file)) throw RuntimeError("gnuplot wrote no " + file.string());
    svgs[name] = ReadFileBytes(file);
  }
  return svgs;
}

std::map<std::string, std::string> DrawScorePlots(const Score& score, const fs::path& gnuplot,
                                                  const fs::path& workdir) {
  fs::create_directories(workdir);
  const std::vector<std::string>& joints = ScoredJoints();
  std::ostringstream gp;
  gp << "# irbench score plots; data beside this script. Run: gnuplot plots.gp\n"
     << "set terminal svg size 960,760 font \"sans,11\" background rgb \"white\"\n"
     << "set style fill solid 0.75 border rgb \"#1f4e79\"\n"
     << "set grid ytics lc rgb \"#dddddd\"\n";

  // Fig. 6.8: histograms. Counts are binned here, gnuplot draws boxes.
  gp << "set output \"joint_histograms.svg\"\n"
     << "set multiplot layout 3,3 title \"Joint error histograms, cm (thesis Fig. 6.8; Chauvenet outliers left out)\"\n";
  for (const std::string& joint : joints) {
    std::vector<double> kept;
    int outliers = 0;
    if (const auto it = score.joint_errors.find(joint); it != score.joint_errors.end()) {
      for (const auto& [frame, error, outlier] : it->second) {
        if (outlier) {
          ++outliers;
        } else {
          kept.push_back(error);
        }
      }
    }
    std::string title = TitleCase(joint);
    if (outliers) title += " (" + std::to_string(outliers) + " outlier" + (outliers > 1 ? "s" : "") + ")";
    gp << "set title " << GnuplotQuoted(title) << "\n";
    if (kept.empty()) {
      gp << "unset xtics; unset ytics; set label 1 \"not scored\" at graph 0.5, graph 0.5 center\n"
         << "plot [0:1] [0:1] 2 notitle\n"
         << "unset label 1; set xtics; set ytics\n";
      continue;
    }
    const double top = *std::max_element(kept.begin(), kept.end());
    const double width = BinWidth(top);
    const int bins = std::max(1, int(std::floor(top / width)) + 1);
    std::vector<int> counts(bins, 0);
    for (double e : kept) ++counts[std::min(bins - 1, int(std::floor(e / width)))];
    std::ostringstream data;
    for (int b = 0; b < bins; ++b) data << (b + 0.5) * width << " " << counts[b] << "\n";
    const std::string file = "hist_" + joint + ".dat";
    AtomicWriteFile(workdir / file, data.str());
    gp << "set boxwidth " << width << "\n"
       << "plot [0:" << bins * width << "] [0:*] " << GnuplotQuoted(file)
       << " using 1:2 with boxes lc rgb \"#4f8fcf\" notitle\n";
  }
  gp << "unset multiplot\n";

  // Errors over time.
  gp << "set output \"errors_over_time.svg\"\n"
     << "set multiplot layout 2,1 title \"Errors over time (outliers included)\"\n"
     << "set key outside right top\nset xlabel \"frame\"\n";
  gp << "set title \"Joints\"\n";
  const char* colours[] = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e",
                           "#e6ab02", "#a6761d", "#666666", "#1f78b4"};
  auto series_plot = [&](const std::map<std::string, std::vector<std::tuple<int, double, bool>>>& series,
                         const std::vector<std::string>& names, const std::string& prefix,
                         const std::string& title_suffix, const std::string& ylabel) {
    gp << "set ylabel " << GnuplotQuoted(ylabel) << "\n";
    std::vector<std::string> parts;
    for (size_t i = 0; i < names.size(); ++i) {
      const auto it = series.find(names[i]);
      if (it == series.end() || it->second.empty()) continue;
      const std::string file = prefix + names[i] + ".dat";
      WriteSeries(workdir / file, it->second);
      parts.push_back(GnuplotQuoted(file) + " using 1:2 with lines lw 1.5 lc rgb \"" + colours[i % 9] + "\" title " +
                      GnuplotQuoted(TitleCase(names[i]) + title_suffix));
    }
    if (parts.empty()) {
      gp << "set label 1 \"not scored\" at graph 0.5, graph 0.5 center\nplot [0:1] [0:1] 2 notitle\nunset label 1\n";
      return;
    }
    gp << "plot [*:*] [0:*] ";
    for (size_t i = 0; i < parts.size(); ++i) gp << (i ? ", \\\n     " : "") << parts[i];
    gp << "\n";
  };
  series_plot(score.joint_errors, joints, "time_", "", "joint error, cm");
  gp << "set title \"Pointing\"\n";
  series_plot(score.pointing_errors, {"right", "left"}, "time_pointing_", " hand", "pointing error, degrees");
  gp << "unset multiplot\n";

  // The silhouettes' IoU over time, a line per camera (when scored).
  std::vector<std::string> names = {"joint_histograms", "errors_over_time"};
  if (score.silhouettes && !score.silhouettes->frames.empty()) {
    std::map<std::string, std::vector<std::tuple<int, double, bool>>> by_camera;
    for (const SilhouetteCounts& c : score.silhouettes->frames) by_camera[c.camera].emplace_back(c.frame, c.iou(), false);
    std::vector<std::string> cameras;
    for (const auto& [camera, rows] : by_camera) cameras.push_back(camera);
    gp << "set terminal svg size 960,380 font \"sans,11\" background rgb \"white\"\n"
       << "set output \"silhouettes_over_time.svg\"\n"
       << "set title \"Silhouettes against the truth masks: IoU per camera-frame\"\n"
       << "set key outside right top\nset xlabel \"frame\"\nset ylabel \"IoU\"\n"
       << "plot [*:*] [0:1] ";
    for (size_t i = 0; i < cameras.size(); ++i) {
      const std::string file = "silhouette_iou_" + cameras[i] + ".dat";
      WriteSeries(workdir / file, by_camera[cameras[i]]);
      gp << (i ? ", \\\n     " : "") << GnuplotQuoted(file) << " using 1:2 with linespoints pt 7 ps 0.2 lw 1.5 lc rgb \""
         << colours[i % 9]
         << "\" title " << GnuplotQuoted(cameras[i]) << " noenhanced";
    }
    gp << "\n";
    names.push_back("silhouettes_over_time");
  }

  return DrawGnuplotSvgs(gnuplot, workdir, "plots.gp", gp.str(), names);
}

}  // namespace irbench
