// The P300 classifier's stage: the EEG filtered causally, cut into epochs around the flashes as
// presented, scored by the model and accumulated for the current selection (its decision and
// certainty drive dynamic stopping), under the model's score model held to the separation the
// online selections of its kind (objects, cells) decided so far show. Until there is a model it
// keeps the calibration run's signal and flashes, and trains on them, when asked, on a worker
// thread exactly as `arbci train` would; the cycle goes on meanwhile. Epochs that touch lost
// samples are discarded, not scored.
#pragma once

#include <deque>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "arbci/bci/epocher.h"
#include "arbci/bci/features.h"
#include "arbci/bci/filters.h"
#include "arbci/bci/held_out_separation.h"
#include "arbci/bci/learning_from_use.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/paradigm.h"
#include "arbci/bci/recording.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct P300Settings {
  bci::SignalInfo info;  // the EEG channels (no photodiode)
  bci::PipelineSettings pipeline;
  bci::TrainingSettings training;  // the method is the paradigm's request's
  // A flash's nominal duration (the paradigm's, in whole frames; the schema's default here).
  double flash_s = bci::ParadigmSettings().flashSeconds();
  int object_stimuli = 0;    // stimuli of the calibration run (the objects)
  std::string model_file;    // a trained model (empty: the calibration run trains one)
  std::string session_file;  // for messages naming a key
  // Learning from use (bci/learning_from_use.h): `learn` (paradigm.calibration none) starts with
  // no model and fits one after each object selection; `adapt` refits a calibrated one, the
  // calibration run's labels kept.
  bool learn = false, adapt = false;
  bci::TrustRule trust;
};

class P300Stage final : public Stage {
 public:
  // Loads the model file when one is named; throws SessionConfigError naming the key when it
  // cannot be used.
  P300Stage(const P300Settings& settings, const StageServices& services);
  ~P300Stage() override;
  const char* name() const override { return "p300"; }
  void step(Cycle& cycle) override;
  // The last fit is waited for: its decodings are the session's post-hoc ones.
  void stop(Cycle& cycle, const std::string& reason) override;
  void report(nlohmann::json& summary) const override;

 private:
  struct FlashRecord {
    int selection = 0;
    int code = 0;
    bci::StimulusEvent event;
  };
  // Raw signal kept for a new filter to start on, and the epocher's history (seconds).
  static constexpr double kHistoryS = 10.0;
  struct Outcome {
    bci::P300Model model;
    bci::EvaluationReport report;
    bci::ErpCurves erp;
    std::vector<int> trained_on, left_out;
  };
  // `why`: the request's origin, for the log.
  // `calibrated`: trained on this session's calibration run, whose signal is kept until the first
  // online selection (a recalibration at the review starts from it); else a model from elsewhere,
  // and there is no calibration signal to keep.
  void setModel(const bci::P300Model& model, double time_s, bool calibrated = false);
  void recalibrate();
  void startSelection(const SelectionStart& selection);
  bci::Recording keptSignal() const;  // the kept signal and flashes, channel-major
  void startTraining(const std::string& method);
  void takeTraining(Cycle& cycle);
  void process(const bci::Block& eeg, double time_s);
  // A filtered block into the epocher; its epochs scored.
  void cutEpochs(const bci::Block& block, double time_s);
  // A model with another filter: that filter, started on the raw history (see the source).
  void refilter(const bci::FilterSettings& filter);
  void keepRaw(const bci::Block& block);
  // Learning from use: a fit over the object selections so far, on a worker thread; its model
  // taken in (the current selection's epochs scored again by it) and its trust judged.
  void startRefit();
  void takeRefit(Cycle& cycle);
  void scoreCurrentAgain();
  // One epoch into the selection's scores (and, for a learnable selection, current_scored_).
  void scoreEpoch(int code, const bci::Epoch& epoch);
  // The score model the current selection is decided under (see the source).
  bci::ScoreModel scoreModelNow();
  // The current selection is over: complete_ moves to it and its scores join held_out_.
  void completeSelection();
  bool learns() const { return settings_.learn || settings_.adapt; }
  // Learnt selections' numbers as the trials they belong to, for the log.
  nlohmann::json byTrial(const std::map<int, int>& by_selection) const;
  std::vector<int> trialsOf(const std::vector<int>& selections) const;
  bool touchesLoss(std::int64_t onset) const;

