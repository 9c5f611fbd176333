// LDA with the covariance shrunk towards a multiple of the identity by the Ledoit-Wolf (2004)
// analytic intensity: no parameter to tune, and well-conditioned with more features than epochs.
#include <Eigen/Cholesky>
#include <algorithm>

#include "arbci/bci/evaluation.h"
#include "classifiers/linear.h"

namespace arbci::bci {
namespace {

class ShrinkageLdaClassifier final : public LinearClassifierBase {
 public:
  std::string method() const override { return "slda"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override;
};

}  // namespace

Eigen::MatrixXd ledoitWolfCovariance(const Eigen::MatrixXd& centred, double& shrinkage) {
  const Eigen::Index n = centred.rows(), p = centred.cols();
  const Eigen::MatrixXd sample = centred.transpose() * centred / static_cast<double>(n);
  const double mu = sample.trace() / static_cast<double>(p);
  // Ledoit-Wolf: d2 = |S - mu I|^2, b2 = min(d2, sum_k |x_k x_k' - S|^2 / n^2).
  const double s_norm2 = sample.squaredNorm();
  const double d2 = s_norm2 - static_cast<double>(p) * mu * mu;
  double sum_x4 = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double r2 = centred.row(i).squaredNorm();
    sum_x4 += r2 * r2;
  }
  const double b2_bar = (sum_x4 - static_cast<double>(n) * s_norm2) /
                        (static_cast<double>(n) * static_cast<double>(n));
  shrinkage = d2 > 0.0 ? std::clamp(b2_bar / d2, 0.0, 1.0) : 1.0;
  Eigen::MatrixXd covariance = (1.0 - shrinkage) * sample;
  covariance.diagonal().array() += shrinkage * mu;
  return covariance;
}

double trainShrinkageLda(const Eigen::MatrixXd& x, const std::vector<bool>& target,
                         Eigen::VectorXd& weights, double& bias) {
  const Eigen::Index n = x.rows(), p = x.cols();
  Eigen::VectorXd mean_target = Eigen::VectorXd::Zero(p), mean_other = Eigen::VectorXd::Zero(p);
  int n_target = 0, n_other = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (target[static_cast<size_t>(i)]) {
      mean_target += x.row(i).transpose();
      ++n_target;
    } else {
      mean_other += x.row(i).transpose();
      ++n_other;
    }
  }
  mean_target /= n_target;
  mean_other /= n_other;
  // Pooled within-class deviations.
  Eigen::MatrixXd centred(n, p);
  for (Eigen::Index i = 0; i < n; ++i) {
    centred.row(i) =
        x.row(i) - (target[static_cast<size_t>(i)] ? mean_target : mean_other).transpose();
  }
  double shrinkage = 0.0;
  const Eigen::MatrixXd covariance = ledoitWolfCovariance(centred, shrinkage);
  weights = covariance.ldlt().solve(mean_target - mean_other);
  bias = -weights.dot(0.5 * (mean_target + mean_other));
  return shrinkage;
}

void ShrinkageLdaClassifier::train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                                   const FeatureShape& shape, const Progress& progress) {
  checkTrainingData(features, target, shape);
  if (progress) progress(0.0, "shrinkage LDA");
  const double shrinkage = trainShrinkageLda(features, target, weights_, bias_);
  details_ = {{"shrinkage", shrinkage}};
  if (progress) progress(1.0, "shrinkage LDA");
}

ClassifierRegistry::Entry shrinkageLdaClassifier() {
  ClassifierParts parts;
  parts.make = [](const TrainingSettings&) { return std::make_unique<ShrinkageLdaClassifier>(); };
  parts.restore = [](const nlohmann::json& json, const FeatureShape& shape) {
    return restoreLinear<ShrinkageLdaClassifier>(json, shape);
  };
  return {"slda", "LDA with the covariance shrunk by the analytic Ledoit-Wolf intensity",
          std::move(parts)};
}

}  // namespace arbci::bci
