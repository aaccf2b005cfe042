// The atoms' selection (thesis 5.1.2) on the true body: three avatars posed
// through the 30 candidate postures (`posture_candidates`) exactly as the
// renderer poses them, voxelised at the tracker's 2 cm, each candidate's
// shape descriptor less the person's own rest (Eq. 5.6), averaged over the
// persons. The SVD selection over their matching-pursuit weights must span
// them nearly as well as the best four candidates (brute force) and pick
// four that do not compete. It does not pick one candidate of each of the
// truth's four arm atoms (the truth's rule, sim/motion/labels.h, names each
// candidate's posture by elevation bands): printed, not asserted
// (docs/recognition.md). No render: the mesh is the truth. `irbench train atoms --candidates` does the same on the
// tracker's own hulls of rendered frames (docs/recognition.md).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>

#include <Eigen/QR>

#include "sim/motion/labels.h"
#include "sim/motion/posture_candidates.h"
#include "sim/sequence/render_job.h"
#include "tests/true_body.h"
#include "tracker/posture/atom_selection.h"
#include "tracker/posture/decompose.h"
#include "tracker/posture/posture_atoms.h"
#include "tracker/shape/shape_descriptor.h"

namespace irbench {
namespace {

std::vector<float> UnitDescriptor(const RenderInputs& in, double t, double height_m) {
  const int frame = static_cast<int>(std::lround(t * in.fps));
  const VoxelHull hull = irbench::testing::Voxelise(irbench::testing::PosedBody(in, frame), 0.02);
  const ShapeDescriptor d = HullShapeDescriptor(hull, height_m);
  double norm = 0;
  for (float v : d.bins) norm += double(v) * v;
  std::vector<float> unit(d.bins.size());
  for (size_t i = 0; i < unit.size(); ++i) unit[i] = static_cast<float>(d.bins[i] / std::sqrt(norm));
  return unit;
}

TEST(AtomSelectionClosedLoop, TheSelectionSpansTheCandidatesWithAtomsThatDoNotCompete) {
  std::vector<std::vector<double>> sums;
  std::vector<std::string> atoms;  // each candidate's truth atom
  const char* avatars[] = {"p1", "p4", "p6"};
  for (const char* avatar : avatars) {
    RenderJobOptions options;
    options.rig = "theater4";
    options.avatar = avatar;
    options.motion = "posture_candidates";
    const RenderInputs in = LoadRenderInputs(options);
    const Labeler labeler(in.avatar, &in.scene, *in.motion);
    const double height = irbench::testing::PosedBody(in, 0).hi.z();
    const std::vector<float> rest = UnitDescriptor(in, 0.0, height);
    std::vector<MotionEvent> holds;
    for (const MotionEvent& e : in.motion->Events()) {
      if (e.kind == "posture_candidate") holds.push_back(e);
    }
    ASSERT_EQ(holds.size(), 30u);
    sums.resize(holds.size());
    atoms.resize(holds.size());
    for (size_t c = 0; c < holds.size(); ++c) {
      const double t = 0.5 * (holds[c].start + holds[c].end);
      const nlohmann::json posture = labeler.Labels(t)["posture"];
      // The other arm rests: the pair is A0 and the candidate's atom.
      const std::string atom = posture[0] == "A0" ? posture[1] : posture[0];
      if (atoms[c].empty()) atoms[c] = atom;
      if (atoms[c] != atom) std::printf("%s: %s on %s, %s before\n", holds[c].value.c_str(), atom.c_str(), avatar, atoms[c].c_str());
      double alpha0 = 0;
      const std::vector<float> r = RestResidual(UnitDescriptor(in, t, height), rest, &alpha0);
      sums[c].resize(r.size(), 0.0);
      for (size_t i = 0; i < r.size(); ++i) sums[c][i] += r[i];
    }
  }
  std::vector<std::vector<float>> candidates;
  for (const auto& s : sums) candidates.emplace_back(s.begin(), s.end());
  const AtomSelection sel = SelectAtoms(candidates, 4, PostureAtoms{}.overlap_threshold);
  const std::vector<std::string> about = PostureCandidateDescriptions();
  std::set<std::string> chosen;
  for (int i : sel.selected) {
    std::printf("selected C%02d (%s): %s\n", i + 1, atoms[i].c_str(), about[i].c_str());
    chosen.insert(atoms[i]);
  }
  std::printf("singular values:");
  for (int k = 0; k < 8; ++k) std::printf(" %.3f", sel.singular_values(k));
  std::printf("\n");
  // The selection spans M nearly as well as the best of all C(30, 4)
  // subsets of its columns (brute force), and its atoms do not compete: no
  // two as alike as the candidates that differ only in azimuth (cosine 0.98).
  const Eigen::MatrixXd& m = sel.weights;
  const auto unspanned = [&](const std::vector<int>& cols) {
    Eigen::MatrixXd a(m.rows(), static_cast<int>(cols.size()));
    for (size_t c = 0; c < cols.size(); ++c) a.col(static_cast<int>(c)) = m.col(cols[c]);
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(a);
    const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(a.rows(), a.cols());
    return (m - q * (q.transpose() * m)).norm();
  };
  double best = 1e9;
  const int n = static_cast<int>(m.rows());
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      for (int c = b + 1; c < n; ++c)
        for (int d = c + 1; d < n; ++d) best = std::min(best, unspanned({a, b, c, d}));
  // The truth's atoms are candidates too: C03 (A1), C19 (A2), C05 (A3), C01 (A4).
  const double truth_atoms = unspanned({2, 18, 4, 0});
  double overlap = 0, truth_overlap = 0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      overlap = std::max(overlap, m(sel.selected[i], sel.selected[j]));
      const int t[4] = {2, 18, 4, 0};
      truth_overlap = std::max(truth_overlap, m(t[i], t[j]));
    }
  }
  std::printf("M outside the columns' span: selected %.3f, best subset %.3f, the truth's atoms %.3f, rank 4 %.3f; "
              "largest weight between two: selected %.3f, the truth's atoms %.3f; one per truth atom: %s\n",
              unspanned(sel.selected), best, truth_atoms, std::sqrt(sel.singular_values.tail(n - 4).squaredNorm()),
              overlap, truth_overlap, chosen.size() == 4 ? "yes" : "no");
  EXPECT_LE(unspanned(sel.selected), 1.5 * best);
  EXPECT_LT(overlap, 0.9);
}

}  // namespace
}  // namespace irbench
