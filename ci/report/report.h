#pragma once
// `report.html`: the score of one track against its sequence's truth as a page
// that opens offline in a browser (issue 8): the thesis's tables, the plots
// (gnuplot SVG, embedded) and a frame viewer — any frame, every camera's image
// with the truth skeleton (green) and the tracked skeleton and, for irbench's
// tracker, its ellipsoid model (orange) drawn over it; the frames with the
// largest joint errors listed first.
//
// The page carries everything but the camera images, which it loads from the
// sequence's frames/ by paths relative to where the page lives: keep the page
// in its sequence (SEQ/score/), or move both together.

#include <filesystem>
#include <string>

#include "ci/score/score.h"

namespace irbench {

struct ReportOptions {
  std::filesystem::path sequence;   // the sequence folder (calib/, frames/, truth/, manifest.json)
  std::filesystem::path track;      // the track.jsonl that `score` was made from
  std::filesystem::path final_dir;  // where report.html will live: image paths are relative to it
  int worst_frames = 30;            // how many frames the "worst first" list offers
};

struct ReportResult {
  bool plots = false;  // false when no gnuplot was found (the page says so)
  std::string note;    // why there are no plots
};

// `s` with &, <, > and " as HTML entities.
std::string HtmlEscape(const std::string& s);

// A Markdown table (a header row, a |---| row, body rows) as an HTML table:
// cells escaped, **bold** kept as <b>.
std::string MarkdownTableHtml(const std::string& markdown);

// Writes `dir`/report.html and `dir`/plots/ (the SVGs with their gnuplot data
// and script). Throws InputError for an unreadable calibration or truth,
// RuntimeError when gnuplot fails.
ReportResult WriteReport(const Score& score, const ReportOptions& options, const std::filesystem::path& dir);

}  // namespace irbench
