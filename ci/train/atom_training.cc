#include "ci/train/atom_training.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <spdlog/fmt/fmt.h>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/logging.h"
#include "common/paths.h"
#include "common/progress.h"
#include "sequence_format/frame_lines.h"
#include "sequence_format/manifest.h"
#include "sim/motion/posture_candidates.h"
#include "tracker/io/sequence_input.h"
#include "tracker/pipeline/frame_tracker.h"
#include "tracker/posture/atom_selection.h"
#include "tracker/posture/decompose.h"

namespace irbench {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string>& AtomNames() {
  static const std::vector<std::string> names = {"A0", "A1", "A2", "A3", "A4"};
  return names;
}

// A unit-length descriptor by its non-zero bins.
struct SparseDescriptor {
  std::vector<int> index;
  std::vector<float> value;
  std::vector<float> Dense(int bins) const {
    std::vector<float> d(bins, 0.0f);
    for (size_t i = 0; i < index.size(); ++i) d[index[i]] = value[i];
    return d;
  }
};

// One training sequence (one person) as the tracker saw it.
struct TrainingSequence {
  std::string name;
  nlohmann::json about;  // for the provenance
  std::vector<SparseDescriptor> frames;
  std::vector<std::array<int, 2>> pairs;  // the truth's, atom indices in order
  std::vector<int> frame_index;           // each frame's number in the sequence
  double fps = 0;
  std::vector<float> own_rest;            // the person's resting posture, unit length
};

int AtomIndex(const std::string& name, const fs::path& file, int frame) {
  const auto& names = AtomNames();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    throw InputError(file.string(), "frame " + std::to_string(frame) + ".labels.posture",
                     "unknown atom '" + name + "'");
  }
  return static_cast<int>(it - names.begin());
}

// Runs the tracker over `dir` and pairs its descriptors with the truth.
TrainingSequence ReadSequence(const fs::path& dir, const ShapeDescriptorOptions& shape) {
  TrainingSequence s;
  s.name = dir.filename().string();
  const Manifest manifest = ReadManifest(dir);
  s.about = {{"name", s.name}, {"avatar", manifest.avatar}, {"motion", manifest.motion},
             {"sensor", manifest.sensor}, {"rig", manifest.rig}, {"seed", manifest.seed}};
  const fs::path truth_file = dir / "truth" / "frames.jsonl";
  const std::map<int, nlohmann::json> truth = ReadFrameLines(truth_file);
  const SequenceInput input = SequenceInput::Open(dir);
  s.fps = input.fps();
  TrackerSettings settings;
  FrameTracker tracker(input, settings, EffectiveFrontEndOptions(settings), LoadRestClassifier(settings));
  const int bins = shape.bin_count();
  std::vector<double> rest_sum(bins, 0.0);
  int rest_frames = 0;
  Progress progress("train atoms: " + s.name, "frame-sets", input.frame_count());
  for (int f = 0; f < input.frame_count(); ++f) {
    std::vector<std::string> problems;
    const FrameTracker::Step step = tracker.Track(f, input.TryFrameSet(f, &problems), problems, 1.0 / input.fps());
    progress.Set(f + 1, "frame");
    const auto t = truth.find(f);
    if (!step.shape || step.shape->point_count == 0 || t == truth.end()) continue;
    const nlohmann::json& posture = t->second["labels"]["posture"];
    if (!posture.is_array() || posture.size() != 2) {
      throw InputError(truth_file.string(), "frame " + std::to_string(f) + ".labels.posture", "must be two atoms");
    }
    const int a = AtomIndex(posture[0].get<std::string>(), truth_file, f);
    const int b = AtomIndex(posture[1].get<std::string>(), truth_file, f);
    double norm = 0;
    for (float v : step.shape->bins) norm += double(v) * v;
    norm = std::sqrt(norm);
    SparseDescriptor d;
    for (int i = 0; i < bins; ++i) {
      if (step.shape->bins[i] == 0) continue;
      d.index.push_back(i);
      d.value.push_back(static_cast<float>(step.shape->bins[i] / norm));
    }
    if (a == 0 && b == 0) {
      for (size_t i = 0; i < d.index.size(); ++i) rest_sum[d.index[i]] += d.value[i];
      ++rest_frames;
    }
    s.frames.push_back(std::move(d));
    s.pairs.push_back({std::min(a, b), std::max(a, b)});
    s.frame_index.push_back(f);
  }
  if (rest_frames == 0) throw InputError(dir.string(), "truth", "the person is never at rest with both arms");
  double norm = 0;
  for (double v : rest_sum) norm += v * v;
  s.own_rest.resize(bins);
  for (int i = 0; i < bins; ++i) s.own_rest[i] = static_cast<float>(rest_sum[i] / std::sqrt(norm));
  return s;
}

