#include "ci/train/motion_label_training.h"

#include <chrono>
#include <fstream>
#include <optional>
#include <sstream>

#include "ci/score/score.h"
#include "ci/train/existing_track.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/logging.h"
#include "common/paths.h"
#include "common/progress.h"
#include "common/sha256.h"
#include "sequence_format/frame_lines.h"
#include "sequence_format/manifest.h"
#include "sim/motion/labels.h"
#include "tracker/io/sequence_input.h"
#include "tracker/motion_labels/motion_labeler.h"
#include "tracker/pipeline/frame_tracker.h"
#include "tracker/pose/rest_state.h"

namespace irbench {
namespace {

namespace fs = std::filesystem;
using Confusion = std::map<std::string, std::map<std::string, int>>;

// A sequence as the tracker saw it, with the truth's labels per frame.
struct TrackedLabels {
  std::string name, person, track;  // track: where the tracker's output came from
  std::vector<std::optional<MotionObservation>> observations;
  std::vector<std::optional<std::array<std::string, 2>>> truth;  // right, left
};

std::vector<std::optional<std::array<std::string, 2>>> TruthLabels(const fs::path& dir, int frames) {
  const fs::path file = dir / "truth" / "frames.jsonl";
  const std::map<int, nlohmann::json> lines = ReadFrameLines(file);
  std::vector<std::optional<std::array<std::string, 2>>> truth(frames);
  int labelled = 0;
  for (const auto& [f, line] : lines) {
    if (f < 0 || f >= frames) continue;
    const nlohmann::json* m = line.contains("labels") && line["labels"].is_object() && line["labels"].contains("motion")
                                  ? &line["labels"]["motion"]
                                  : nullptr;
    if (!m || !m->is_object() || !m->contains("right") || !m->contains("left") || !(*m)["right"].is_string() ||
        !(*m)["left"].is_string()) {
      continue;
    }
    truth[f] = std::array<std::string, 2>{(*m)["right"].get<std::string>(), (*m)["left"].get<std::string>()};
    ++labelled;
  }
  if (labelled == 0) throw InputError(file.string(), "labels.motion", "no frame has motion labels for both arms");
  return truth;
}

std::vector<nlohmann::json> TrackHere(const fs::path& dir) {
  const SequenceInput input = SequenceInput::Open(dir);
  TrackerSettings settings;
  settings.motion_model = MotionModelChoice::kNone;
  FrameTracker tracker(input, settings, EffectiveFrontEndOptions(settings), LoadRestClassifier(settings));
  Progress progress("train motion-labels: " + dir.filename().string(), "frame-sets", input.frame_count());
  std::vector<nlohmann::json> out;
  for (int f = 0; f < input.frame_count(); ++f) {
    std::vector<std::string> problems;
    out.push_back(tracker.Track(f, input.TryFrameSet(f, &problems), problems, 1.0 / input.fps()).track_line);
    progress.Set(f + 1, "frame");
  }
  return out;
}

TrackedLabels Load(const fs::path& dir, const RestClassifier& rest, bool retrack) {
  const Manifest manifest = ReadManifest(dir);
  TrackedLabels s;
  s.name = dir.filename().string();
  s.person = manifest.avatar.empty() ? s.name : manifest.avatar;
  s.truth = TruthLabels(dir, manifest.frame_count);
  std::optional<std::vector<nlohmann::json>> lines;
  if (std::optional<ExistingTrack> existing = retrack ? std::nullopt : ReadExistingTrack(dir, manifest.frame_count)) {
    lines = std::move(existing->lines);
  }
  if (lines) {
    s.track = "track/";
    Log().info("train motion-labels: {}: using its track/", s.name);
  } else {
    lines = TrackHere(dir);
    s.track = "tracked by irbench train motion-labels";
  }
  for (const nlohmann::json& line : *lines) s.observations.push_back(MotionObservationFromTrackLine(line, &rest));
  return s;
}

int LabelIndex(const std::string& label) {
  const auto& names = MotionLabelNames();
  const auto it = std::find(names.begin(), names.end(), label);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// Per arm, the runs of frames with both features and a truth label; the
// left arm's labels mirrored as its features are.
std::vector<std::pair<std::vector<MotionFeatures>, std::vector<int>>> Chains(const TrackedLabels& s) {
  std::vector<std::pair<std::vector<MotionFeatures>, std::vector<int>>> out;
  MotionFeatureExtractor extractor;
  std::array<std::pair<std::vector<MotionFeatures>, std::vector<int>>, 2> open;
  auto close = [&](int a) {
    if (!open[a].first.empty()) out.push_back(std::move(open[a]));
    open[a] = {};
  };
  for (size_t f = 0; f < s.observations.size(); ++f) {
    const auto features = extractor.Update(s.observations[f]);
    for (int a = 0; a < 2; ++a) {
      const int label = features && s.truth[f] ? LabelIndex(a == 0 ? (*s.truth[f])[0] : MirrorMotionLabel((*s.truth[f])[1])) : -1;
      if (label < 0) {
        close(a);
        continue;
      }
      open[a].first.push_back((*features)[a]);
      open[a].second.push_back(label);
    }
  }
  close(0);
  close(1);
  return out;
}

MotionLabelModel Fit(MotionModelKind kind, const std::vector<std::pair<std::vector<MotionFeatures>, std::vector<int>>>& chains,
                     const MotionLabelTrainingJob& job, CrfTrainingReport* report) {
  MotionLabelModel m;
  m.kind = kind;
  m.labels = MotionLabelNames();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(kMotionFeatureCount), sum2 = sum;
  double n = 0;
  for (const auto& [features, labels] : chains) {
    for (const MotionFeatures& f : features) {
      sum += f;
      sum2 += f.cwiseProduct(f);
      ++n;
    }
  }
  m.feature_mean = sum / n;
  m.feature_scale = (sum2 / n - m.feature_mean.cwiseProduct(m.feature_mean)).cwiseMax(0).cwiseSqrt();
  for (Eigen::Index i = 0; i < m.feature_scale.size(); ++i) {
    if (!(m.feature_scale(i) > 1e-9)) m.feature_scale(i) = 1;
  }
  m.decision = job.decision;
  m.prior_power = job.prior_power;
  m.label_prior = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m.labels.size()));
  for (const auto& [features, labels] : chains) {
    for (int l : labels) m.label_prior(l) += 1;
  }
  // A label the training never saw keeps a share of half a frame.
  m.label_prior = (m.label_prior.array().max(0.5) / n).matrix();
  std::vector<CrfSequence> data;
  for (const auto& [features, labels] : chains) data.push_back({m.Standardize(features), labels});
  m.crf = LatentCrf(static_cast<int>(m.labels.size()), kind == MotionModelKind::kCrf ? 1 : job.ldcrf_states,
                    kMotionFeatureCount, job.window);
  CrfTrainingOptions options = job.options;
  const std::string name = MotionModelKindName(kind);
  options.progress = [&](int k, double fx) {
    if (k % 25 == 0) Log().info("train motion-labels: {} iteration {}: objective {:.1f}", name, k, fx);
  };
  *report = TrainCrf(&m.crf, data, options);
  Log().info("train motion-labels: {}: {} after {} iterations, objective {:.1f}", name, report->status_text,
             report->iterations, report->objective);
  return m;
}

void Evaluate(const std::shared_ptr<const MotionLabelModel>& model, const TrackedLabels& s, Confusion* confusion) {
  MotionLabeler labeler(model);
  std::vector<std::optional<std::array<std::string, 2>>> found(s.observations.size());
  auto put = [&](const std::vector<MotionLabeler::Labels>& labels) {
    for (const auto& l : labels) found[l.frame] = l.arms;
  };
  for (size_t f = 0; f < s.observations.size(); ++f) put(labeler.Update(static_cast<int>(f), s.observations[f]));
  put(labeler.Finish());
  for (size_t f = 0; f < found.size(); ++f) {
    if (!s.truth[f]) continue;
    for (int a = 0; a < 2; ++a) ++(*confusion)[(*s.truth[f])[a]][found[f] ? (*found[f])[a] : "none"];
  }
}

nlohmann::json Provenance(const MotionLabelTrainingJob& job, const std::vector<TrackedLabels>& train, int arm_frames,
                          const fs::path& rest_path, const MotionLabelModel& m, const CrfTrainingReport& r) {
  nlohmann::json persons = nlohmann::json::array(), sequences = nlohmann::json::array();
  for (const TrackedLabels& s : train) {
    persons.push_back(s.person);
    sequences.push_back({{"sequence", s.name}, {"track", s.track}});
  }
  return {{"made_by", "irbench train motion-labels"},
          {"tool_version", ToolVersion()},
          {"trained_on", persons},
          {"sequences", sequences},
          {"arm_frames", arm_frames},
          {"rest_model", {{"file", rest_path.filename().string()}, {"sha256", Sha256OfFile(rest_path)}}},
          {"options",
           {{"sigma", job.options.sigma},
            {"regulariser", "|theta|^2 / (2 sigma^2)"},
            {"window", job.window},
            {"states_per_label", m.crf.states_per_label()},
            {"max_iterations", job.options.max_iterations},
            {"epsilon", job.options.epsilon},
            {"seed", job.options.seed}}},
          {"lbfgs", {{"iterations", r.iterations}, {"status", r.status_text}, {"objective", r.objective}}}};
}

}  // namespace

