// A trained P300 model: the signal it expects, the pipeline (filters, window, decimation,
// channels), the classifier, the score model for decisions, and where it came from. Saved and
// loaded as JSON; exported as a BCI2000 parameter fragment.
#pragma once

#include <filesystem>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "arbci/bci/classifier.h"
#include "arbci/bci/decision.h"
#include "arbci/bci/evaluation.h"
#include "arbci/bci/features.h"

namespace arbci::bci {

// A model file that cannot be used: missing, malformed, or made for another signal.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct P300Model {
  std::string method;
  double rate_hz = 0.0;
  PipelineSettings pipeline;  // pipeline.channels: the feature channels, by name
  FeatureShape shape;
  std::shared_ptr<const Classifier> classifier;
  ScoreModel score_model;
  ParadigmLayout layout;
  nlohmann::json provenance = nlohmann::json::object();
  // The error-related-potential classifier trained beside it (its "target": error feedback;
  // its layout: 2 classes), when the session has one. Saved inside this model's JSON as "errp".
  std::shared_ptr<const P300Model> errp;
  // Its cross-validated AUC on the calibration block (NaN: unknown).
  double errp_auc = std::numeric_limits<double>::quiet_NaN();

  // Throws ModelError naming the mismatch (rate, a missing channel).
  void checkCompatible(const SignalInfo& info, const std::string& what) const;
  FeatureExtractor extractor(const SignalInfo& info) const {
    return FeatureExtractor(pipeline, info);
  }

  nlohmann::json toJson() const;
  static P300Model fromJson(const nlohmann::json& json, const std::string& source);
  void save(const std::filesystem::path& path) const;        // throws ModelError
  static P300Model load(const std::filesystem::path& path);  // throws ModelError

  // BCI2000 parameters (LinearClassifier, P3TemporalFilter epoch length, the channels, and the
  // band-pass as IIRBandpass) so the model runs in BCI2000's P3 signal processing. Throws
  // ModelError when the window does not start at the stimulus, as BCI2000's epochs do.
  std::string bci2000Fragment() const;
};

// Trains `settings.method` on all labelled epochs of `data`, after cross-validating it by
// selection (whose out-of-fold scores give the score model and the report).
struct TrainingResult {
  P300Model model;
  CrossValidation cross_validation;
};
TrainingResult trainModel(const P300Dataset& data, const PipelineSettings& pipeline,
                          const TrainingSettings& settings, const Progress& progress = {});

}  // namespace arbci::bci
