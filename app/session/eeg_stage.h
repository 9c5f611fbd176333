// The EEG half of the cycle: takes the blocks the acquisition delivered (on the EEG sample clock),
// records every block and event to the session's BDF+ file, filters, cuts epochs around the
// flashes actually presented, scores them with the model and accumulates the scores of the
// current selection. It keeps the calibration run's signal and trains the model from it on a
// worker thread, exactly as `arbci train` would. A photodiode channel, when there is one, is
// recorded but kept out of the filters, epochs and classifier. With ErrPs on, each selection's
// feedback is recorded ("Feedback <codes> correct|error"), kept from the calibration run's
// feedback block to train the ErrP classifier beside the P300 one, and scored online.
#pragma once

#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "arbci/bci/acquisition.h"
#include "arbci/bci/decision.h"
#include "arbci/bci/epocher.h"
#include "arbci/bci/erp.h"
#include "arbci/bci/lsl/outlet.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/recording_writer.h"
#include "arbci/bci/simulated_subject.h"
#include "session/session_config.h"
#include "session/session_log.h"
#include "session/stage.h"

namespace arbci::app {

// What the EEG stage needs of the session file, and nothing else.
struct EegStageSettings {
  EegSettings eeg;
  bci::PipelineSettings pipeline;
  double flash_s = 0.06;     // a flash's nominal duration (the paradigm's, in whole frames)
  int object_stimuli = 0;    // stimuli of the calibration run (the objects)
  std::string model_file;    // a trained model (empty: none, the calibration run trains one)
  std::string session_file;  // for messages naming a key
  bool errp = false;         // train and use an ErrP classifier
  bci::PipelineSettings errp_pipeline;
  bci::TrainingSettings errp_training;
  bci::lsl::LslConfig lsl;   // source "lsl" or markers: lsl_api.cfg with the session's scope, peers
  bool lsl_markers = false;  // publish stimuli and annotations as an LSL Markers stream
  std::string marker_stream;
  static EegStageSettings of(const SessionConfig& config);
  // Before the run: the files named exist; throws SessionConfigError naming the key and value.
  void validate() const;
};

// The simulated subject a session with `eeg` (source "simulated") acquires from: its montage,
// rate, seed and line noise, the seed's drawn profile with eeg.erp_scale and eeg.errp_scale
// applied, and a virtual photodiode channel when one is named.
bci::SimulatedSubjectConfig simulatedSubjectOf(const EegSettings& eeg);

struct TrainingOutcome {
  bci::P300Model model;
  bci::EvaluationReport report;
  // The ErrP classifier's cross-validated report, or why it could not be trained.
  std::optional<bci::EvaluationReport> errp_report;
  std::string errp_failure;
  // The averages the classifiers were trained on: target and non-target flashes of the
  // calibration run; error (the ErrP classifier's target) and correct feedback of its block.
  bci::ErpCurves erp;
  std::optional<bci::ErpCurves> errp_erp;
};

class EegStage final : public Stage {
 public:
  // Opens the source named by the session, loads the model when one is named, and starts the
  // recording. `stepped`: the source runs in lock-step with a simulated clock; otherwise on its
  // own clock, acquired by a thread. Lost samples are logged and said on `progress` (when given).
  // Throws std::runtime_error (SessionConfigError naming the key for a bad channel).
  EegStage(const EegStageSettings& settings, const std::filesystem::path& recording_path,
           bool stepped, const std::map<std::string, std::string>& parameters, SessionLog& log,
           std::ostream* progress);
  ~EegStage();

  const char* name() const override { return "eeg"; }
  // Takes everything that has arrived (stepped: generated up to the cycle's time) and fills in
  // the cycle's EEG sample.
  void step(CycleContext& cycle) override;
  // Live, the EEG of the last frames is still on its way: waits for it (at most 1 s), notes the
  // end in the recording and closes it.
  void stop(const CycleContext& cycle, const std::string& reason) override;

  // The EEG channels (without the photodiode): what filters, epochs and models see.
  const bci::SignalInfo& info() const { return eeg_info_; }
  bool hasPhotodiode() const { return photodiode_ >= 0; }
  // Stepped: the simulated clock is now at `seconds`.
  void advanceTo(double seconds);
  void poll();
  // The first EEG sample taken at or after host instant `host_s` (the clock model).
  std::int64_t sampleAt(double host_s) const;
  // What the screen showed from `host_s` on (the simulated subject's virtual photodiode).
  void displayed(double host_s, bool patch_lit);

  // A new selection: its stimuli (objects, or grid rows and columns), what the subject attends
  // (the simulated subject looks there; online, the trial's intention, which labels the flashes
  // T and N in the recording, or U when `attended` is empty: not known), and for the calibration
  // run the cued target.
  void startSelection(bool objects, const bci::ParadigmLayout& layout,
                      const std::set<int>& attended, std::optional<int> target);
  // A flash first presented at `sample` (its onset); epoched and shown to the subject now.
  // A flash first shown at `host_s` (the frame's presentation), stamped `sample`.
  void flash(int code, std::int64_t sample, double host_s);
  // Its measured duration, once the frame after its last is presented: recorded then, as
  // "Stim <code> T|N" (grid codes as 100 + code) with the duration.
  void flashEnded(std::int64_t onset_sample, int duration_samples);
  void annotate(std::int64_t sample, const std::string& text);
  // A selection's feedback first presented at `sample`: the codes shown as chosen (grid codes as
  // the paradigm's), whether it is wrong (known: the calibration block's deliberate errors, or
  // the trial's intention; unknown: nullopt). Shown to the subject, recorded, and epoched for the
  // ErrP classifier (training data in the calibration run, scored online).
  void feedback(const std::set<int>& codes, bool objects, std::optional<bool> error,
                std::int64_t sample);
  // The ErrP classifier's score of the latest feedback, once its epoch is complete (each once).
  std::optional<double> takeErrpScore();
  bool hasErrpModel() const { return model_ && model_->errp != nullptr; }

