#include "ci/train/gesture_training.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "ci/train/existing_track.h"
#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/logging.h"
#include "common/paths.h"
#include "common/progress.h"
#include "common/sha256.h"
#include "sequence_format/manifest.h"
#include "tracker/gesture/gesture_recognizer.h"
#include "tracker/io/sequence_input.h"
#include "tracker/pipeline/frame_tracker.h"

namespace irbench {
namespace {

namespace fs = std::filesystem;

// The six gestures of thesis 5.3 in its order (the sim's names).
const std::vector<std::string>& Gestures() {
  static const std::vector<std::string> names = {"point_horizontal", "flap_both",      "direct_traffic",
                                                 "raise_overhead",   "flap_one",       "point_diagonal_both"};
  return names;
}

// Thesis Tables 5.2 (FHMM) and 5.3 (HMM): identification rates (%) per
// gesture (rows, in Gestures() order) and person 1-5 (person 1 trained on).
constexpr double kThesisFhmm[6][5] = {{45, 50, 30.77, 23.08, 50.0},  {87.5, 87.5, 83.3, 88.9, 90.0},
                                      {100, 100, 25.0, 87.5, 100},   {100, 92.3, 75.0, 80.0, 100},
                                      {76.6, 66.6, 83.3, 100, 85.7}, {100, 100, 55.5, 100, 100}};
constexpr double kThesisHmm[6][5] = {{37.5, 50, 76.9, 44, 80.0},  {87.5, 87.5, 100, 55.5, 100},
                                     {41.6, 41.6, 0, 37.5, 66.6}, {80.0, 87.5, 75, 10, 91.6},
                                     {88.8, 88.8, 100, 100, 100}, {22.2, 22.2, 11.1, 7.8, 0}};

// A sequence as the tracker saw it: per frame its posture (or none) and
// whether its arms are at rest, and the truth's gesture spans.
struct TrackedSession {
  std::string person;
  std::string track;  // where the tracker's output came from
  std::vector<std::optional<GestureObservation>> frames;
  std::vector<bool> at_rest;  // as the online recogniser reads it (FrameTracker)
  struct Span {
    int gesture, first, last;
  };
  std::vector<Span> spans;

