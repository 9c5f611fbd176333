// Linear P300 classifiers behind one interface: trained on labelled feature vectors (rows of X,
// target or not), scoring new ones (higher: more target-like).
//  - SWLDA as BCI2000's P300Classifier: stepwise regression (p-enter 0.10, p-remove 0.15, at most
//    60 features), least-squares weights on the features kept;
//  - shrinkage LDA with the analytic Ledoit-Wolf shrinkage (no tuning);
//  - xDAWN spatial filters (OpenViBE's P300 pipeline) followed by shrinkage LDA;
//  - Riemannian: xDAWN-augmented covariances in the tangent space at their Riemannian mean,
//    then shrinkage LDA (MOABB's best P300 pipeline); not linear, so no BCI2000 export.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "arbci/bci/features.h"

namespace arbci::bci {

// Called during long training with a fraction done (0-1) and what is being done.
using Progress = std::function<void(double fraction, const std::string& stage)>;

struct SwldaSettings {
  double p_enter = 0.10;
  double p_remove = 0.15;
  int max_features = 60;
};

struct XdawnSettings {
  int filters = 4;  // spatial filters kept (the Riemannian method: per class)
};

class Classifier {
 public:
  virtual ~Classifier() = default;
  virtual std::string method() const = 0;  // "swlda", "slda", "xdawn" or "riemann"
  // Throws std::invalid_argument when the data cannot train a model (too few targets, sizes).
  virtual void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                     const FeatureShape& shape, const Progress& progress = {}) = 0;
  virtual double score(const Eigen::Ref<const Eigen::VectorXd>& features) const = 0;
  // The equivalent weights on the features (score = weights . x + bias); empty for a method that
  // is not linear in the features.
  virtual Eigen::VectorXd weights() const = 0;
  virtual double bias() const = 0;
  virtual nlohmann::json toJson() const = 0;
};

// "swlda", "slda", "xdawn" or "riemann"; throws std::invalid_argument for anything else.
std::unique_ptr<Classifier> makeClassifier(const std::string& method,
                                           const SwldaSettings& swlda = {},
                                           const XdawnSettings& xdawn = {});
// Throws std::invalid_argument naming what is missing or inconsistent.
std::unique_ptr<Classifier> classifierFromJson(const nlohmann::json& json,
                                               const FeatureShape& shape);

// Shared by the methods: the minimum number of target and non-target examples to train.
constexpr int kMinimumTargets = 10;
void checkTrainingData(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                       const FeatureShape& shape);

}  // namespace arbci::bci
