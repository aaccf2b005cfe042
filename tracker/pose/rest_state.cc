#include "tracker/pose/rest_state.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numeric>
#include <opencv2/ml.hpp>
#include <random>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/paths.h"

namespace irbench {

struct RestClassifier::Impl {
  cv::Ptr<cv::ml::SVM> svm;
};

RestClassifier::RestClassifier() : impl_(std::make_unique<Impl>()) {}
RestClassifier::~RestClassifier() = default;
RestClassifier::RestClassifier(RestClassifier&&) noexcept = default;
RestClassifier& RestClassifier::operator=(RestClassifier&&) noexcept = default;

std::array<float, 6> RestFeatures(const Eigen::Vector3d& waist, const Eigen::Vector3d& neck,
                                  const Eigen::Vector3d& right_shoulder, const Eigen::Vector3d& left_shoulder,
                                  const Eigen::Vector3d& elbow, const Eigen::Vector3d& wrist, double height_m,
                                  bool left_arm) {
  const Eigen::Vector3d z = (neck - waist).normalized();
  Eigen::Vector3d x = right_shoulder - left_shoulder;
  x = (x - x.dot(z) * z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d upper_from_world;
  upper_from_world.row(0) = x;
  upper_from_world.row(1) = y;
  upper_from_world.row(2) = z;
  const Eigen::Vector3d& shoulder = left_arm ? left_shoulder : right_shoulder;
  Eigen::Vector3d e = upper_from_world * (elbow - shoulder) / height_m;
  Eigen::Vector3d w = upper_from_world * (wrist - shoulder) / height_m;
  if (left_arm) {
    e.x() = -e.x();
    w.x() = -w.x();
  }
  return {float(e.x()), float(e.y()), float(e.z()), float(w.x()), float(w.y()), float(w.z())};
}

namespace {

cv::Mat ToMat(const std::vector<std::array<float, 6>>& features) {
  cv::Mat m(static_cast<int>(features.size()), 6, CV_32F);
  for (size_t i = 0; i < features.size(); ++i) {
    for (int k = 0; k < 6; ++k) m.at<float>(static_cast<int>(i), k) = features[i][k];
  }
  return m;
}

}  // namespace

RestClassifier RestClassifier::Train(const std::vector<std::array<float, 6>>& features, const std::vector<int>& at_rest,
                                     int folds, double* cv_accuracy) {
  if (features.size() != at_rest.size() || features.empty()) {
    throw std::invalid_argument("rest training needs as many labels as feature rows, and some rows");
  }
  const int positives = std::accumulate(at_rest.begin(), at_rest.end(), 0);
  if (positives == 0 || positives == static_cast<int>(at_rest.size())) {
    throw std::invalid_argument("rest training needs both arms at rest and arms not at rest");
  }
  if (folds < 2) throw std::invalid_argument("rest training needs at least 2 folds");
  const cv::Mat x = ToMat(features);
  cv::Mat y(static_cast<int>(at_rest.size()), 1, CV_32S);
  for (size_t i = 0; i < at_rest.size(); ++i) y.at<int>(static_cast<int>(i)) = at_rest[i] ? 1 : 0;
  cv::theRNG().state = 0x1234abcd;  // trainAuto shuffles its folds with OpenCV's RNG
  RestClassifier out;
  out.impl_->svm = cv::ml::SVM::create();
  out.impl_->svm->setType(cv::ml::SVM::C_SVC);
  out.impl_->svm->setKernel(cv::ml::SVM::RBF);
  out.impl_->svm->trainAuto(cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y), folds);
  if (cv_accuracy) {
    // A separate k-fold pass with the chosen C and gamma, folds by a seeded shuffle.
    std::vector<int> order(features.size());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
    int correct = 0;
    for (int f = 0; f < folds; ++f) {
      std::vector<int> train_rows, test_rows;
      for (size_t i = 0; i < order.size(); ++i) (static_cast<int>(i) % folds == f ? test_rows : train_rows).push_back(order[i]);
      cv::Mat tx(static_cast<int>(train_rows.size()), 6, CV_32F), ty(static_cast<int>(train_rows.size()), 1, CV_32S);
      for (size_t i = 0; i < train_rows.size(); ++i) {
        x.row(train_rows[i]).copyTo(tx.row(static_cast<int>(i)));
        ty.at<int>(static_cast<int>(i)) = y.at<int>(train_rows[i]);
      }
      cv::Ptr<cv::ml::SVM> svm = cv::ml::SVM::create();
      svm->setType(cv::ml::SVM::C_SVC);
      svm->setKernel(cv::ml::SVM::RBF);
      svm->setC(out.impl_->svm->getC());
      svm->setGamma(out.impl_->svm->getGamma());
      svm->train(tx, cv::ml::ROW_SAMPLE, ty);
      for (int r : test_rows) correct += (svm->predict(x.row(r)) > 0.5) == (y.at<int>(r) == 1);
    }
    *cv_accuracy = static_cast<double>(correct) / features.size();
  }
  return out;
}

RestClassifier RestClassifier::Load(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw InputError(path.string(), "", "rest-state model not found");
  RestClassifier out;
  try {
    out.impl_->svm = cv::ml::SVM::load(path.string());
  } catch (const cv::Exception& e) {
    throw InputError(path.string(), "", std::string("not a rest-state SVM: ") + e.what());
  }
  if (out.impl_->svm.empty() || !out.impl_->svm->isTrained() || out.impl_->svm->getVarCount() != 6) {
    throw InputError(path.string(), "", "not a trained rest-state SVM with 6 features");
  }
  return out;
}

void RestClassifier::Save(const std::filesystem::path& path) const {
  if (empty()) throw std::logic_error("saving an untrained rest classifier");
  // What cv::ml::SVM::save writes, through the project's atomic writer.
  cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  fs << impl_->svm->getDefaultName() << "{";
  impl_->svm->write(fs);
  fs << "}";
  AtomicWriteFile(path, fs.releaseAndGetString());
}

bool RestClassifier::AtRest(const std::array<float, 6>& features) const {
  if (empty()) return false;
  cv::Mat row(1, 6, CV_32F, const_cast<float*>(features.data()));
  return impl_->svm->predict(row) > 0.5;
}

double RestClassifier::Margin(const std::array<float, 6>& features) const {
  if (empty()) return 0;
  cv::Mat row(1, 6, CV_32F, const_cast<float*>(features.data()));
  // OpenCV's raw decision value has the sign of its internal class order;
  // the label decides the sign here.
  const double raw = std::abs(impl_->svm->predict(row, cv::noArray(), cv::ml::StatModel::RAW_OUTPUT));
  return AtRest(features) ? raw : -raw;
}

bool RestClassifier::empty() const { return !impl_->svm || !impl_->svm->isTrained(); }

std::filesystem::path DefaultRestModelPath() { return DataRoot() / "tracker" / "models" / "rest_svm.yml"; }

}  // namespace irbench
