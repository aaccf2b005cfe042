#pragma once
// The report's pictures, drawn by gnuplot (Debian's gnuplot-nox) as SVG: the
// per-joint error histograms of the thesis's Fig. 6.8 and the errors over
// time. irbench writes the data and a gnuplot script; gnuplot draws.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ci/score/score.h"

namespace irbench {

// The gnuplot to run: $IRBENCH_GNUPLOT when set (a path; empty means "no
// gnuplot"), otherwise `gnuplot` found on PATH. nullopt when there is none.
std::optional<std::filesystem::path> FindGnuplot();

// `s` as a gnuplot string literal ("..." with " and \ escaped).
std::string GnuplotQuoted(const std::string& s);

// Runs `gnuplot script_file` in `workdir`. Throws RuntimeError with what
// gnuplot printed when it fails.
void RunGnuplot(const std::filesystem::path& gnuplot, const std::filesystem::path& workdir,
                const std::string& script_file);

// Writes `script` to workdir/script_file, runs it (RunGnuplot) and returns
// name -> the text of workdir/<name>.svg for each of `names`; RuntimeError
// when gnuplot fails or leaves one of them unwritten.
std::map<std::string, std::string> DrawGnuplotSvgs(const std::filesystem::path& gnuplot,
                                                   const std::filesystem::path& workdir, const std::string& script_file,
                                                   const std::string& script, const std::vector<std::string>& names);

// Draws the score's plots with `gnuplot` in `workdir` (created if needed):
// returns plot name -> SVG text for "joint_histograms" (Fig. 6.8: one panel
// per joint, Chauvenet outliers left out and counted in the panel's title)
// and "errors_over_time" (joint errors in cm and pointing errors in degrees
// against the frame; gaps where nothing was scored) and, when the score has
// silhouettes, "silhouettes_over_time" (their IoU per camera against the
// frame). The data and script
// stay in `workdir` so that a user can restyle them.
std::map<std::string, std::string> DrawScorePlots(const Score& score, const std::filesystem::path& gnuplot,
                                                  const std::filesystem::path& workdir);

}  // namespace irbench