std::vector<double> ArmWeights(const PostureAtoms& atoms, const std::vector<float>& residual) {
  return atoms.weights == AtomWeights::kMatchingPursuit
             ? MatchingPursuitWeights(residual, atoms.arms, atoms.iterations, atoms.overlap_threshold)
             : NonNegativeWeights(residual, atoms.arms);
}

// Every frame's arm weights under `atoms`, the person's own rest subtracted.
std::vector<std::vector<double>> Weights(const PostureAtoms& atoms, const TrainingSequence& s) {
  std::vector<std::vector<double>> w;
  for (const SparseDescriptor& d : s.frames) {
    double alpha0 = 0;
    w.push_back(ArmWeights(atoms, RestResidual(d.Dense(atoms.descriptor.bin_count()), s.own_rest, &alpha0)));
  }
  return w;
}

double Accuracy(const PostureAtoms& atoms, const std::vector<const TrainingSequence*>& seqs,
                const std::vector<std::vector<std::vector<double>>>& weights) {
  long right = 0, total = 0;
  for (size_t q = 0; q < seqs.size(); ++q) {
    for (size_t f = 0; f < seqs[q]->frames.size(); ++f) {
      right += PairFromWeights(weights[q][f], atoms) == seqs[q]->pairs[f];
      ++total;
    }
  }
  return total ? double(right) / total : 0.0;
}

