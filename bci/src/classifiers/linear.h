// The linear classifiers share their scoring, a weight per feature and a bias, and their file
// format; shrinkage LDA is also the last step of the xDAWN and Riemannian methods.
#pragma once

#include "arbci/bci/classifier.h"

namespace arbci::bci {

class LinearClassifierBase : public Classifier {
 public:
  double score(const Eigen::Ref<const Eigen::VectorXd>& features) const override;
  Eigen::VectorXd weights() const override { return weights_; }
  double bias() const override { return bias_; }
  nlohmann::json toJson() const override;
  // Restores the weights, bias and details written by toJson().
  void restore(const nlohmann::json& json, const FeatureShape& shape);

 protected:
  Eigen::VectorXd weights_;
  double bias_ = 0.0;
  nlohmann::json details_ =
      nlohmann::json::object();  // what each method adds (selected features, filters)
};

// The covariance of `centred`'s rows (already centred) shrunk towards a multiple of the identity by
// the Ledoit-Wolf (2004) analytic intensity, which goes to `shrinkage`.
Eigen::MatrixXd ledoitWolfCovariance(const Eigen::MatrixXd& centred, double& shrinkage);

// Shrinkage LDA on rows of X: weights and bias with the decision threshold midway between the
// class means. Returns the shrinkage intensity used.
double trainShrinkageLda(const Eigen::MatrixXd& x, const std::vector<bool>& target,
                         Eigen::VectorXd& weights, double& bias);

// A linear classifier of kind C restored from what its toJson() wrote.
template <class C, class... Args>
std::unique_ptr<Classifier> restoreLinear(const nlohmann::json& json, const FeatureShape& shape,
                                          Args&&... args) {
  auto classifier = std::make_unique<C>(std::forward<Args>(args)...);
  classifier->restore(json, shape);
  return classifier;
}

}  // namespace arbci::bci