  P300Settings settings_;
  StageServices s_;
  std::unique_ptr<bci::FilterChain> filters_;
  bci::FilterSettings filter_settings_;  // filters_'s
  std::deque<bci::Block> raw_history_;   // the last kHistoryS of the signal, unfiltered
  std::vector<bci::Block> refiltered_;   // the history through a new filter, to be epoched
  std::int64_t missed_before_ = 0;       // by the epochers before a change of filter
  std::unique_ptr<bci::Epocher> epocher_;
  std::shared_ptr<const bci::P300Model> model_;
  std::optional<bci::FeatureExtractor> extractor_;
  std::shared_ptr<const bci::ErpCurves> trained_erp_;
  // The calibration run: its signal (sample-major while collecting) and cued flashes, each
  // flash's selection beside it, and the selections interrupted and retaken (their flashes gone).
  bci::Recording calibration_;
  std::vector<int> calibration_selection_;
  std::vector<int> left_out_;
  bool keep_signal_ = true;
  std::future<Outcome> training_;
  std::map<std::int64_t, FlashRecord> flashes_;  // by onset sample, until epoched
  int selection_ = 0;
  bool calibrating_ = false;  // the current selection is a cued one
  std::optional<bci::SelectionAccumulator> accumulator_;
  int presented_ = 0, scored_ = 0;
  // Stretches of lost samples [first, end): epochs touching them are discarded, not scored.
  std::vector<std::pair<std::int64_t, std::int64_t>> lost_spans_;
  std::int64_t discarded_ = 0;
  // Learning from use: each kept flash's selection is in calibration_selection_ (the object
  // selections' flashes with their labels removed); the cued selections' choices (adapt);
  // the current selection's layout and scored epochs (scored again when a new model comes).
  struct LearningOutcome {
    bci::LearnedSelections fit;
    std::map<int, int> frozen;
    // The fit's separation as its cross-validation gave it, and as the selections decided before
    // show it (none before any), which bounds it.
    bci::SeparationBound separation;
  };
  std::future<LearningOutcome> refit_;
  int complete_ = 0, fitted_ = 0;  // the last learnable selection complete; the last fitted
  std::shared_ptr<const bci::P300Model> frozen_;  // adapting: the calibrated model
  bool current_learnable_ = false;                // the current selection is kept for learning
  bool selection_objects_ = true;
  std::map<int, int> known_;
  std::map<int, int> trial_of_;  // online selection -> its trial
  bci::ParadigmLayout layout_;
  std::vector<std::pair<int, bci::Epoch>> current_epochs_;
  // The learnable selections decided by a model fitted without them (on at least as many
  // selections as trust asks), each flash's score standardised by that model
  // (bci/held_out_separation.h: they bound what a fit may claim), and the current one's so far.
  std::vector<bci::HeldOutSelection> held_out_;
  bci::HeldOutSelection current_scored_;
  // Every online selection decided, by kind (0 objects, 1 cells), each flash standardised by the
  // model that scored it: they bound the separation the next of their kind is decided under
  // (bci/held_out_separation.h). The current one's so far, its kind (-1: a cued selection), and
  // the bound now (none below bci::kMinHeldOutSelections).
  std::vector<bci::HeldOutSelection> decided_[2];
  bci::HeldOutSelection online_scored_;
  int online_kind_ = -1;
  std::optional<double> held_out_now_;
  int model_selections_ = 0;  // the selections model_ was learnt from (trained on labels: all)
  LearningState state_;
  std::shared_ptr<const LearningState> published_;
  int learnable_ = 0;  // object selections kept for learning
};

}  // namespace arbci::session
