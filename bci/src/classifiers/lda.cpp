// Plain Fisher LDA, the unregularised baseline: w = S^+ (mean_target - mean_other), with S the
// pooled within-class covariance and S^+ its Moore-Penrose inverse (a complete orthogonal
// decomposition: with more features than epochs S is singular, and the minimum-norm solution is
// what an unregularised LDA can give); the threshold midway between the class means. Compare it
// with shrinkage LDA (slda) to see what the shrinkage buys.
#include <Eigen/QR>
#include <utility>

#include "arbci/bci/evaluation.h"
#include "classifiers/linear.h"

namespace arbci::bci {
namespace {

class PlainLdaClassifier final : public LinearClassifierBase {
 public:
  std::string method() const override { return "lda"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override {
    checkTrainingData(features, target, shape);
    if (progress) progress(0.0, "LDA");
    const Eigen::Index n = features.rows(), p = features.cols();
    Eigen::VectorXd mean_target = Eigen::VectorXd::Zero(p), mean_other = Eigen::VectorXd::Zero(p);
    double n_target = 0, n_other = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      (target[static_cast<size_t>(i)] ? mean_target : mean_other) += features.row(i).transpose();
      (target[static_cast<size_t>(i)] ? n_target : n_other) += 1;
    }
    mean_target /= n_target;
    mean_other /= n_other;
    Eigen::MatrixXd centred(n, p);
    for (Eigen::Index i = 0; i < n; ++i)
      centred.row(i) =
          features.row(i) - (target[static_cast<size_t>(i)] ? mean_target : mean_other).transpose();
    const Eigen::MatrixXd pooled = centred.transpose() * centred / static_cast<double>(n - 2);
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> solver(pooled);
    weights_ = solver.solve(mean_target - mean_other);
    bias_ = -weights_.dot(0.5 * (mean_target + mean_other));
    details_ = {{"covariance_rank", solver.rank()}, {"features", p}};
    if (progress) progress(1.0, "LDA");
  }
};

}  // namespace

ClassifierRegistry::Entry plainLdaClassifier() {
  ClassifierParts parts;
  parts.make = [](const TrainingSettings&) { return std::make_unique<PlainLdaClassifier>(); };
  parts.restore = [](const nlohmann::json& json, const FeatureShape& shape) {
    return restoreLinear<PlainLdaClassifier>(json, shape);
  };
  return {"lda",
          "plain Fisher LDA (pooled covariance, no shrinkage; its pseudo-inverse where singular): "
          "the unregularised baseline",
          std::move(parts)};
}

}  // namespace arbci::bci
