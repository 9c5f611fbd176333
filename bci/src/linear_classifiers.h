// The three classifiers share their scoring: a weight per feature and a bias.
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

// Shrinkage LDA on rows of X: weights and bias with the decision threshold midway between the
// class means. Returns the shrinkage intensity used.
double trainShrinkageLda(const Eigen::MatrixXd& x, const std::vector<bool>& target,
                         Eigen::VectorXd& weights, double& bias);

class SwldaClassifier final : public LinearClassifierBase {
 public:
  explicit SwldaClassifier(const SwldaSettings& settings) : settings_(settings) {}
  std::string method() const override { return "swlda"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override;

 private:
  SwldaSettings settings_;
};

class ShrinkageLdaClassifier final : public LinearClassifierBase {
 public:
  std::string method() const override { return "slda"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override;
};

class XdawnClassifier final : public LinearClassifierBase {
 public:
  explicit XdawnClassifier(const XdawnSettings& settings) : settings_(settings) {}
  std::string method() const override { return "xdawn"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override;

 private:
  XdawnSettings settings_;
};

}  // namespace arbci::bci
