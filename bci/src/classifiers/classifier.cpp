#include <stdexcept>

#include "arbci/bci/evaluation.h"
#include "classifiers/linear.h"

namespace arbci::bci {

double LinearClassifierBase::score(const Eigen::Ref<const Eigen::VectorXd>& features) const {
  if (features.size() != weights_.size()) {
    throw std::invalid_argument("classifier: " + std::to_string(features.size()) +
                                " features given, the model has " +
                                std::to_string(weights_.size()));
  }
  return weights_.dot(features) + bias_;
}

nlohmann::json LinearClassifierBase::toJson() const {
  nlohmann::json json;
  json["method"] = method();
  json["weights"] = std::vector<double>(weights_.data(), weights_.data() + weights_.size());
  json["bias"] = bias_;
  json["details"] = details_;
  return json;
}

void LinearClassifierBase::restore(const nlohmann::json& json, const FeatureShape& shape) {
  if (!json.contains("weights") || !json["weights"].is_array() || !json.contains("bias")) {
    throw std::invalid_argument("classifier: weights or bias missing");
  }
  const std::vector<double> w = json["weights"].get<std::vector<double>>();
  if (static_cast<int>(w.size()) != shape.size()) {
    throw std::invalid_argument("classifier: " + std::to_string(w.size()) + " weights for " +
                                std::to_string(shape.size()) + " features (" +
                                std::to_string(shape.channels) + " channels x " +
                                std::to_string(shape.bins) + " bins)");
  }
  weights_ = Eigen::Map<const Eigen::VectorXd>(w.data(), static_cast<Eigen::Index>(w.size()));
  bias_ = json["bias"].get<double>();
  details_ = json.value("details", nlohmann::json::object());
}

void checkTrainingData(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                       const FeatureShape& shape) {
  if (features.rows() != static_cast<Eigen::Index>(target.size()))
    throw std::invalid_argument("one label per epoch is needed");
  if (features.cols() != shape.size())
    throw std::invalid_argument("feature vectors do not match the feature shape");
  const auto targets = static_cast<int>(std::count(target.begin(), target.end(), true));
  const int others = static_cast<int>(target.size()) - targets;
  if (targets < kMinimumTargets || others < kMinimumTargets) {
    throw std::invalid_argument("too few examples to train: " + std::to_string(targets) +
                                " target and " + std::to_string(others) +
                                " non-target epochs (at least " + std::to_string(kMinimumTargets) +
                                " of each)");
  }
  if (!features.allFinite())
    throw std::invalid_argument("the features contain NaN or infinite values");
}

namespace {

const ClassifierParts& partsOf(const std::string& method) {
  const ClassifierRegistry::Entry* entry = classifiers().find(method);
  if (!entry)
    throw std::invalid_argument("unknown classification method '" + method + "' (" +
                                classifiers().list() + ")");
  return entry->make;
}

}  // namespace

PipelineSettings withMethodRate(PipelineSettings pipeline, const std::string& method) {
  if (!(pipeline.decimate_hz > 0.0)) pipeline.decimate_hz = partsOf(method).feature_rate_hz;
  return pipeline;
}

TrainingSettings withMethodDefaults(TrainingSettings settings) {
  if (settings.xdawn.filters == 0) settings.xdawn.filters = partsOf(settings.method).xdawn_filters;
  return settings;
}

std::unique_ptr<Classifier> makeClassifier(const TrainingSettings& settings) {
  try {
    return classifiers().at(settings.method).make.make(withMethodDefaults(settings));
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("unknown classification method '" + settings.method + "' (" +
                                classifiers().list() + ")");
  }
}

std::unique_ptr<Classifier> classifierFromJson(const nlohmann::json& json,
                                               const FeatureShape& shape) {
  if (!json.is_object() || !json.contains("method") || !json["method"].is_string()) {
    throw std::invalid_argument("classifier: no method");
  }
  const std::string method = json["method"].get<std::string>();
  const ClassifierRegistry::Entry* entry = classifiers().find(method);
  if (!entry)
    throw std::invalid_argument("classifier: unknown method '" + method + "' (" +
                                classifiers().list() + ")");
  return entry->make.restore(json, shape);
}

}  // namespace arbci::bci
