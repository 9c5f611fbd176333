// The error-related-potential classifier's stage (with errp.enabled): each selection's feedback,
// as presented, cut into an epoch of the ErrP's own band and scored once the epoch is complete.
// The calibration run's feedback block (cued feedback, some deliberately wrong) is kept with the
// signal, and the classifier trained on it, when asked, on a worker thread beside the P300 one.
#pragma once

#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arbci/bci/epocher.h"
#include "arbci/bci/evaluation.h"
#include "arbci/bci/features.h"
#include "arbci/bci/filters.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/paradigm.h"
#include "arbci/bci/recording.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct ErrpStageSettings {
  bool enabled = false;
  bci::SignalInfo info;  // the EEG channels (no photodiode)
  bci::PipelineSettings pipeline;
  bci::TrainingSettings training;
  // The feedback's nominal duration (a flash's; the schema's default here).
  double flash_s = bci::ParadigmSettings().flashSeconds();
  std::string model_file;  // a trained P300 model whose "errp" part is used
  double threshold = 0.0;  // errp.threshold, for the summary
};

class ErrpStage final : public Stage {
 public:
  ErrpStage(const ErrpStageSettings& settings, const StageServices& services);
  ~ErrpStage() override;
  const char* name() const override { return "errp"; }
  void step(Cycle& cycle) override;
  void report(nlohmann::json& summary) const override;

 private:
  struct Outcome {
    bci::P300Model model;
    bci::EvaluationReport report;
    bci::ErpCurves erp;
  };
  // `calibrated`: trained on this session's feedback block, whose signal is kept until the first
  // online selection (a recalibration at the review starts from it).
  void setModel(std::shared_ptr<const bci::P300Model> errp, bool calibrated = false);
  void startTraining();
  void takeTraining(Cycle& cycle);

  ErrpStageSettings settings_;
  StageServices s_;
  std::shared_ptr<const bci::P300Model> model_;
  double auc_ = std::numeric_limits<double>::quiet_NaN();
  std::shared_ptr<const bci::ErpCurves> trained_erp_;
  std::unique_ptr<bci::FilterChain> filters_;
  std::unique_ptr<bci::Epocher> epocher_;
  std::optional<bci::FeatureExtractor> extractor_;
  // The calibration run's signal (sample-major) and its feedback block's feedbacks.
  std::vector<float> signal_;
  std::int64_t samples_ = 0;
  std::vector<bci::StimulusEvent> feedbacks_;
  bool keep_signal_ = true;
  bool calibrating_ = false;
  std::future<Outcome> training_;
  std::int64_t pending_ = -1;  // the onset of the feedback whose score is awaited
};

}  // namespace arbci::session