// Steps 2-3 from the sequences `train`.
PostureAtoms Fit(const std::vector<const TrainingSequence*>& train, const AtomTrainingOptions& options,
                 const ShapeDescriptorOptions& shape) {
  PostureAtoms atoms;
  atoms.descriptor = shape;
  atoms.names = AtomNames();
  atoms.weights = options.weights;
  atoms.rule = options.rule;
  atoms.pair_rest_state = options.pair_rest_state;
  const int bins = shape.bin_count();
  // A0: the persons' resting postures, averaged.
  std::vector<double> rest(bins, 0.0);
  for (const TrainingSequence* s : train) {
    for (int i = 0; i < bins; ++i) rest[i] += s->own_rest[i];
  }
  double norm = 0;
  for (double v : rest) norm += v * v;
  atoms.rest.resize(bins);
  for (int i = 0; i < bins; ++i) atoms.rest[i] = static_cast<float>(rest[i] / std::sqrt(norm));
  // The arm atoms: mean residuals of the one-arm frames.
  for (int k = 1; k < static_cast<int>(atoms.names.size()); ++k) {
    std::vector<double> sum(bins, 0.0);
    int count = 0;
    for (const TrainingSequence* s : train) {
      for (size_t f = 0; f < s->frames.size(); ++f) {
        if (s->pairs[f] != std::array<int, 2>{0, k}) continue;
        double alpha0 = 0;
        const std::vector<float> r = RestResidual(s->frames[f].Dense(bins), s->own_rest, &alpha0);
        for (int i = 0; i < bins; ++i) sum[i] += r[i];
        ++count;
      }
    }
    if (count == 0) {
      throw InputError(train.front()->name, "truth", "no frame shows one arm in atom " + atoms.names[k]);
    }
    std::vector<float> arm(bins);
    for (int i = 0; i < bins; ++i) arm[i] = static_cast<float>(sum[i] / count);
    atoms.arms.push_back(arm);
  }
  // Scale each atom so that one arm in its posture weighs 1 on average (alpha'_i).
  std::vector<std::vector<std::vector<double>>> weights;
  for (const TrainingSequence* s : train) weights.push_back(Weights(atoms, *s));
  for (size_t k = 0; k < atoms.arms.size(); ++k) {
    double sum = 0;
    int count = 0;
    for (size_t q = 0; q < train.size(); ++q) {
      for (size_t f = 0; f < train[q]->frames.size(); ++f) {
        if (train[q]->pairs[f] != std::array<int, 2>{0, static_cast<int>(k) + 1}) continue;
        sum += weights[q][f][k];
        ++count;
      }
    }
    const double scale = count && sum > 0 ? sum / count : 1.0;
    for (float& v : atoms.arms[k]) v = static_cast<float>(v * scale);
  }
  weights.clear();
  for (const TrainingSequence* s : train) weights.push_back(Weights(atoms, *s));
  // The centroids of every pair's weights.
  std::map<std::array<int, 2>, std::pair<std::vector<double>, int>> sums;
  for (size_t q = 0; q < train.size(); ++q) {
    for (size_t f = 0; f < train[q]->frames.size(); ++f) {
      auto& [sum, count] = sums[train[q]->pairs[f]];
      sum.resize(atoms.arms.size(), 0.0);
      for (size_t k = 0; k < sum.size(); ++k) sum[k] += weights[q][f][k];
      ++count;
    }
  }
  for (auto& [pair, sc] : sums) {
    for (double& v : sc.first) v /= sc.second;
    atoms.centroids.emplace_back(PairName(pair, atoms), sc.first);
  }
  // Their pooled within-pair covariance, inverted (a small ridge keeps it so).
  const int k = static_cast<int>(atoms.arms.size());
  Eigen::MatrixXd scatter = Eigen::MatrixXd::Zero(k, k);
  long samples = 0;
  for (size_t q = 0; q < train.size(); ++q) {
    for (size_t f = 0; f < train[q]->frames.size(); ++f) {
      const std::vector<double>& mean = sums.at(train[q]->pairs[f]).first;
      Eigen::VectorXd d(k);
      for (int i = 0; i < k; ++i) d(i) = weights[q][f][i] - mean[i];
      scatter += d * d.transpose();
      ++samples;
    }
  }
  const Eigen::MatrixXd covariance = scatter / std::max<long>(samples - 1, 1) + 1e-4 * Eigen::MatrixXd::Identity(k, k);
  const Eigen::MatrixXd precision = covariance.inverse();
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) atoms.centroid_precision.push_back(precision(i, j));
  }
  // The thresholds: the best on the training frames.
  const PairRule rule = atoms.rule;
  atoms.rule = PairRule::kThresholds;
  double best = -1;
  double best_presence = atoms.presence, best_instance = atoms.instance;
  for (double presence = 0.2; presence < 0.81; presence += 0.05) {
    for (double instance = 1.2; instance < 2.21; instance += 0.1) {
      atoms.presence = presence;
      atoms.instance = instance;
      const double acc = Accuracy(atoms, train, weights);
      if (acc > best + 1e-12) best = acc, best_presence = presence, best_instance = instance;
    }
  }
  atoms.presence = std::round(best_presence * 100) / 100;
  atoms.instance = std::round(best_instance * 100) / 100;
  atoms.rule = rule;
  return atoms;
}

double AccuracyOn(const PostureAtoms& atoms, const std::vector<const TrainingSequence*>& seqs) {
  std::vector<std::vector<std::vector<double>>> weights;
  for (const TrainingSequence* s : seqs) weights.push_back(Weights(atoms, *s));
  return Accuracy(atoms, seqs, weights);
}

// One person's candidate postures: each `posture_candidate` event's hold,
// less a tenth of a second at either end (the arm still settling), as the
// mean rest residual of its frames, and the truth's pairs over them.
struct PersonCandidates {
  std::map<std::string, std::vector<double>> residual_sum;
  std::map<std::string, int> frames;
  std::map<std::string, std::map<std::array<int, 2>, int>> pairs;
};

PersonCandidates ReadCandidates(const fs::path& dir, const TrainingSequence& s, int bins) {
  const fs::path events_file = dir / "truth" / "events.json";
  const JsonNode events = ParseJsonFile(events_file.string());
  std::map<int, size_t> by_frame;
  for (size_t i = 0; i < s.frame_index.size(); ++i) by_frame[s.frame_index[i]] = i;
  const int trim = static_cast<int>(std::lround(0.1 * s.fps));
  PersonCandidates p;
  for (size_t e = 0; e < events.Size(); ++e) {
    if (events[e].GetString("kind") != "posture_candidate") continue;
    const std::string name = events[e].GetString("value");
    const int first = events[e].GetInt("start_frame"), last = events[e].GetInt("end_frame");
    if (last < first) events[e]["end_frame"].Fail("ends before it starts");
    std::vector<double>& sum = p.residual_sum[name];
    sum.resize(bins, 0.0);
    int& count = p.frames[name];
    for (int f = first + trim; f <= last - trim; ++f) {
      const auto it = by_frame.find(f);
      if (it == by_frame.end()) continue;
      double alpha0 = 0;
      const std::vector<float> r = RestResidual(s.frames[it->second].Dense(bins), s.own_rest, &alpha0);
      for (int i = 0; i < bins; ++i) sum[i] += r[i];
      ++count;
      ++p.pairs[name][s.pairs[it->second]];
    }
  }
  if (p.residual_sum.empty()) {
    throw InputError(events_file.string(), "", "no posture_candidate events: not a rendering of "
                                               "irbench render --motion posture_candidates");
  }
  for (auto& [name, sum] : p.residual_sum) {
    if (p.frames[name] == 0) throw InputError(events_file.string(), name, "no tracked frame in its hold");
    for (double& v : sum) v /= p.frames[name];
  }
  return p;
}

