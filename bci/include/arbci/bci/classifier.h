// P300 classifiers behind one interface, trained on labelled feature vectors (rows of X, target
// or not) and scoring new ones (higher: more target-like), and the registry that names them
// (classifiers(): docs/settings.md lists each with its line): SWLDA as BCI2000's, shrinkage LDA,
// plain LDA, xDAWN + shrinkage LDA, and the Riemannian method. Adding one is a file in
// bci/src/classifiers/ and a line in its registry.cpp.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "arbci/bci/features.h"
#include "arbci/core/registry.h"

namespace arbci::bci {

// Called during long training with a fraction done (0-1) and what is being done.
using Progress = std::function<void(double fraction, const std::string& stage)>;

// Their defaults and ranges: bci::trainingSchema() (bci/settings.h), which TrainingSettings
// takes them from.
struct SwldaSettings {
  double p_enter = 0.0;
  double p_remove = 0.0;
  int max_features = 0;
};

struct XdawnSettings {
  int filters = 0;  // spatial filters kept (the Riemannian method: per class)
};

class Classifier {
 public:
  virtual ~Classifier() = default;
  virtual std::string method() const = 0;  // its name in classifiers()
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

struct TrainingSettings;  // evaluation.h

// What the registry knows of a method.
struct ClassifierParts {
  // A new, untrained classifier with its parameters from `settings`.
  std::function<std::unique_ptr<Classifier>(const TrainingSettings& settings)> make;
  // One restored from what its toJson() wrote; throws std::invalid_argument naming what is
  // missing or inconsistent.
  std::function<std::unique_ptr<Classifier>(const nlohmann::json& json, const FeatureShape& shape)>
      restore;
  // Throws std::invalid_argument when data of `shape` cannot meet `settings` (checked before any
  // cross-validation fold); empty: nothing to check.
  std::function<void(const TrainingSettings& settings, const FeatureShape& shape)> check;
  // The parameters it is trained with, for the model's provenance; empty: none.
  std::function<nlohmann::json(const TrainingSettings& settings)> parameters;
  // Linear in the features: BCI2000's LinearClassifier can run it.
  bool linear = true;
  // What the method takes where a setting leaves it to the method (0): the features' rate
  // (pipeline decimate_hz) and the xDAWN filters it keeps (training xdawn_filters; unused by
  // methods without spatial filters).
  double feature_rate_hz = 20.0;  // BCI2000's P300 features
  int xdawn_filters = 0;
};
using ClassifierRegistry = core::Registry<ClassifierParts>;
// Every method, by the name `classifier.method` and `arbci train --method` take.
const ClassifierRegistry& classifiers();

// The settings with what is left to the method (0) filled in from its registry entry; throw
// std::invalid_argument naming the methods there are when `method` is unknown.
PipelineSettings withMethodRate(PipelineSettings pipeline, const std::string& method);
TrainingSettings withMethodDefaults(TrainingSettings settings);

// `settings.method`, untrained; throws std::invalid_argument naming the methods there are.
std::unique_ptr<Classifier> makeClassifier(const TrainingSettings& settings);
// Throws std::invalid_argument naming what is missing or inconsistent.
std::unique_ptr<Classifier> classifierFromJson(const nlohmann::json& json,
                                               const FeatureShape& shape);

// Shared by the methods: the minimum number of target and non-target examples to train.
constexpr int kMinimumTargets = 10;
void checkTrainingData(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                       const FeatureShape& shape);

}  // namespace arbci::bci