std::string MotionLabelEvaluation::Markdown() const {
  std::ostringstream out;
  for (const auto& [kind, confusion] : this->confusion) {
    out << "## " << (kind == "crf" ? "CRF (thesis Table 7.1)" : "LDCRF (thesis Table 7.2)") << "\n\n"
        << MotionConfusionMarkdown(confusion) << "\n";
  }
  return out.str();
}

MotionLabelTrainingResult RunMotionLabelTraining(const MotionLabelTrainingJob& job) {
  if (job.train.empty()) throw InputError("", "--train", "needs at least one sequence");
  if (job.window < 0 || job.window > 100) throw InputError("", "--window", "must be 0 to 100");
  if (job.ldcrf_states < 1 || job.ldcrf_states > 16) throw InputError("", "--ldcrf-states", "must be 1 to 16");
  const fs::path rest_path = job.rest_model.empty() ? DefaultRestModelPath() : job.rest_model;
  const RestClassifier rest = RestClassifier::Load(rest_path);
  std::vector<TrackedLabels> train, test;
  for (const fs::path& dir : job.train) train.push_back(Load(dir, rest, job.retrack));
  for (const fs::path& dir : job.test) test.push_back(Load(dir, rest, job.retrack));
  std::vector<std::pair<std::vector<MotionFeatures>, std::vector<int>>> chains;
  for (const TrackedLabels& s : train) {
    auto c = Chains(s);
    chains.insert(chains.end(), std::make_move_iterator(c.begin()), std::make_move_iterator(c.end()));
  }
  MotionLabelTrainingResult result;
  for (const auto& c : chains) result.train_frames += static_cast<int>(c.first.size());
  if (result.train_frames == 0) throw InputError("", "--train", "no tracked frame has a motion label");
  const fs::path out_dir = job.out_dir.empty() ? DefaultMotionLabelModelPath(MotionModelKind::kCrf).parent_path() : job.out_dir;
  fs::create_directories(out_dir);
  for (MotionModelKind kind : job.kinds) {
    const std::string name = MotionModelKindName(kind);
    const auto start = std::chrono::steady_clock::now();
    CrfTrainingReport report;
    auto model = std::make_shared<MotionLabelModel>(Fit(kind, chains, job, &report));
    result.train_seconds[name] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.reports[name] = report;
    model->provenance = Provenance(job, train, result.train_frames, rest_path, *model, report);
    const fs::path path = out_dir / ("motion_" + name + ".json");
    model->Save(path);
    result.models.push_back(path);
    for (const TrackedLabels& s : test) Evaluate(model, s, &result.evaluation.confusion[name]);
  }
  for (const TrackedLabels& s : test) {
    for (const auto& t : s.truth) result.evaluation.frames += t ? 2 : 0;
  }
  if (!job.table.empty() && !test.empty()) AtomicWriteFile(job.table, result.evaluation.Markdown());
  return result;
}

}  // namespace irbench