  // A span's frames as the online recogniser cuts a performance: from the
  // last frame at rest before its first frame with an arm raised to its
  // last such frame (the truth's span also holds the rest before and after
  // a performance, which the recogniser never sees); the whole span when no
  // arm is raised in it.
  std::vector<GestureObservation> Segment(const Span& s) const {
    const int n = static_cast<int>(frames.size());
    int first = std::max(0, s.first), last = std::min(s.last, n - 1);
    int raised_first = -1, raised_last = -1;
    for (int f = first; f <= last; ++f) {
      if (at_rest[f]) continue;
      if (raised_first < 0) raised_first = f;
      raised_last = f;
    }
    if (raised_first >= 0) first = std::max(0, raised_first - 1), last = raised_last;
    std::vector<GestureObservation> out;
    for (int f = first; f <= last; ++f) {
      if (frames[f]) out.push_back(*frames[f]);
    }
    return out;
  }
};

// The truth's gesture spans of a rendered session.
std::vector<TrackedSession::Span> GestureSpans(const fs::path& dir) {
  std::vector<TrackedSession::Span> spans;
  const fs::path events_file = dir / "truth" / "events.json";
  const JsonNode events = ParseJsonFile(events_file.string());
  for (size_t i = 0; i < events.Size(); ++i) {
    if (events[i].GetString("kind") != "gesture") continue;
    const std::string name = events[i].GetString("value");
    const auto it = std::find(Gestures().begin(), Gestures().end(), name);
    if (it == Gestures().end()) events[i]["value"].Fail("unknown gesture '" + name + "'");
    spans.push_back({static_cast<int>(it - Gestures().begin()), events[i].GetInt("start_frame"),
                     events[i].GetInt("end_frame")});
  }
  if (spans.empty()) throw InputError(events_file.string(), "", "no gesture events: not a gesture session");
  return spans;
}

// A track.jsonl line's posture (weights as track.jsonl rounds them, to 4
// decimals), or nullopt for none; an atom the line lacks weighs 0.
std::optional<GestureObservation> PostureOfTrackLine(const nlohmann::json& line, const PostureAtoms& atoms) {
  if (!line.is_object() || !line.contains("posture") || !line["posture"].is_object()) return std::nullopt;
  const nlohmann::json& posture = line["posture"];
  if (!posture.contains("pair") || !posture["pair"].is_array() || posture["pair"].size() != 2 ||
      !posture.contains("weights") || !posture["weights"].is_object()) {
    return std::nullopt;
  }
  auto index = [&](const nlohmann::json& name) {
    const auto it = name.is_string() ? std::find(atoms.names.begin(), atoms.names.end(), name.get<std::string>())
                                     : atoms.names.end();
    return it == atoms.names.end() ? -1 : static_cast<int>(it - atoms.names.begin());
  };
  GestureObservation o;
  o.secondary = index(posture["pair"][0]);
  o.primary = index(posture["pair"][1]);
  if (o.primary < 0 || o.secondary < 0) return std::nullopt;
  o.weights = Eigen::VectorXd::Zero(static_cast<int>(atoms.names.size()));
  for (size_t k = 0; k < atoms.names.size(); ++k) {
    const auto w = posture["weights"].find(atoms.names[k]);
    if (w != posture["weights"].end() && w->is_number()) o.weights[static_cast<int>(k)] = w->get<double>();
  }
  return o;
}

// The session as the tracker saw it: from its track/ when that was made with
// these posture atoms (`atoms_sha256`, and `retrack` is off), else tracked here.
TrackedSession Track(const fs::path& dir, const fs::path& atoms, const std::string& atoms_sha256,
                     const PostureAtoms& atom_model, bool retrack) {
  TrackedSession s;
  const Manifest manifest = ReadManifest(dir);
  s.person = manifest.avatar.empty() ? dir.filename().string() : manifest.avatar;
  s.spans = GestureSpans(dir);
  ExistingTrackMiss miss = ExistingTrackMiss::kNone;
  if (std::optional<ExistingTrack> existing =
          retrack ? std::nullopt
                  : ReadExistingTrack(dir, manifest.frame_count, {{"posture_atoms", atoms_sha256}}, &miss)) {
    Log().info("train gestures: {}: using its track/", dir.filename().string());
    s.track = "track/";
    for (const nlohmann::json& line : existing->lines) {
      s.frames.push_back(PostureOfTrackLine(line, atom_model));
      std::optional<bool> right, left;
      if (line.contains("rest") && line["rest"].is_object()) {
        const nlohmann::json& r = line["rest"];
        if (r.contains("right") && r["right"].is_boolean()) right = r["right"].get<bool>();
        if (r.contains("left") && r["left"].is_boolean()) left = r["left"].get<bool>();
      }
      s.at_rest.push_back(BothArmsAtRest(right, left, s.frames.back()));
    }
    return s;
  }
  if (miss == ExistingTrackMiss::kOtherModels) {
    Log().info("train gestures: {}: its track/ was made with other posture atoms: tracking it again",
               dir.filename().string());
  }
  s.track = "tracked by irbench train gestures";
  const SequenceInput input = SequenceInput::Open(dir);
  TrackerSettings settings;
  settings.posture_atoms = atoms;
  FrameTracker tracker(input, settings, EffectiveFrontEndOptions(settings), LoadRestClassifier(settings));
  Progress progress("train gestures: " + dir.filename().string(), "frame-sets", input.frame_count());
  for (int f = 0; f < input.frame_count(); ++f) {
    std::vector<std::string> problems;
    const FrameTracker::Step step = tracker.Track(f, input.TryFrameSet(f, &problems), problems, 1.0 / input.fps());
    progress.Set(f + 1, "frame");
    const std::optional<bool> right = step.pose ? step.pose->rest[0] : std::nullopt;
    const std::optional<bool> left = step.pose ? step.pose->rest[1] : std::nullopt;
    if (!step.posture) {
      s.frames.push_back(std::nullopt);
      s.at_rest.push_back(BothArmsAtRest(right, left, std::nullopt));
      continue;
    }
    GestureObservation o;
    o.weights = Eigen::Map<const Eigen::VectorXd>(step.posture->weights.data(), step.posture->weights.size());
    o.primary = step.posture->pair[1];
    o.secondary = step.posture->pair[0];
    s.frames.push_back(o);
    s.at_rest.push_back(BothArmsAtRest(right, left, o));
  }
  return s;
}

std::vector<std::vector<std::vector<GestureObservation>>> SegmentsOf(const std::vector<const TrackedSession*>& sessions) {
  std::vector<std::vector<std::vector<GestureObservation>>> segments(Gestures().size());
  for (const TrackedSession* s : sessions) {
    for (const auto& span : s->spans) {
      std::vector<GestureObservation> seg = s->Segment(span);
      if (!seg.empty()) segments[span.gesture].push_back(std::move(seg));
    }
  }
  return segments;
}

// The models of the gestures the sessions perform (a warning for the others).
GestureModels TrainPresent(const std::vector<std::string>& atoms, const std::vector<const TrackedSession*>& sessions,
                           const GestureTrainingOptions& options) {
  const auto segments = SegmentsOf(sessions);
  std::vector<std::string> names;
  std::vector<std::vector<std::vector<GestureObservation>>> present;
  for (size_t g = 0; g < segments.size(); ++g) {
    if (segments[g].empty()) {
      Log().warn("train gestures: no performance of {} to train on; it is left out", Gestures()[g]);
      continue;
    }
    names.push_back(Gestures()[g]);
    present.push_back(segments[g]);
  }
  if (names.empty()) throw InputError("", "--train", "the sessions perform no gesture");
  return GestureModels::Train(names, atoms, present, options);
}

void Evaluate(const GestureModels& models, const TrackedSession& test, GestureEvaluation* e) {
  for (GestureModelKind kind : {GestureModelKind::kHmm, GestureModelKind::kParallelHmm, GestureModelKind::kFactorialHmm}) {
    const std::string k = GestureModelKindName(kind);
    for (const auto& span : test.spans) {
      const std::vector<GestureObservation> seg = test.Segment(span);
      const std::string& truth = Gestures()[span.gesture];
      auto& c = e->counts[k][test.person][truth];
      ++c.second;
      if (seg.empty()) {
        ++e->confusion[k][truth]["(no posture)"];
        continue;
      }
      const std::string found = models.gestures[models.Classify(kind, seg)];
      c.first += found == truth;
      ++e->confusion[k][truth][found];
    }
  }
}

std::string Percent(double v) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%.1f", v);
  return buf;
}

}  // namespace

