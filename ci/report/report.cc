#include "ci/report/report.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "ci/report/plots.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/logging.h"
#include "sequence_format/frame_lines.h"
#include "sequence_format/manifest.h"
#include "tracker/io/sequence_input.h"
#include "tracker/body_model/body_model.h"
#include "tracker/body_model/ellipse_projection.h"

namespace irbench {
namespace fs = std::filesystem;
namespace {

using Json = nlohmann::json;

std::string Escape(const std::string& s) { return HtmlEscape(s); }


std::string Base64(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += table[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint8_t(bytes[i]) << 16;
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8);
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

double Round1(double v) { return std::round(v * 10) / 10; }

std::string StatsRow(const std::string& name, const ErrorStats& s) {
  const auto cell = [&](double v) { return s.total ? Fixed(v, 2) : std::string("–"); };
  return "<tr><th>" + Escape(name) + "</th><td>" + cell(s.mean) + "</td><td>" + cell(s.std) + "</td><td>" +
         std::to_string(s.outliers) + "</td><td>" + std::to_string(s.total) + "</td><td>" +
         std::to_string(s.missing) + "</td><td>" + cell(s.max) + "</td></tr>\n";
}

// A confusion matrix (truth -> found -> count) as an HTML table, rows truth.
std::string ConfusionTable(const std::string& id, const std::string& title_html,
                           const std::map<std::string, std::map<std::string, int>>& confusion) {
  const std::vector<std::string> labels = ConfusionLabels(confusion);
  std::ostringstream out;
  out << "<h3>" << title_html << "</h3>\n<table id=\"" << id << "\"><tr><th></th>";
  for (const std::string& l : labels) out << "<th>" << Escape(l) << "</th>";
  out << "</tr>\n";
  for (const std::string& t : labels) {
    const auto row = confusion.find(t);
    if (row == confusion.end()) continue;
    out << "<tr><th>" << Escape(t) << "</th>";
    for (const std::string& l : labels) {
      const auto c = row->second.find(l);
      out << "<td>" << (c == row->second.end() ? 0 : c->second) << "</td>";
    }
    out << "</tr>\n";
  }
  out << "</table>\n";
  return out.str();
}

// Per truth label: frames, our recall, and the diagonals of the thesis's
// Tables 7.1 (CRF) and 7.2 (LDCRF).
std::string MotionRecallTable(const std::map<std::string, std::map<std::string, int>>& confusion) {
  const std::map<std::string, double> recall = PerLabelRecall(confusion);
  std::ostringstream out;
  out << "<table id=\"motion-recall\"><tr><th>label</th><th>frames</th><th>recall</th><th>thesis CRF</th>"
      << "<th>thesis LDCRF</th></tr>\n";
  auto percent = [](double v) { return std::isnan(v) ? std::string("–") : Fixed(100 * v, 1) + " %"; };
  for (const auto& [label, r] : recall) {
    int frames = 0;
    for (const auto& [found, n] : confusion.at(label)) frames += n;
    out << "<tr><th>" << Escape(label) << "</th><td>" << frames << "</td><td>" << percent(r) << "</td><td>"
        << percent(ThesisMotionRecall("crf", label)) << "</td><td>" << percent(ThesisMotionRecall("ldcrf", label))
        << "</td></tr>\n";
  }
  out << "<tr><th>mean</th><td></td><td>" << percent(MeanRecall(confusion)) << "</td><td>74.3 %</td><td>85.5 %</td></tr>\n"
      << "</table>\n";
  return out.str();
}

// Labels over time (truth above, the track's below) as an inline SVG: one
// colour per label, blank where there is none. Empty when neither side
// names a label. Rows: (frame, truth, found), frames increasing.
std::string Timeline(const std::string& id, const std::string& title,
                     const std::vector<std::tuple<int, std::string, std::string>>& rows) {
  std::vector<std::string> names;
  for (const auto& [frame, truth, found] : rows) {
    for (const std::string* n : {&truth, &found}) {
      if (!n->empty() && std::find(names.begin(), names.end(), *n) == names.end()) names.push_back(*n);
    }
  }
  if (names.empty() || rows.empty()) return "";
  std::sort(names.begin(), names.end());
  static const char* kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                                   "#7f7f7f", "#bcbd22", "#17becf"};
  const int first = std::get<0>(rows.front()), last = std::get<0>(rows.back());
  const double width = 900, scale = width / std::max(1, last - first + 1);
  std::ostringstream svg;
  svg << "<h3>" << Escape(title) << " <small>(frames " << first << "–" << last
      << "; top: truth, bottom: tracked)</small></h3>\n<svg id=\"" << id << "\" width=\"" << width + 90
      << "\" height=\"70\" xmlns=\"http://www.w3.org/2000/svg\" font-size=\"11\">"
      << "<text x=\"0\" y=\"16\">truth</text><text x=\"0\" y=\"44\">tracked</text>";
  for (int lane = 0; lane < 2; ++lane) {
    size_t i = 0;
    while (i < rows.size()) {
      const std::string& label = lane == 0 ? std::get<1>(rows[i]) : std::get<2>(rows[i]);
      size_t j = i;
      while (j + 1 < rows.size() && (lane == 0 ? std::get<1>(rows[j + 1]) : std::get<2>(rows[j + 1])) == label &&
             std::get<0>(rows[j + 1]) == std::get<0>(rows[j]) + 1) {
        ++j;
      }
      if (!label.empty()) {
        const size_t c = std::find(names.begin(), names.end(), label) - names.begin();
        svg << "<rect x=\"" << 80 + (std::get<0>(rows[i]) - first) * scale << "\" y=\"" << 4 + lane * 28
            << "\" width=\"" << std::max(1.0, (std::get<0>(rows[j]) - std::get<0>(rows[i]) + 1) * scale)
            << "\" height=\"18\" fill=\"" << kColours[c % 10] << "\"><title>" << Escape(label) << ", frames "
            << std::get<0>(rows[i]) << "–" << std::get<0>(rows[j]) << "</title></rect>";
      }
      i = j + 1;
    }
  }
  svg << "</svg>\n<p class=\"legend\">";
  for (size_t c = 0; c < names.size(); ++c) {
    svg << "<span style=\"color:" << kColours[c % 10] << "\">■ " << Escape(names[c]) << "</span> ";
  }
  svg << "</p>\n";
  return svg.str();
}

std::string Tables(const Score& score) {
  std::ostringstream out;
  out << "<p>Frames: " << score.truth_frames << " in the truth, " << score.present_frames
      << " with the person on the stage, " << score.tracked_frames << " of those tracked.</p>\n";
  const std::string head =
      "<tr><th></th><th>Mean</th><th>Std</th><th>Outliers</th><th>Total</th><th>Missing</th><th>Max kept</th></tr>\n";
  out << "<h3>Joint errors, cm <small>(thesis Table 6.1; outliers by Chauvenet's criterion)</small></h3>\n"
      << "<table id=\"joints\">" << head;
  for (const std::string& joint : ScoredJoints()) out << StatsRow(TitleCase(joint), score.joints.at(joint));
  out << "</table>\n<h3>Pointing errors, degrees <small>(thesis Table 6.3)</small></h3>\n<table id=\"pointing\">"
      << head;
  for (const std::string side : {"right", "left"}) out << StatsRow(TitleCase(side) + " hand", score.pointing.at(side));
  out << "</table>\n<h3>Rest state <small>(thesis 6.4)</small></h3>\n<table id=\"rest\">"
      << "<tr><th>Arm</th><th>Accuracy</th><th>Frames</th><th>Missing</th></tr>\n";
  for (const std::string side : {"right", "left", "both"}) {
    const auto it = score.rest.find(side);
    const Score::Accuracy a = it == score.rest.end() ? Score::Accuracy{} : it->second;
    out << "<tr><th>" << TitleCase(side) << "</th><td>" << (a.total ? Fixed(100 * a.rate(), 2) + " %" : "–")
        << "</td><td>" << a.total << "</td><td>" << a.missing << "</td></tr>\n";
  }
  out << "</table>\n";
  if (!score.motion_confusion.empty()) {
    out << ConfusionTable("motion",
                          "Motion labels <small>(thesis Tables 7.1–7.2; rows truth, columns tracked; accuracy " +
                              Fixed(100 * score.motion.rate(), 2) + " %, mean per-label recall " +
                              Fixed(100 * MeanRecall(score.motion_confusion), 2) + " %)</small>",
                          score.motion_confusion)
        << MotionRecallTable(score.motion_confusion);
  }
  if (!score.posture_confusion.empty()) {
    out << ConfusionTable("postures",
                          "Postures <small>(thesis 5.1: atom pairs, unordered; rows truth, columns recognised; " +
                              Fixed(100 * score.posture.rate(), 2) + " % of " + std::to_string(score.posture.total) +
                              " frames)</small>",
                          score.posture_confusion);
  }
  if (!score.gesture_confusion.empty()) {
    out << ConfusionTable("gestures",
                          "Gestures <small>(thesis 5.3: each performance identified as the last gesture the track "
                          "reports in it; rows truth, columns identified; " +
                              Fixed(100 * score.gesture.rate(), 2) + " % of " + std::to_string(score.gesture.total) +
                              " performances)</small>",
                          score.gesture_confusion);
  }
  if (score.silhouettes) {
    const SilhouetteScore& sil = *score.silhouettes;
    out << "<h3>Silhouettes against the truth masks <small>(camera-frames with the person in the truth mask; "
           "false foreground and missed body pixels as a share of the true body's; near the outline: the share "
           "of those errors within one pixel of the true outline)</small></h3>\n<table id=\"silhouettes\">"
        << "<tr><th>Camera</th><th>Frames</th><th>IoU median</th><th>IoU p10</th><th>False</th><th>Missed</th>"
           "<th>Near the outline</th></tr>\n";
    const auto row = [&](const std::string& name, const SilhouetteSummary& s) {
      const auto cell = [&](const std::string& v) { return "<td>" + (s.camera_frames ? v : std::string("–")) + "</td>"; };
      out << "<tr><th>" << Escape(name) << "</th><td>" << s.camera_frames << "</td>" << cell(Fixed(s.iou_median, 3))
          << cell(Fixed(s.iou_p10, 3)) << cell(Fixed(100 * s.false_share, 1) + " %")
          << cell(Fixed(100 * s.missed_share, 1) + " %")
          << cell(s.near_outline_share ? Fixed(100 * *s.near_outline_share, 0) + " %" : std::string("–"))
          << "</tr>\n";
    };
    for (const auto& [camera, s] : sil.ByCamera()) row(camera, s);
    row("All", sil.All());
    out << "</table>\n";
    if (sil.empty_frames) {
      out << "<p>" << sil.empty_frames << " camera-frames without the person in view: " << sil.empty_false
          << " silhouette pixels there.</p>\n";
    }
    if (sil.missing) out << "<p>" << sil.missing << " camera-frames have a truth mask but no silhouette.</p>\n";
  }
  return out.str();
}

// The manifest's names of what was rendered, for the page's heading.
std::string Describe(const fs::path& sequence) {
  Manifest m;
  try {
    m = ReadManifest(sequence);
  } catch (const std::exception&) {
    return "";  // the heading goes without (another tool's folder, an unreadable file)
  }
  std::ostringstream out;
  for (const auto& [key, v] : {std::pair<const char*, const std::string&>{"scene", m.scene},
                               {"rig", m.rig},
                               {"avatar", m.avatar},
                               {"motion", m.motion},
                               {"sensor", m.sensor}}) {
    if (!v.empty()) out << "<span><b>" << key << "</b> " << Escape(v) << "</span> ";
  }
  if (m.json.contains("seed") && m.json["seed"].is_number()) {
    out << "<span><b>seed</b> " << m.json["seed"].dump() << "</span> ";
  }
  return out.str();
}

// The irbench tracker's model for a track line: its 21 `dof` by name,
// `height_m`, `girth`, `arm_thickness` and `shoulder_width_m` (the fixed
// proportions where a line lacks them).
// nullopt for another tracker's line (no dof).
std::optional<PosedBody> TrackedModel(const Json& line) {
  if (!line.contains("dof") || !line["dof"].is_object() || !line.contains("height_m") ||
      !line["height_m"].is_number()) {
    return std::nullopt;
  }
  BodyPose pose;
  for (int d = 0; d < kDofCount; ++d) {
    const auto it = line["dof"].find(BodyDofName(d));
    if (it == line["dof"].end() || !it->is_number()) return std::nullopt;
    pose.dof[d] = it->get<double>();
  }
  auto number_or_one = [&](const char* key) {
    return line.contains(key) && line[key].is_number() ? line[key].get<double>() : 1.0;
  };
  // The configured shoulder width (metres between the joints) as the
  // model's factor on its fixed proportion.
  const double height = line["height_m"].get<double>();
  const double fixed_width = 2 * BodyShape::FromHeight(height).shoulder_offset_m;
  const double shoulders = line.contains("shoulder_width_m") && line["shoulder_width_m"].is_number() && fixed_width > 0
                               ? line["shoulder_width_m"].get<double>() / fixed_width
                               : 1.0;
  return PoseBody(BodyShape::FromHeight(height, number_or_one("girth"), number_or_one("arm_thickness"), shoulders),
                  pose);
}

// The viewer's data: cameras, joint names, bones, and per frame the truth's
// 2D joints, the tracked joints projected and the tracked model's outlines.
Json ViewerData(const Score& score, const ReportOptions& options, const SequenceInput& input) {
  // Read again for what the score does not keep: the truth's 2D joints, the
  // track's 3D joints and model.
  const std::map<int, Json> truth = ReadFrameLines(options.sequence / "truth" / "frames.jsonl");
  const std::map<int, Json> track = fs::is_regular_file(options.track) ? ReadFrameLines(options.track) : std::map<int, Json>{};
  const std::vector<Camera>& cameras = input.cameras();

  Json data;
  data["cameras"] = Json::array();
  for (size_t c = 0; c < cameras.size(); ++c) {
    const fs::path folder = input.FramePath(int(c), 0).parent_path();
    const auto relative = [&](const fs::path& dir) {
      return fs::relative(fs::absolute(dir), fs::absolute(options.final_dir)).generic_string() + "/";
    };
    Json cam = {{"name", cameras[c].name}, {"width", cameras[c].width}, {"height", cameras[c].height},
                {"dir", relative(folder)}};
    // The silhouettes the score compared, and the truth masks, for the
    // viewer's overlay.
    if (score.silhouettes && !score.silhouettes->frames.empty()) {
      cam["silhouettes"] = relative(score.silhouettes->silhouettes / cameras[c].name);
      cam["masks"] = relative(options.sequence / "truth" / "masks" / cameras[c].name);
    }
    data["cameras"].push_back(cam);
  }
  // Joint names from the truth (all of them, legs too), in a fixed order.
  std::vector<std::string> names;
  for (const auto& [frame, t] : truth) {
    if (!t.contains("joints3d") || !t["joints3d"].is_object()) continue;
    for (const auto& [name, v] : t["joints3d"].items()) names.push_back(name);
    break;
  }
  std::sort(names.begin(), names.end());
  const auto index = [&](const std::string& n) {
    const auto it = std::find(names.begin(), names.end(), n);
    return it == names.end() ? -1 : int(it - names.begin());
  };
  data["joints"] = names;
  data["bones"] = Json::array();
  const std::vector<std::pair<std::string, std::string>> bones = {
      {"head", "neck"}, {"neck", "waist"}, {"waist", "root"},
      {"neck", "left_shoulder"}, {"left_shoulder", "left_elbow"}, {"left_elbow", "left_wrist"}, {"left_wrist", "left_hand_tip"},
      {"neck", "right_shoulder"}, {"right_shoulder", "right_elbow"}, {"right_elbow", "right_wrist"}, {"right_wrist", "right_hand_tip"},
      {"waist", "left_hip"}, {"left_hip", "left_knee"}, {"left_knee", "left_ankle"},
      {"waist", "right_hip"}, {"right_hip", "right_knee"}, {"right_knee", "right_ankle"}};
  for (const auto& [a, b] : bones) {
    if (index(a) >= 0 && index(b) >= 0) data["bones"].push_back({index(a), index(b)});
  }

  // Per-frame error: mean over the joints scored in that frame.
  std::map<int, std::pair<double, int>> sums;
  for (const auto& [joint, rows] : score.joint_errors) {
    for (const auto& [frame, error, outlier] : rows) {
      sums[frame].first += error;
      ++sums[frame].second;
    }
  }
  const int frame_count = input.frame_count();
  data["frames"] = Json::array();
  std::vector<std::pair<double, int>> ranked;
  for (int f = 0; f < frame_count; ++f) {
    Json fr = {{"f", f}};
    const auto s = sums.find(f);
    fr["e"] = s == sums.end() ? Json(nullptr) : Json(std::round(100 * s->second.first / s->second.second) / 100);
    if (s != sums.end()) ranked.emplace_back(s->second.first / s->second.second, f);
    const auto t = truth.find(f);
    const auto k = track.find(f);
    const std::string state =
        k == track.end() ? "none" : k->second.contains("state") && k->second["state"].is_string() ? k->second["state"].get<std::string>() : "tracking";
    fr["s"] = state;
    fr["present"] = t != truth.end() && t->second.value("present", false);
    std::optional<PosedBody> model;
    // The tracked joints (world), in `names` order.
    std::vector<std::optional<Eigen::Vector3d>> tracked(names.size());
    if (k != track.end() && state == "tracking") {
      model = TrackedModel(k->second);
      const Json& j3d = k->second.contains("joints3d") ? k->second["joints3d"] : Json();
      for (size_t n = 0; n < names.size() && j3d.is_object(); ++n) {
        const auto p = j3d.find(names[n]);
        if (p != j3d.end() && p->is_array() && p->size() == 3 && (*p)[0].is_number() && (*p)[1].is_number() &&
            (*p)[2].is_number()) {
          tracked[n] = Eigen::Vector3d((*p)[0].get<double>(), (*p)[1].get<double>(), (*p)[2].get<double>());
        }
      }
    }
    Json per_truth = Json::array(), per_track = Json::array(), per_model = Json::array();
    for (const Camera& cam : cameras) {
      // Truth: x, y, visibility per joint (null when absent).
      Json tj = Json::array();
      const Json* j2d = nullptr;
      if (t != truth.end() && t->second.contains("joints2d") && t->second["joints2d"].contains(cam.name)) {
        j2d = &t->second["joints2d"][cam.name];
      }
      for (const std::string& n : names) {
        if (j2d && j2d->contains(n) && (*j2d)[n].is_array() && (*j2d)[n].size() >= 3 && (*j2d)[n][0].is_number() &&
            (*j2d)[n][1].is_number() && (*j2d)[n][2].is_number()) {
          const Json& p = (*j2d)[n];
          tj.push_back(Round1(p[0].get<double>()));
          tj.push_back(Round1(p[1].get<double>()));
          tj.push_back(p[2].get<int>());
        } else {
          tj.push_back(nullptr), tj.push_back(nullptr), tj.push_back(0);
        }
      }
      per_truth.push_back(tj);
      // Tracked joints, projected with the calibration.
      Json kj = Json::array();
      bool any = false;
      for (const std::optional<Eigen::Vector3d>& w : tracked) {
        if (w && (cam.cam_from_world * *w).z() > 0.05) {
          const Eigen::Vector2d px = cam.Project(*w);
          kj.push_back(Round1(px.x())), kj.push_back(Round1(px.y()));
          any = true;
        } else {
          kj.push_back(nullptr), kj.push_back(nullptr);
        }
      }
      per_track.push_back(any ? kj : Json(nullptr));
      Json outlines = Json::array();
      if (model) {
        for (const auto& outline : BodyOutlines(cam, *model, 20)) {
          Json o = Json::array();
          for (const Eigen::Vector2d& p : outline) o.push_back(Round1(p.x())), o.push_back(Round1(p.y()));
          outlines.push_back(o);
        }
      }
      per_model.push_back(outlines);
    }
    fr["t"] = per_truth;
    fr["k"] = per_track;
    fr["m"] = per_model;
    data["frames"].push_back(fr);
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  data["worst"] = Json::array();
  for (size_t i = 0; i < ranked.size() && int(i) < options.worst_frames; ++i) data["worst"].push_back(ranked[i].second);
  return data;
}

constexpr const char* kStyle = R"css(
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; background: #fafafa; }
h1 { margin-bottom: 0.2em; } .meta span { margin-right: 1.2em; color: #444; }
table { border-collapse: collapse; margin: 0.5em 0 1em; background: white; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.7em; text-align: right; }
th:first-child { text-align: left; } small { font-weight: normal; color: #666; }
.plot img { max-width: 100%; border: 1px solid #ddd; background: white; margin: 0.3em 0; }
.note { background: #fff4d6; border: 1px solid #e0c060; padding: 0.5em 0.8em; }
.controls { margin: 0.5em 0; display: flex; gap: 0.6em; align-items: center; flex-wrap: wrap; }
.controls input[type=range] { width: 24em; }
.cams { display: flex; flex-wrap: wrap; gap: 0.8em; }
.cam { margin: 0; } .cam figcaption { font-size: 0.9em; color: #444; }
.cam canvas { display: block; border: 1px solid #ccc; }
.legend span { margin-right: 1em; } .truth { color: #1a9641; } .tracked { color: #f07800; }
)css";

constexpr const char* kScript = R"js(
(function () {
  const data = JSON.parse(document.getElementById('viewer-data').textContent);
  const slider = document.getElementById('frame');
  const info = document.getElementById('frame-info');
  const worst = document.getElementById('worst');
  const zoom = document.getElementById('zoom');
  const cams = document.getElementById('cams');
  const scale = 2;
  const views = data.cameras.map((cam) => {
    const fig = document.createElement('figure');
    fig.className = 'cam';
    const canvas = document.createElement('canvas');
    canvas.width = cam.width * scale;
    canvas.height = cam.height * scale;
    const caption = document.createElement('figcaption');
    caption.textContent = cam.name;
    fig.appendChild(canvas);
    fig.appendChild(caption);
    cams.appendChild(fig);
    const img = new Image();
    img.addEventListener('error', () => console.error('report: cannot load ' + img.src));
    // The silhouette and the truth mask, each tinted on a canvas of its own
    // (compositing only: a page opened from file:// may not read pixels back).
    const layer = (colour) => {
      const m = new Image();
      m.addEventListener('error', () => console.error('report: cannot load ' + m.src));
      const tint = document.createElement('canvas');
      tint.width = cam.width;
      tint.height = cam.height;
      return { img: m, tint, colour };
    };
    const masks = cam.silhouettes ? [layer('#ff2020'), layer('#20c020')] : [];
    return { cam, img, canvas, masks };
  });
  const overlay = document.getElementById('show-silhouettes');
  const pad = (n) => String(n).padStart(6, '0');
  // The image window to show: the whole image, or (zoomed) a box about
  // everything drawn in this camera, with the image's aspect ratio.
  function windowFor(view, fr, c) {
    const W = view.cam.width, H = view.cam.height;
    if (!zoom.checked) return { x: 0, y: 0, w: W, h: H };
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    const add = (x, y) => {
      if (x === null || y === null || x < -W || x > 2 * W || y < -H || y > 2 * H) return;
      x0 = Math.min(x0, x); y0 = Math.min(y0, y); x1 = Math.max(x1, x); y1 = Math.max(y1, y);
    };
    if (fr.present) for (let i = 0; i < fr.t[c].length; i += 3) add(fr.t[c][i], fr.t[c][i + 1]);
    if (fr.k[c]) for (let i = 0; i < fr.k[c].length; i += 2) add(fr.k[c][i], fr.k[c][i + 1]);
    for (const o of fr.m[c]) for (let i = 0; i < o.length; i += 2) add(o[i], o[i + 1]);
    if (x0 === Infinity) return { x: 0, y: 0, w: W, h: H };
    let w = Math.max(x1 - x0, 20) * 1.5, h = Math.max(y1 - y0, 20) * 1.5;
    if (w / h > W / H) h = w * H / W; else w = h * W / H;
    w = Math.min(w, W); h = Math.min(h, H);
    const x = Math.max(0, Math.min(W - w, (x0 + x1 - w) / 2)), y = Math.max(0, Math.min(H - h, (y0 + y1 - h) / 2));
    return { x, y, w, h };
  }
  function draw(view, fr, c) {
    const ctx = view.canvas.getContext('2d');
    const win = windowFor(view, fr, c);
    const s = view.canvas.width / win.w;
    const X = (x) => (x - win.x) * s, Y = (y) => (y - win.y) * s;
    ctx.imageSmoothingEnabled = false;
    ctx.fillStyle = '#000';
    ctx.fillRect(0, 0, view.canvas.width, view.canvas.height);
    if (view.img.complete && view.img.naturalWidth) {
      ctx.drawImage(view.img, win.x, win.y, win.w, win.h, 0, 0, view.canvas.width, view.canvas.height);
    }
    // Silhouette red, truth green, added: yellow where they agree, red false
    // foreground, green missed body.
    if (overlay && overlay.checked) {
      for (const m of view.masks) {
        if (!(m.img.complete && m.img.naturalWidth)) continue;
        const t = m.tint.getContext('2d');
        t.globalCompositeOperation = 'source-over';
        t.drawImage(m.img, 0, 0);
        t.globalCompositeOperation = 'multiply';
        t.fillStyle = m.colour;
        t.fillRect(0, 0, m.tint.width, m.tint.height);
        ctx.globalCompositeOperation = 'lighter';
        ctx.globalAlpha = 0.6;
        ctx.drawImage(m.tint, win.x, win.y, win.w, win.h, 0, 0, view.canvas.width, view.canvas.height);
        ctx.globalAlpha = 1;
        ctx.globalCompositeOperation = 'source-over';
      }
    }
    function skeleton(pts, stride, colour, dashedWhenHidden) {
      ctx.strokeStyle = colour;
      ctx.fillStyle = colour;
      ctx.lineWidth = 2;
      for (const [a, b] of data.bones) {
        const ax = pts[a * stride], ay = pts[a * stride + 1], bx = pts[b * stride], by = pts[b * stride + 1];
        if (ax === null || bx === null) continue;
        const hidden = dashedWhenHidden && (pts[a * stride + 2] < 2 || pts[b * stride + 2] < 2);
        ctx.setLineDash(hidden ? [4, 4] : []);
        ctx.beginPath();
        ctx.moveTo(X(ax), Y(ay));
        ctx.lineTo(X(bx), Y(by));
        ctx.stroke();
      }
      ctx.setLineDash([]);
      for (let j = 0; j < data.joints.length; ++j) {
        const x = pts[j * stride], y = pts[j * stride + 1];
        if (x === null) continue;
        ctx.beginPath();
        ctx.arc(X(x), Y(y), 2.5, 0, 2 * Math.PI);
        ctx.fill();
      }
    }
    if (fr.present) skeleton(fr.t[c], 3, '#1a9641', true);
    ctx.strokeStyle = '#f07800';
    ctx.lineWidth = 1.5;
    for (const o of fr.m[c]) {
      ctx.beginPath();
      for (let i = 0; i < o.length; i += 2) {
        if (i === 0) ctx.moveTo(X(o[i]), Y(o[i + 1])); else ctx.lineTo(X(o[i]), Y(o[i + 1]));
      }
      ctx.closePath();
      ctx.stroke();
    }
    if (fr.k[c]) skeleton(fr.k[c], 2, '#f07800', false);
  }
  function show(f) {
    f = Math.max(0, Math.min(data.frames.length - 1, f));
    slider.value = f;
    const fr = data.frames[f];
    info.textContent = 'frame ' + f + ' · track ' + fr.s + (fr.present ? '' : ' · nobody on stage (truth)') +
        (fr.e === null ? '' : ' · mean joint error ' + fr.e.toFixed(2) + ' cm');
    views.forEach((view, c) => {
      view.img.onload = () => draw(view, fr, c);
      view.img.src = view.cam.dir + pad(fr.f) + '.png';
      if (overlay && overlay.checked) {
        [view.cam.silhouettes, view.cam.masks].forEach((dir, i) => {
          const m = view.masks[i];
          m.img.onload = () => draw(view, fr, c);
          m.img.src = dir + pad(fr.f) + '.png';
        });
      }
      draw(view, fr, c);
    });
  }
  slider.max = data.frames.length - 1;
  slider.addEventListener('input', () => show(Number(slider.value)));
  zoom.addEventListener('change', () => show(Number(slider.value)));
  if (overlay) overlay.addEventListener('change', () => show(Number(slider.value)));
  document.getElementById('prev').addEventListener('click', () => show(Number(slider.value) - 1));
  document.getElementById('next').addEventListener('click', () => show(Number(slider.value) + 1));
  for (const f of data.worst) {
    const option = document.createElement('option');
    option.value = f;
    option.textContent = 'frame ' + f + ' · ' + data.frames[f].e.toFixed(2) + ' cm';
    worst.appendChild(option);
  }
  worst.addEventListener('change', () => show(Number(worst.value)));
  document.addEventListener('keydown', (e) => {
    if (e.key === 'ArrowLeft') show(Number(slider.value) - 1);
    if (e.key === 'ArrowRight') show(Number(slider.value) + 1);
  });
  show(data.worst.length ? data.worst[0] : 0);
})();
)js";

}  // namespace

ReportResult WriteReport(const Score& score, const ReportOptions& options, const fs::path& dir) {
  const SequenceInput input = SequenceInput::Open(options.sequence);
  ReportResult result;
  std::map<std::string, std::string> svgs;
  if (const std::optional<fs::path> gnuplot = FindGnuplot()) {
    svgs = DrawScorePlots(score, *gnuplot, dir / "plots");
    result.plots = true;
  } else {
    result.note = "no gnuplot found (install Debian's gnuplot-nox, or set IRBENCH_GNUPLOT): the report has no plots";
    Log().warn("report: {}", result.note);
  }
  Json data = ViewerData(score, options, input);
  std::string json = data.dump();
  // Inside <script>, "</" would end the element.
  for (size_t at = 0; (at = json.find("</", at)) != std::string::npos; at += 3) json.replace(at, 2, "<\\/");

  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       << "<title>irbench report: " << Escape(options.sequence.filename().string()) << "</title>\n"
       << "<style>" << kStyle << "</style>\n</head>\n<body>\n"
       << "<h1>irbench report</h1>\n<p class=\"meta\">" << Describe(options.sequence) << "</p>\n"
       << "<p class=\"meta\"><span><b>sequence</b> " << Escape(fs::absolute(options.sequence).lexically_normal().string())
       << "</span> <span><b>track</b> " << Escape(fs::absolute(options.track).lexically_normal().string())
       << "</span></p>\n<h2>Tables</h2>\n"
       << Tables(score) << Timeline("gesture-timeline", "Gestures over time", score.gesture_timeline);
  for (const auto& [side, rows] : score.motion_timeline) {
    if (score.motion.total == 0) break;  // a track without motion labels
    html << Timeline("motion-timeline-" + side, "Motion labels of the " + side + " arm over time", rows);
  }
  html << "<h2>Plots</h2>\n";
  if (result.plots) {
    for (const auto& [name, title] : std::vector<std::pair<std::string, std::string>>{
             {"joint_histograms", "Joint error histograms (Fig. 6.8)"},
             {"errors_over_time", "Errors over time"},
             {"silhouettes_over_time", "Silhouettes: IoU over time, per camera"}}) {
      if (!svgs.count(name)) continue;
      html << "<figure class=\"plot\" id=\"plot-" << name << "\"><img alt=\"" << Escape(title)
           << "\" src=\"data:image/svg+xml;base64," << Base64(svgs.at(name)) << "\"><figcaption>" << Escape(title)
           << " — also <code>plots/" << name << ".svg</code>, drawn by gnuplot from <code>plots/plots.gp</code>"
           << "</figcaption></figure>\n";
    }
  } else {
    html << "<p class=\"note\">" << Escape(result.note) << "</p>\n";
  }
  html << "<h2>Frames</h2>\n"
       << "<p class=\"legend\"><span class=\"truth\">■ truth skeleton</span> (dashed where the camera does not see "
          "the joint) <span class=\"tracked\">■ tracked joints and model</span></p>\n"
       << "<div class=\"controls\"><button id=\"prev\" title=\"previous frame (←)\">◀</button>"
       << "<input type=\"range\" id=\"frame\" min=\"0\" max=\"0\" value=\"0\">"
       << "<button id=\"next\" title=\"next frame (→)\">▶</button><span id=\"frame-info\"></span>"
       << "<label>worst frames first: <select id=\"worst\"></select></label>"
       << "<label><input type=\"checkbox\" id=\"zoom\" checked> zoom to the person</label>"
       << (score.silhouettes && !score.silhouettes->frames.empty()
               ? "<label title=\"the tracker's silhouette red, the truth mask green: yellow where they agree, red "
                 "false foreground, green missed body\"><input type=\"checkbox\" id=\"show-silhouettes\"> silhouettes "
                 "against the truth masks</label>"
               : "")
       << "</div>\n"
       << "<div class=\"cams\" id=\"cams\"></div>\n"
       << "<script type=\"application/json\" id=\"viewer-data\">" << json << "</script>\n"
       << "<script>" << kScript << "</script>\n</body>\n</html>\n";
  AtomicWriteFile(dir / "report.html", html.str());
  return result;
}

std::string HtmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string MarkdownTableHtml(const std::string& markdown) {
  std::istringstream lines(markdown);
  std::ostringstream out;
  out << "<table>";
  int row = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.size() < 2 || line.front() != '|') continue;
    if (row++ == 1) continue;  // the |---| row
    std::vector<std::string> cells;
    for (size_t a = 1, b; (b = line.find('|', a)) != std::string::npos; a = b + 1) {
      std::string cell = line.substr(a, b - a);
      cell.erase(0, cell.find_first_not_of(' '));
      cell.erase(cell.find_last_not_of(' ') + 1);
      cells.push_back(cell);
    }
    out << "<tr>";
    for (const std::string& cell : cells) {
      std::string html = HtmlEscape(cell);
      for (size_t at; (at = html.find("**")) != std::string::npos;) {
        const size_t end = html.find("**", at + 2);
        if (end == std::string::npos) break;
        html = html.substr(0, at) + "<b>" + html.substr(at + 2, end - at - 2) + "</b>" + html.substr(end + 2);
      }
      out << (row == 1 ? "<th>" : "<td>") << html << (row == 1 ? "</th>" : "</td>");
    }
    out << "</tr>\n";
  }
  out << "</table>\n";
  return out.str();
}

}  // namespace irbench
