// The Riemannian method (Barachant & Congedo 2014; the best P300 pipeline of MOABB's benchmark,
// pyriemann's XdawnCovariances + TangentSpace + a linear classifier): each epoch becomes the
// covariance of its xDAWN-filtered signal stacked under the two classes' filtered mean responses
// (so it carries the epoch's correlation with each prototype), regularised by Ledoit-Wolf
// shrinkage; the covariances are mapped to the tangent space at their Riemannian (Karcher) mean,
// where shrinkage LDA separates them. Not linear in the features: it has no BCI2000 export.
#pragma once

#include "arbci/bci/classifier.h"

namespace arbci::bci {

class RiemannClassifier final : public Classifier {
 public:
  explicit RiemannClassifier(const XdawnSettings& settings) : settings_(settings) {}
  std::string method() const override { return "riemann"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override;
  double score(const Eigen::Ref<const Eigen::VectorXd>& features) const override;
  Eigen::VectorXd weights() const override { return {}; }  // not linear
  double bias() const override { return 0.0; }
  nlohmann::json toJson() const override;
  // Restores what toJson() wrote; throws std::invalid_argument naming what is inconsistent.
  void restore(const nlohmann::json& json, const FeatureShape& shape);

 private:
  // The epoch's tangent vector at the reference.
  Eigen::VectorXd tangentVector(const Eigen::Ref<const Eigen::RowVectorXd>& features) const;

  XdawnSettings settings_;
  FeatureShape shape_;
  Eigen::MatrixXd filters_;          // channels x 2 filters (the target's, then the others')
  Eigen::MatrixXd prototypes_;       // 2 filters x bins: each class's mean, filtered
  Eigen::MatrixXd reference_isqrt_;  // the Riemannian mean's inverse square root
  Eigen::VectorXd weights_;          // shrinkage LDA on the tangent vectors
  double bias_ = 0.0;
};

}  // namespace arbci::bci