double GestureEvaluation::MeanRate(const std::string& kind) const {
  const auto k = counts.find(kind);
  if (k == counts.end() || k->second.empty()) return 0;
  double sum = 0;
  for (const auto& [person, per_gesture] : k->second) {
    double rates = 0;
    int n = 0;
    for (const auto& [g, c] : per_gesture) {
      if (c.second == 0) continue;
      rates += double(c.first) / c.second;
      ++n;
    }
    sum += n ? rates / n : 0;
  }
  return sum / k->second.size();
}

std::string GestureEvaluation::Markdown() const {
  std::ostringstream out;
  for (const auto& [kind, per_person] : counts) {
    out << "**" << kind << "**: identification rate (%) per gesture and test person; mean over persons "
        << Percent(100 * MeanRate(kind)) << "%";
    if (kind == "fhmm" || kind == "hmm") out << " (thesis, persons 2-5: " << (kind == "fhmm" ? "Table 5.2" : "Table 5.3") << ")";
    out << "\n\n| Gesture |";
    for (const auto& [person, _] : per_person) out << " " << person << " |";
    if (kind == "fhmm" || kind == "hmm") out << " thesis |";
    out << "\n|---|";
    for (size_t i = 0; i < per_person.size(); ++i) out << "---|";
    if (kind == "fhmm" || kind == "hmm") out << "---|";
    out << "\n";
    for (size_t g = 0; g < Gestures().size(); ++g) {
      out << "| " << g + 1 << " " << Gestures()[g] << " |";
      for (const auto& [person, per_gesture] : per_person) {
        const auto c = per_gesture.find(Gestures()[g]);
        if (c == per_gesture.end() || c->second.second == 0) {
          out << " – |";
        } else {
          out << " " << Percent(100.0 * c->second.first / c->second.second) << " (" << c->second.first << "/"
              << c->second.second << ") |";
        }
      }
      if (kind == "fhmm" || kind == "hmm") {
        const auto& t = kind == "fhmm" ? kThesisFhmm : kThesisHmm;
        out << " " << Percent((t[g][1] + t[g][2] + t[g][3] + t[g][4]) / 4) << " |";
      }
      out << "\n";
    }
    out << "\nConfusion (" << kind << "; rows truth, columns recognised):\n\n| |";
    std::vector<std::string> cols = Gestures();
    cols.push_back("(no posture)");
    for (const auto& c : cols) out << " " << c << " |";
    out << "\n|---|";
    for (size_t i = 0; i < cols.size(); ++i) out << "---|";
    out << "\n";
    const auto& conf = confusion.at(kind);
    for (const std::string& t : Gestures()) {
      const auto row = conf.find(t);
      if (row == conf.end()) continue;
      out << "| " << t << " |";
      for (const auto& c : cols) {
        const auto n = row->second.find(c);
        out << " " << (n == row->second.end() ? 0 : n->second) << " |";
      }
      out << "\n";
    }
    out << "\n";
  }
  return out.str();
}