// `vectors` (of one size) as the columns of a matrix, each at unit length.
Eigen::MatrixXd UnitColumns(const std::vector<std::vector<float>>& vectors) {
  Eigen::MatrixXd a(static_cast<int>(vectors.front().size()), static_cast<int>(vectors.size()));
  for (int k = 0; k < a.cols(); ++k) {
    a.col(k) = Eigen::Map<const Eigen::VectorXf>(vectors[k].data(), a.rows()).cast<double>().normalized();
  }
  return a;
}

// How well `vectors` stand for the candidates (unit columns of `c`): the
// share of c's Frobenius norm outside their span, and the largest cosine
// between two of them (the thesis wants atoms that do not compete).
void SpanAndOverlap(const Eigen::MatrixXd& c, const std::vector<std::vector<float>>& vectors, double* residual,
                    double* overlap) {
  const Eigen::MatrixXd a = UnitColumns(vectors);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(a);
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(a.rows(), a.cols());
  *residual = (c - q * (q.transpose() * c)).norm() / c.norm();
  *overlap = 0;
  for (int i = 0; i < a.cols(); ++i) {
    for (int j = i + 1; j < a.cols(); ++j) *overlap = std::max(*overlap, a.col(i).dot(a.col(j)));
  }
}

// The selection among the candidate renders' postures (5.1.2), each
// candidate named by the truth's atom for its posture, and compared with
// `atoms` (trained from the truth's atoms); `about` gets it for the model
// file's provenance.
AtomSelectionSummary SelectFromCandidates(const AtomTrainingOptions& options, const ShapeDescriptorOptions& shape,
                                          const PostureAtoms& atoms, nlohmann::json* about) {
  const int bins = shape.bin_count();
  std::vector<PersonCandidates> persons;
  nlohmann::json sequences = nlohmann::json::array();
  for (const fs::path& dir : options.candidates) {
    if (!HasManifest(dir)) throw InputError(dir.string(), "manifest.json", "not a rendered sequence");
    const TrainingSequence seq = ReadSequence(dir, shape);
    persons.push_back(ReadCandidates(dir, seq, bins));
    if (persons.back().residual_sum.size() != persons.front().residual_sum.size()) {
      throw InputError(dir.string(), "truth/events.json",
                       "holds other candidates than " + options.candidates.front().string());
    }
    sequences.push_back(seq.about);
  }
  AtomSelectionSummary summary;
  std::vector<std::vector<float>> parts;
  const std::vector<std::string> descriptions = PostureCandidateDescriptions();
  for (const auto& [name, unused] : persons.front().residual_sum) {
    std::vector<double> mean(bins, 0.0);
    std::map<std::array<int, 2>, int> pairs;
    for (size_t q = 0; q < persons.size(); ++q) {
      const auto it = persons[q].residual_sum.find(name);
      if (it == persons[q].residual_sum.end()) {
        throw InputError(options.candidates[q].string(), "truth/events.json",
                         "holds other candidates than " + options.candidates.front().string());
      }
      for (int i = 0; i < bins; ++i) mean[i] += it->second[i] / persons.size();
      for (const auto& [pair, n] : persons[q].pairs[name]) pairs[pair] += n;
    }
    const auto most = std::max_element(pairs.begin(), pairs.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    AtomSelectionSummary::Candidate c;
    c.name = name;
    const int number = std::atoi(name.c_str() + 1);
    c.about = number >= 1 && number <= static_cast<int>(descriptions.size()) ? descriptions[number - 1] : "";
    c.atom = most->first[1];
    parts.emplace_back(mean.begin(), mean.end());
    summary.candidates.push_back(c);
  }
  const int count = atoms.atom_count() - 1;
  if (static_cast<int>(parts.size()) < count) {
    throw InputError(options.candidates.front().string(), "truth/events.json",
                     "fewer candidates than the " + std::to_string(count) + " arm atoms");
  }
  const AtomSelection sel = SelectAtoms(parts, count, atoms.overlap_threshold);
  summary.weights = sel.weights;
  summary.singular_values = sel.singular_values;
  summary.selected = sel.selected;
  // Against the truth's atoms: how much of the candidates each set spans.
  const Eigen::MatrixXd c = UnitColumns(parts);
  std::vector<std::vector<float>> chosen;
  for (int i : sel.selected) chosen.push_back(parts[i]);
  SpanAndOverlap(c, chosen, &summary.selected_residual, &summary.selected_overlap);
  SpanAndOverlap(c, atoms.arms, &summary.atoms_residual, &summary.atoms_overlap);
  const Eigen::VectorXd sc = Eigen::BDCSVD<Eigen::MatrixXd>(c).singularValues();
  summary.best_residual = std::sqrt(sc.tail(sc.size() - count).squaredNorm() / sc.squaredNorm());
  const Eigen::VectorXd& sv = sel.singular_values;
  std::set<int> named;
  for (int i : sel.selected) named.insert(summary.candidates[i].atom);
  summary.one_per_atom = static_cast<int>(named.size()) == count && !named.count(0);

  nlohmann::json selected = nlohmann::json::array();
  for (int i : sel.selected) {
    selected.push_back({{"candidate", summary.candidates[i].name}, {"about", summary.candidates[i].about},
                        {"truth_atom", AtomNames()[summary.candidates[i].atom]}});
  }
  std::vector<double> singular;
  for (int i = 0; i < sv.size(); ++i) singular.push_back(std::round(sv(i) * 1e4) / 1e4);
  const auto r4 = [](double v) { return std::round(v * 1e4) / 1e4; };
  *about = {{"method", "thesis 5.1.2: each candidate's mean rest residual, the matrix of their pairwise "
                       "matching-pursuit weights, its SVD, the candidates pivoted first by a column-pivoted QR "
                       "of the leading right singular vectors; reported beside the atoms, which stay the truth's"},
            {"candidate_sequences", sequences},
            {"candidates", summary.candidates.size()},
            {"singular_values", singular},
            {"selected", selected},
            {"one_per_truth_atom", summary.one_per_atom},
            {"unspanned_share", {{"selected", r4(summary.selected_residual)}, {"atoms", r4(summary.atoms_residual)}}},
            {"largest_cosine", {{"selected", r4(summary.selected_overlap)}, {"atoms", r4(summary.atoms_overlap)}}}};
  return summary;
}

void CheckSelectionTable(const AtomTrainingOptions& options) {
  if (options.selection_table.empty()) return;
  if (options.candidates.empty()) {
    throw InputError("", "--selection-table", "there is a selection only with --candidates");
  }
  std::vector<fs::path> inputs = options.sequences;
  inputs.insert(inputs.end(), options.candidates.begin(), options.candidates.end());
  CheckOutputApart(options.selection_table, inputs, "--selection-table");
}

}  // namespace

