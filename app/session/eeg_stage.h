// The EEG half of the cycle: polls the source, records every block and event to the session's
// BDF+ file, filters, cuts epochs around the flashes actually presented, scores them with the
// model and accumulates the scores of the current selection. It also keeps the calibration run's
// signal and trains the model from it, exactly as `arbci train` would.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "arbci/bci/decision.h"
#include "arbci/bci/eeg_source.h"
#include "arbci/bci/epocher.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/recording_writer.h"
#include "arbci/bci/sample_clock.h"
#include "session/session_config.h"

namespace arbci::app {

class EegStage {
 public:
  // Opens the source named by the session and starts the recording. Throws std::runtime_error.
  EegStage(const SessionConfig& config, const std::filesystem::path& recording_path,
           std::shared_ptr<bci::SampleClock> clock,
           const std::map<std::string, std::string>& parameters);
  ~EegStage();

  const bci::SignalInfo& info() const { return source_->info(); }
  void poll();
  // The sample index at `seconds` of the experiment's clock.
  std::int64_t sampleAt(double seconds) const;

  // A new selection: its stimuli (objects, or grid rows and columns), what the subject attends
  // (the simulated subject looks there), and for the calibration run the cued target.
  void startSelection(bool objects, const bci::ParadigmLayout& layout,
                      const std::set<int>& attended, std::optional<int> target);
  // A flash presented at `sample`; grid codes are recorded as 100 + code.
  void flash(int code, std::int64_t sample, int duration_samples);
  void annotate(std::int64_t sample, const std::string& text);

  bool hasModel() const { return model_.has_value(); }
  const std::optional<bci::P300Model>& model() const { return model_; }
  void setModel(bci::P300Model model);
  // Trains on the calibration run; returns the cross-validation report or throws with the reason.
  bci::EvaluationReport train(const std::string& method, const bci::Progress& progress = {});

  // Every presented flash of the current selection has been scored.
  bool selectionScored() const;
  int scoredSequences() const;
  bci::Decision decide() const;

  std::int64_t lostSamples() const { return lost_; }
  std::int64_t missedEpochs() const;
  std::int64_t samplesRecorded() const;
  void close();

  // For the panels: the latest filtered samples of each channel (up to `samples`).
  std::vector<std::vector<float>> recentSignal(int samples) const;

 private:
  struct FlashRecord {
    int selection = 0;
    int code = 0;
  };
  const SessionConfig& config_;
  std::shared_ptr<bci::SampleClock> clock_;
  std::unique_ptr<bci::EegSource> source_;
  std::unique_ptr<bci::RecordingWriter> writer_;
  std::unique_ptr<bci::FilterChain> filters_;
  std::unique_ptr<bci::Epocher> epocher_;
  std::optional<bci::P300Model> model_;
  std::optional<bci::FeatureExtractor> extractor_;
  // Calibration data, for training.
  bci::Recording calibration_;
  bool keep_signal_ = true;
  std::int64_t next_sample_ = 0;
  std::int64_t lost_ = 0;
  std::map<std::int64_t, FlashRecord> flashes_;  // by onset sample, until epoched
  int selection_ = 0;
  bool selection_objects_ = true;
  std::optional<int> target_;
  std::optional<bci::SelectionAccumulator> accumulator_;
  int presented_ = 0, scored_ = 0;
  std::vector<std::vector<float>> recent_;
};

}  // namespace arbci::app