  bool hasModel() const { return model_.has_value(); }
  const std::optional<bci::P300Model>& model() const { return model_; }
  // The ERP averages behind the session's own training (none for a model loaded from a file).
  const std::optional<bci::ErpCurves>& trainedErp() const { return trained_erp_; }
  const std::optional<bci::ErpCurves>& trainedErrpErp() const { return trained_errp_erp_; }
  void setModel(bci::P300Model model);
  // Trains on the calibration run on a worker thread; trainingResult() returns it once done
  // (rethrowing a training error), waiting for it when `wait`.
  void startTraining(const std::string& method);
  bool training() const { return training_.valid(); }
  std::optional<TrainingOutcome> trainingResult(bool wait);

  // Every presented flash of the current selection has been scored.
  bool selectionScored() const;
  int scoredSequences() const;
  bci::Decision decide() const;

  std::int64_t lostSamples() const { return acquisition_->lostSamples(); }
  std::int64_t missedEpochs() const;
  std::int64_t samplesRecorded() const;
  double clockDriftPpm() const { return acquisition_->driftPpm(); }
  double clockJitterMs() const { return acquisition_->jitterS() * 1000.0; }
  // The source's own account (an LSL stream's name, host, rates, clock offset) and its fault.
  std::string sourceLine() const;
  std::string sourceFault() const;
  // Epochs left out because they overlapped lost samples.
  std::int64_t discardedEpochs() const { return discarded_; }
  // Live: waits (at most `timeout_s`) until the samples taken up to host instant `host_s` have
  // arrived and are recorded, so the last flashes' EEG and photodiode edges are in the file.
  void drainUntil(double host_s, double timeout_s);
  void close();

  // For the panels: the latest filtered samples of each channel (up to `samples`).
  std::vector<std::vector<float>> recentSignal(int samples) const;

 private:
  struct FlashRecord {
    int selection = 0;
    int code = 0;
    bool target = false;
    bool objects = true;
    bool known = true;
  };
  bci::Block eegOnly(const bci::Block& block) const;

  EegStageSettings settings_;
  bool stepped_;
  SessionLog& log_;
  std::ostream* progress_;
  std::int64_t lost_logged_ = 0;  // lost samples already in the log
  std::string fault_logged_;      // the source's fault last logged (empty: none)
  // Stretches of lost samples [first, end): epochs touching them are discarded, not scored.
  std::vector<std::pair<std::int64_t, std::int64_t>> lost_spans_;
  std::int64_t discarded_ = 0;
  bool touchesLoss(std::int64_t onset) const;
  std::unique_ptr<bci::lsl::Outlet> markers_;  // lsl.markers: the session's events on LSL
  // An event at `host_s` (the host clock, which is LSL's) to the Markers stream; a run on the
  // simulated clock stamps the instant it is sent.
  void publish(const std::string& text, double host_s);
  double time_s_ = 0.0;  // the last cycle's session time, for the log
  std::unique_ptr<bci::Acquisition> acquisition_;
  bci::SignalInfo eeg_info_;
  int photodiode_ = -1;  // the photodiode's channel in the source's blocks
  std::unique_ptr<bci::RecordingWriter> writer_;
  std::unique_ptr<bci::FilterChain> filters_;
  std::unique_ptr<bci::Epocher> epocher_;
  std::optional<bci::P300Model> model_;
  std::optional<bci::ErpCurves> trained_erp_, trained_errp_erp_;
  std::optional<bci::FeatureExtractor> extractor_;
  // Calibration data, for training.
  bci::Recording calibration_;
  bool keep_signal_ = true;
  std::future<TrainingOutcome> training_;
  std::map<std::int64_t, FlashRecord> flashes_;     // by onset sample, until epoched
  std::map<std::int64_t, FlashRecord> unrecorded_;  // by onset sample, until its duration is known
  int selection_ = 0;
  bool selection_objects_ = true;
  std::optional<int> target_;
  std::set<int> truth_;  // the attended codes, empty when not known
  std::optional<bci::SelectionAccumulator> accumulator_;
  int presented_ = 0, scored_ = 0;
  std::vector<std::vector<float>> recent_;
  // ErrP: the calibration block's feedbacks (bci::kErrorFeedbackCode, kCorrectFeedbackCode), the
  // online filters and epocher.
  std::vector<bci::StimulusEvent> errp_stimuli_;
  std::unique_ptr<bci::FilterChain> errp_filters_;
  std::unique_ptr<bci::Epocher> errp_epocher_;
  std::optional<bci::FeatureExtractor> errp_extractor_;
  std::optional<double> errp_score_;
  std::int64_t errp_pending_ = -1;  // the onset of the feedback whose score is awaited
};

}  // namespace arbci::app