std::string AtomSelectionSummary::Markdown() const {
  std::string md = "# Posture atoms selected among " + std::to_string(candidates.size()) +
                   " candidates (thesis 5.1.2)\n\n"
                   "M(i, j): the weight of candidate j when candidate i is decomposed by matching pursuit with j "
                   "as its only atom (each candidate its mean rest residual, at unit length). The atoms are the "
                   "first pivots of a column-pivoted QR of M's leading right singular vectors.\n\n"
                   "## Selected\n\n| order | candidate | posture | truth's atom |\n|---|---|---|---|\n";
  for (size_t o = 0; o < selected.size(); ++o) {
    const Candidate& c = candidates[selected[o]];
    md += fmt::format("| {} | {} | {} | {} |\n", o + 1, c.name, c.about, AtomNames()[c.atom]);
  }
  md += fmt::format(
      "\nOne candidate per truth atom (A1..A4): {}. The trained atoms stay the truth's (its posture labels name "
      "them).\n\n| | share of the candidates outside their span | largest cosine between two |\n|---|---|---|\n"
      "| the selected candidates | {:.3f} | {:.3f} |\n| the truth's atoms, as trained | {:.3f} | {:.3f} |\n"
      "| the best rank-{} approximation (SVD) | {:.3f} | |\n",
      one_per_atom ? "yes" : "no", selected_residual, selected_overlap, atoms_residual, atoms_overlap,
      selected.size(), best_residual);
  md += "\n## Singular values of M (Fig. 5.2)\n\n| k | singular value | share of the sum of squares |\n|---|---|---|\n";
  const double total = singular_values.squaredNorm();
  for (int k = 0; k < singular_values.size(); ++k) {
    md += fmt::format("| {} | {:.4f} | {:.1f}% |\n", k + 1, singular_values(k),
                      total > 0 ? 100 * singular_values(k) * singular_values(k) / total : 0.0);
  }
  md += "\n## Candidates\n\n| candidate | posture | truth's atom |\n|---|---|---|\n";
  for (const Candidate& c : candidates) md += fmt::format("| {} | {} | {} |\n", c.name, c.about, AtomNames()[c.atom]);
  md += "\n## M (Fig. 5.1)\n\n|   |";
  for (const Candidate& c : candidates) md += " " + c.name + " |";
  md += "\n|---|";
  for (size_t j = 0; j < candidates.size(); ++j) md += "---|";
  md += "\n";
  for (size_t i = 0; i < candidates.size(); ++i) {
    md += "| " + candidates[i].name + " |";
    for (size_t j = 0; j < candidates.size(); ++j) md += fmt::format(" {:.2f} |", weights(int(i), int(j)));
    md += "\n";
  }
  return md;
}

