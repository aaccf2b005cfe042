#include "tracker/gesture/gesture_models.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/json_reader.h"
#include "common/logging.h"
#include "common/paths.h"

namespace irbench {
namespace {



// The Gaussian models' observations, one column per frame: its atom weights,
// or its pair as weights (pair_scale per arm on the pair's atoms).
Eigen::MatrixXd Observations(const std::vector<GestureObservation>& segment, int atoms, GestureObservationKind kind,
                             double pair_scale) {
  Eigen::MatrixXd y(atoms, segment.size());
  for (size_t t = 0; t < segment.size(); ++t) {
    const GestureObservation& o = segment[t];
    if (kind == GestureObservationKind::kPair) {
      if (o.primary < 0 || o.primary >= atoms || o.secondary < 0 || o.secondary >= atoms) {
        throw std::invalid_argument("an atom index outside the models' atoms");
      }
      y.col(t).setZero();
      y(o.primary, t) += pair_scale;
      y(o.secondary, t) += pair_scale;
      continue;
    }
    if (o.weights.size() != atoms) {
      throw std::invalid_argument("an observation of " + std::to_string(o.weights.size()) +
                                  " weights; the models take " + std::to_string(atoms));
    }
    y.col(t) = o.weights;
  }
  return y;
}

std::vector<int> Symbols(const std::vector<GestureObservation>& segment, bool primary, int atoms) {
  std::vector<int> s;
  for (const auto& o : segment) {
    const int v = primary ? o.primary : o.secondary;
    if (v < 0 || v >= atoms) throw std::invalid_argument("an atom index outside the models' atoms");
    s.push_back(v);
  }
  return s;
}

// --- JSON ---------------------------------------------------------------

nlohmann::json MatrixJson(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json VectorJson(const Eigen::VectorXd& v) {
  nlohmann::json row = nlohmann::json::array();
  for (int i = 0; i < v.size(); ++i) row.push_back(v(i));
  return row;
}

nlohmann::json ChainJson(const LogMarkovChain& c) {
  return {{"initial", VectorJson(c.log_initial.array().exp())},
          {"transition", MatrixJson(c.log_transition.array().exp())}};
}

LogMarkovChain ChainFrom(const JsonNode& node, int n) {
  node.CheckKeys({"initial", "transition"});
  const LogMarkovChain c =
      LogMarkovChain::FromProbabilities(node["initial"].FiniteVector(n), node["transition"].FiniteMatrix(n, n));
  try {
    c.Check();
  } catch (const std::invalid_argument& e) {
    node.Fail(e.what());
  }
  return c;
}

Eigen::MatrixXd CovarianceFrom(const JsonNode& node, int d) {
  Eigen::MatrixXd c = node.FiniteMatrix(d, d);
  if ((c - c.transpose()).cwiseAbs().maxCoeff() > 1e-9 * (1 + c.cwiseAbs().maxCoeff()) ||
      Eigen::LLT<Eigen::MatrixXd>(c).info() != Eigen::Success) {
    node.Fail("must be a symmetric positive definite matrix");
  }
  return c;
}

// --- training -------------------------------------------------------------

Fhmm TrainOneFhmm(const std::vector<Eigen::MatrixXd>& data, const GestureTrainingOptions& o, uint64_t seed) {
  BaumWelchOptions bw;
  bw.max_iterations = o.max_iterations;
  CovarianceOptions cov{o.covariance_ridge};
  Fhmm best;
  double best_ll = kLogZero;
  for (int r = 0; r < o.restarts; ++r) {
    Fhmm m = InitialFhmm(data, 2, o.chain_states, 0.8, seed + 7919 * r);
    m.covariance.diagonal().array() += o.covariance_ridge;
    try {
      const TrainingTrace t = TrainFhmm(data, bw, cov, &m);
      if (t.final_log_likelihood > best_ll) best_ll = t.final_log_likelihood, best = m;
    } catch (const std::domain_error&) {
      continue;  // a degenerate start; the other restarts decide
    }
  }
  if (best.chains.empty()) throw std::runtime_error("the FHMM's training failed from every start");
  return best;
}

GaussianHmm TrainOneHmm(const std::vector<Eigen::MatrixXd>& data, const GestureTrainingOptions& o, uint64_t seed) {
  const int d = static_cast<int>(data[0].rows());
  long frames = 0;
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(d);
  Eigen::MatrixXd second = Eigen::MatrixXd::Zero(d, d);
  for (const auto& y : data) {
    frames += y.cols();
    mean += y.rowwise().sum();
    second += y * y.transpose();
  }
  mean /= frames;
  Eigen::MatrixXd cov = second / frames - mean * mean.transpose();
  cov.diagonal().array() += o.covariance_ridge;
  BaumWelchOptions bw;
  bw.max_iterations = o.max_iterations;
  GaussianHmm best;
  double best_ll = kLogZero;
  std::mt19937_64 rng(seed);
  for (int r = 0; r < o.restarts; ++r) {
    GaussianHmm m;
    m.chain = StickyChain(o.hmm_states, 0.8);
    m.means.resize(d, o.hmm_states);
    for (int k = 0; k < o.hmm_states; ++k) {
      const auto& y = data[static_cast<size_t>(UniformDraw(rng) * data.size())];
      m.means.col(k) = y.col(static_cast<int>(UniformDraw(rng) * y.cols()));
      for (int i = 0; i < d; ++i) m.means(i, k) += 0.05 * std::sqrt(cov(i, i)) * (UniformDraw(rng) - 0.5);
    }
    m.covariance = cov;
    try {
      const TrainingTrace t = TrainGaussianHmm(data, bw, {o.covariance_ridge}, &m);
      if (t.final_log_likelihood > best_ll) best_ll = t.final_log_likelihood, best = m;
    } catch (const std::domain_error&) {
      continue;
    }
  }
  if (best.means.size() == 0) throw std::runtime_error("the HMM's training failed from every start");
  return best;
}

DiscreteHmm TrainOneChain(const std::vector<std::vector<int>>& data, const GestureTrainingOptions& o) {
  const int k = o.chain_states;
  DiscreteHmm m;
  m.chain = StickyChain(k, 0.8);
  // The thesis: a gesture starts at rest (pi_0 = 1).
  m.chain.log_initial = Eigen::VectorXd::Constant(k, kLogZero);
  m.chain.log_initial(0) = 0;
  Eigen::MatrixXd b = Eigen::MatrixXd::Constant(k, k, 0.4 / (k - 1));
  b.diagonal().setConstant(0.6);
  m.log_emission = b.array().log();
  BaumWelchOptions bw;
  bw.max_iterations = o.max_iterations;
  bw.pseudo_count = o.pseudo_count;
  bw.fixed_initial = true;
  TrainDiscreteHmm(data, bw, &m);
  return m;
}

}  // namespace

const char* GestureModelKindName(GestureModelKind kind) {
  switch (kind) {
    case GestureModelKind::kHmm: return "hmm";
    case GestureModelKind::kParallelHmm: return "pahmm";
    case GestureModelKind::kFactorialHmm: return "fhmm";
  }
  return "";
}

const char* GestureObservationKindName(GestureObservationKind kind) {
  return kind == GestureObservationKind::kPair ? "pair" : "weights";
}

std::optional<GestureObservationKind> ParseGestureObservationKind(const std::string& name) {
  if (name == "weights") return GestureObservationKind::kWeights;
  if (name == "pair") return GestureObservationKind::kPair;
  return std::nullopt;
}

std::optional<GestureModelKind> ParseGestureModelKind(const std::string& name) {
  for (GestureModelKind k : {GestureModelKind::kHmm, GestureModelKind::kParallelHmm, GestureModelKind::kFactorialHmm}) {
    if (name == GestureModelKindName(k)) return k;
  }
  return std::nullopt;
}

Eigen::VectorXd GestureModels::ObservationVector(const GestureObservation& o) const {
  return Observations({o}, dimension(), observation, pair_scale).col(0);
}

double GestureModels::LogLikelihood(GestureModelKind kind, int g, const std::vector<GestureObservation>& segment) const {
  switch (kind) {
    case GestureModelKind::kHmm:
      return hmm.at(g).LogLikelihood(Observations(segment, dimension(), observation, pair_scale));
    case GestureModelKind::kFactorialHmm:
      return fhmm.at(g).LogLikelihood(Observations(segment, dimension(), observation, pair_scale));
    case GestureModelKind::kParallelHmm:
      return pahmm.at(g)[0].LogLikelihood(Symbols(segment, true, dimension())) +
             pahmm.at(g)[1].LogLikelihood(Symbols(segment, false, dimension()));
  }
  return kLogZero;
}

int GestureModels::Classify(GestureModelKind kind, const std::vector<GestureObservation>& segment,
                            std::vector<double>* log_likelihoods) const {
  std::vector<double> ll;
  int best = 0;
  for (int g = 0; g < gesture_count(); ++g) {
    ll.push_back(LogLikelihood(kind, g, segment));
    if (ll[g] > ll[best]) best = g;
  }
  if (log_likelihoods) *log_likelihoods = ll;
  return best;
}

GestureModels GestureModels::Train(const std::vector<std::string>& gestures, const std::vector<std::string>& atoms,
                                   const std::vector<std::vector<std::vector<GestureObservation>>>& segments,
                                   const GestureTrainingOptions& options) {
  if (segments.size() != gestures.size()) throw std::invalid_argument("one set of segments per gesture");
  if (options.chain_states != static_cast<int>(atoms.size())) {
    throw std::invalid_argument("the PaHMM's chains have one state per atom");
  }
  if (!(options.pair_scale > 0) || !std::isfinite(options.pair_scale)) {
    throw std::invalid_argument("the pair observation's scale must be finite and > 0");
  }
  GestureModels m;
  m.gestures = gestures;
  m.atoms = atoms;
  m.observation = options.observation;
  m.pair_scale = options.pair_scale;
  for (size_t g = 0; g < gestures.size(); ++g) {
    std::vector<Eigen::MatrixXd> y;
    std::vector<std::vector<int>> primary, secondary;
    for (const auto& segment : segments[g]) {
      if (segment.empty()) continue;
      y.push_back(Observations(segment, static_cast<int>(atoms.size()), options.observation, options.pair_scale));
      primary.push_back(Symbols(segment, true, static_cast<int>(atoms.size())));
      secondary.push_back(Symbols(segment, false, static_cast<int>(atoms.size())));
    }
    if (y.empty()) throw std::invalid_argument("no training segment of gesture " + gestures[g]);
    const uint64_t seed = options.seed + 104729 * g;
    m.fhmm.push_back(TrainOneFhmm(y, options, seed));
    m.hmm.push_back(TrainOneHmm(y, options, seed));
    m.pahmm.push_back({TrainOneChain(primary, options), TrainOneChain(secondary, options)});
    Log().info("train gestures: {}: {} segments, {} frames", gestures[g], y.size(), [&] {
      long n = 0;
      for (const auto& s : y) n += s.cols();
      return n;
    }());
  }
  return m;
}

void GestureModels::Save(const std::filesystem::path& path) const {
  nlohmann::json j;
  j["format"] = kFormat;
  j["provenance"] = provenance;
  j["gestures"] = gestures;
  j["atoms"] = atoms;
  j["observation"] = GestureObservationKindName(observation);
  if (observation == GestureObservationKind::kPair) j["pair_scale"] = pair_scale;
  j["models"] = nlohmann::json::array();
  for (int g = 0; g < gesture_count(); ++g) {
    nlohmann::json f = {{"chains", nlohmann::json::array()}, {"weights", nlohmann::json::array()},
                        {"covariance", MatrixJson(fhmm[g].covariance)}};
    for (int c = 0; c < fhmm[g].chain_count(); ++c) {
      f["chains"].push_back(ChainJson(fhmm[g].chains[c]));
      f["weights"].push_back(MatrixJson(fhmm[g].weights[c]));
    }
    nlohmann::json p = nlohmann::json::array();
    for (const DiscreteHmm& chain : pahmm[g]) {
      p.push_back({{"chain", ChainJson(chain.chain)}, {"emission", MatrixJson(chain.log_emission.array().exp())}});
    }
    j["models"].push_back({{"gesture", gestures[g]},
                           {"hmm",
                            {{"chain", ChainJson(hmm[g].chain)},
                             {"means", MatrixJson(hmm[g].means.transpose())},
                             {"covariance", MatrixJson(hmm[g].covariance)}}},
                           {"pahmm", p},
                           {"fhmm", f}});
  }
  std::string text = "{\n";
  for (auto it = j.begin(); it != j.end(); ++it) {
    text += (it == j.begin() ? " " : ",\n ") + nlohmann::json(it.key()).dump() + ": " + it.value().dump();
  }
  AtomicWriteFile(path, text + "\n}\n");
}

GestureModels GestureModels::Load(const std::filesystem::path& path) {
  const JsonNode root = ParseJsonFile(path.string());
  root.CheckKeys({"format", "provenance", "gestures", "atoms", "observation", "pair_scale", "models"});
  if (root.GetString("format") != kFormat) {
    root["format"].Fail("must be " + std::string(kFormat) + " (got " + root.GetString("format") + ")");
  }
  GestureModels m;
  for (size_t i = 0; i < root["gestures"].Size(); ++i) m.gestures.push_back(root["gestures"][i].String());
  for (size_t i = 0; i < root["atoms"].Size(); ++i) m.atoms.push_back(root["atoms"][i].String());
  if (m.dimension() < 2) root["atoms"].Fail("needs at least two atoms");
  // Files from before the key observe the weights.
  const std::string observation = root.GetString("observation", "weights");
  const std::optional<GestureObservationKind> kind = ParseGestureObservationKind(observation);
  if (!kind) root["observation"].Fail("must be weights or pair (got " + observation + ")");
  m.observation = *kind;
  if (m.observation == GestureObservationKind::kPair) {
    m.pair_scale = root.GetDouble("pair_scale");
    if (!(m.pair_scale > 0) || !std::isfinite(m.pair_scale)) root["pair_scale"].Fail("must be finite and > 0");
  }
  const int d = m.dimension();
  if (m.gestures.empty()) root["gestures"].Fail("needs at least one gesture");
  const JsonNode models = root["models"];
  if (models.Size() != m.gestures.size()) models.Fail("needs one entry per gesture");
  for (size_t g = 0; g < models.Size(); ++g) {
    const JsonNode e = models[g];
    e.CheckKeys({"gesture", "hmm", "pahmm", "fhmm"});
    if (e.GetString("gesture") != m.gestures[g]) e["gesture"].Fail("must be " + m.gestures[g]);
    const JsonNode h = e["hmm"];
    h.CheckKeys({"chain", "means", "covariance"});
    GaussianHmm hmm;
    const int states = static_cast<int>(h["chain"]["initial"].Size());
    hmm.chain = ChainFrom(h["chain"], states);
    hmm.means = h["means"].FiniteMatrix(states, d).transpose();
    hmm.covariance = CovarianceFrom(h["covariance"], d);
    m.hmm.push_back(hmm);
    const JsonNode p = e["pahmm"];
    if (p.Size() != 2) p.Fail("needs the primary and the secondary chain");
    std::array<DiscreteHmm, 2> pa;
    for (size_t c = 0; c < 2; ++c) {
      p[c].CheckKeys({"chain", "emission"});
      pa[c].chain = ChainFrom(p[c]["chain"], d);
      const Eigen::MatrixXd b = p[c]["emission"].FiniteMatrix(d, d);
      for (int i = 0; i < d; ++i) {
        if ((b.row(i).array() < 0).any() || std::abs(b.row(i).sum() - 1) > 1e-6) {
          p[c]["emission"][i].Fail("must be probabilities summing to 1");
        }
      }
      pa[c].log_emission = b.unaryExpr([](double v) { return v > 0 ? std::log(v) : kLogZero; });
    }
    m.pahmm.push_back(pa);
    const JsonNode f = e["fhmm"];
    f.CheckKeys({"chains", "weights", "covariance"});
    Fhmm fh;
    if (f["chains"].Size() != f["weights"].Size() || f["chains"].Size() == 0) {
      f["weights"].Fail("needs one weight matrix per chain");
    }
    for (size_t c = 0; c < f["chains"].Size(); ++c) {
      const int k = static_cast<int>(f["chains"][c]["initial"].Size());
      fh.chains.push_back(ChainFrom(f["chains"][c], k));
      fh.weights.push_back(f["weights"][c].FiniteMatrix(d, k));
    }
    fh.covariance = CovarianceFrom(f["covariance"], d);
    try {
      fh.Check();
    } catch (const std::invalid_argument& err) {
      f.Fail(err.what());
    }
    m.fhmm.push_back(fh);
  }
  m.provenance = root.Has("provenance") ? root["provenance"].raw() : nlohmann::json::object();
  return m;
}

std::filesystem::path DefaultGestureModelsPath() {
  return DataRoot() / "tracker" / "models" / "gesture_models.json";
}

}  // namespace irbench