GestureTrainingResult RunGestureTraining(const GestureTrainingJob& job) {
  if (job.train.empty()) throw InputError("", "--train", "give at least one rendered gesture session");
  const fs::path atoms = job.posture_atoms.empty() ? DefaultPostureAtomsPath() : job.posture_atoms;
  if (!fs::exists(atoms)) {
    throw InputError(atoms.string(), "", "no posture atoms (irbench train atoms writes them)");
  }
  const PostureAtoms atom_model = PostureAtoms::Load(atoms);
  std::vector<TrackedSession> train, test;
  const std::string atoms_sha256 = Sha256OfFile(atoms);
  for (const fs::path& dir : job.train) train.push_back(Track(dir, atoms, atoms_sha256, atom_model, job.retrack));
  for (const fs::path& dir : job.test) test.push_back(Track(dir, atoms, atoms_sha256, atom_model, job.retrack));
  std::vector<const TrackedSession*> all;
  for (const auto& s : train) all.push_back(&s);
  GestureTrainingResult result;
  for (size_t i = 0; i < job.train.size(); ++i) result.tracks[job.train[i].filename().string()] = train[i].track;
  for (size_t i = 0; i < job.test.size(); ++i) result.tracks[job.test[i].filename().string()] = test[i].track;
  GestureModels models = TrainPresent(atom_model.names, all, job.options);
  for (const auto& per_gesture : SegmentsOf(all)) result.segments += static_cast<int>(per_gesture.size());
  result.evaluation.gestures = models.gestures;
  if (job.leave_one_out) {
    for (size_t q = 0; q < train.size(); ++q) {
      std::vector<const TrackedSession*> others;
      for (size_t r = 0; r < train.size(); ++r) {
        if (r != q) others.push_back(&train[r]);
      }
      const GestureModels held = TrainPresent(atom_model.names, others, job.options);
      Evaluate(held, train[q], &result.evaluation);
    }
  } else {
    for (const auto& t : test) Evaluate(models, t, &result.evaluation);
  }
  nlohmann::json persons = nlohmann::json::array();
  for (const auto& s : train) persons.push_back(s.person);
  models.provenance = {{"made_by", "irbench train gestures"},
                       {"tool_version", ToolVersion()},
                       {"trained_on", persons},
                       {"sequences", [&] {
                          nlohmann::json a = nlohmann::json::array();
                          for (const fs::path& p : job.train) a.push_back(p.filename().string());
                          return a;
                        }()},
                       {"tracks", [&] {
                          nlohmann::json a = nlohmann::json::object();
                          for (size_t i = 0; i < job.train.size(); ++i) a[job.train[i].filename().string()] = train[i].track;
                          return a;
                        }()},
                       {"segments", result.segments},
                       {"posture_atoms", atoms.filename().string()},
                       {"options",
                        {{"hmm_states", job.options.hmm_states},
                         {"chain_states", job.options.chain_states},
                         {"restarts", job.options.restarts},
                         {"max_iterations", job.options.max_iterations},
                         {"covariance_ridge", job.options.covariance_ridge},
                         {"pseudo_count", job.options.pseudo_count},
                         {"observation", GestureObservationKindName(job.options.observation)},
                         {"pair_scale", job.options.pair_scale},
                         {"seed", job.options.seed}}}};
  result.model = job.out.empty() ? DefaultGestureModelsPath() : job.out;
  models.Save(result.model);
  if (!job.table.empty() && !result.evaluation.counts.empty()) AtomicWriteFile(job.table, result.evaluation.Markdown());
  return result;
}

}  // namespace irbench