AtomTrainingResult RunAtomTraining(const AtomTrainingOptions& options) {
  if (options.sequences.empty()) throw InputError("", "SEQ", "give at least one rendered sequence");
  CheckSelectionTable(options);
  const ShapeDescriptorOptions shape;
  std::vector<TrainingSequence> seqs;
  for (const fs::path& dir : options.sequences) {
    if (!HasManifest(dir)) throw InputError(dir.string(), "manifest.json", "not a rendered sequence");
    seqs.push_back(ReadSequence(dir, shape));
    Log().info("train atoms: {}: {} frames", seqs.back().name, seqs.back().frames.size());
  }
  std::vector<const TrainingSequence*> all;
  for (const auto& s : seqs) all.push_back(&s);
  AtomTrainingResult result;
  for (const auto& s : seqs) result.frames += static_cast<int>(s.frames.size());
  PostureAtoms atoms = Fit(all, options, shape);
  result.training_accuracy = AccuracyOn(atoms, all);
  if (options.cross_validate && seqs.size() > 1) {
    for (size_t q = 0; q < seqs.size(); ++q) {
      std::vector<const TrainingSequence*> others;
      for (size_t r = 0; r < seqs.size(); ++r) {
        if (r != q) others.push_back(&seqs[r]);
      }
      const PostureAtoms held = Fit(others, options, shape);
      result.held_out.emplace_back(seqs[q].name, AccuracyOn(held, {&seqs[q]}));
      Log().info("train atoms: {} held out: {:.1f}% of its frames' pairs right", seqs[q].name,
                 100 * result.held_out.back().second);
    }
  }
  nlohmann::json sequences = nlohmann::json::array();
  for (const auto& s : seqs) sequences.push_back(s.about);
  nlohmann::json held_out = nlohmann::json::object();
  for (const auto& [name, acc] : result.held_out) held_out[name] = std::round(acc * 1e4) / 1e4;
  atoms.provenance = {{"made_by", "irbench train atoms"},
                      {"tool_version", ToolVersion()},
                      {"sequences", sequences},
                      {"frames", result.frames},
                      {"rest", "each person's own: the mean descriptor over the truth's both-arms-at-rest frames"},
                      {"training_accuracy", std::round(result.training_accuracy * 1e4) / 1e4},
                      {"held_out_accuracy", held_out}};
  if (!options.candidates.empty()) {
    nlohmann::json about;
    result.selection = SelectFromCandidates(options, shape, atoms, &about);
    atoms.provenance["selection"] = about;
  }
  result.model = options.out.empty() ? DefaultPostureAtomsPath() : options.out;
  atoms.Save(result.model);
  if (result.selection && !options.selection_table.empty()) {
    AtomicWriteFile(options.selection_table, result.selection->Markdown());
  }
  return result;
}

}  // namespace irbench
