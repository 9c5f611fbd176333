#include "arbci/session/stages/errp_stage.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cmath>

#include "arbci/bci/errp_feedback.h"
#include "arbci/bci/p300_dataset.h"

namespace arbci::session {

ErrpStage::ErrpStage(const ErrpStageSettings& settings, const StageServices& services)
    : settings_(settings), s_(services) {
  // A model named in the session file means no calibration run: nothing to keep.
  keep_signal_ = settings_.enabled && settings_.model_file.empty();
  if (!settings_.model_file.empty()) {
    const bci::P300Model model = bci::P300Model::load(settings_.model_file);
    if (model.errp) {
      auc_ = model.errp_auc;
      setModel(model.errp);
    }
  }
}

ErrpStage::~ErrpStage() {
  if (training_.valid()) training_.wait();
}

void ErrpStage::setModel(std::shared_ptr<const bci::P300Model> errp, bool calibrated) {
  if (!calibrated) {
    keep_signal_ = false;
    signal_.clear();
    signal_.shrink_to_fit();
  }
  model_ = std::move(errp);
  filters_.reset();
  epocher_.reset();
  extractor_.reset();
  trained_erp_.reset();
  if (!model_) return;
  model_->checkCompatible(settings_.info, "the EEG source (for the ErrP classifier)");
  filters_ = std::make_unique<bci::FilterChain>(model_->pipeline.filter, settings_.info);
  extractor_.emplace(model_->extractor(settings_.info));
  epocher_ = std::make_unique<bci::Epocher>(settings_.info.channelCount(), settings_.info.rate_hz,
                                            model_->pipeline.window, 10.0);
}

void ErrpStage::startTraining() {
  bci::Recording recording;
  recording.source = "calibration run, ErrP feedback block";
  recording.format = "memory";
  recording.info = settings_.info;
  recording.samples = samples_;
  recording.parameters["Paradigm"] = "single stimulus, 2 stimuli";
  recording.stimuli = feedbacks_;
  // Channel-major, as a recording holds its samples.
  const int channels = settings_.info.channelCount();
  recording.data.assign(signal_.size(), 0.0f);
  for (std::int64_t s = 0; s < samples_; ++s) {
    for (int c = 0; c < channels; ++c) {
      recording.data[static_cast<size_t>(c * samples_ + s)] =
          signal_[static_cast<size_t>(s * channels + c)];
    }
  }
  training_ = std::async(
      std::launch::async, [recording = std::move(recording), pipeline = settings_.pipeline,
                           training = settings_.training]() {
        // Below the cycle's priority, as the P300 classifier's training.
        ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
        const bci::P300Dataset data = bci::buildDataset({recording}, pipeline);
        bci::TrainingResult errp = bci::trainModel(data, pipeline, training);
        errp.model.provenance["training_files"] = {"this session's ErrP feedback block"};
        return Outcome{std::move(errp.model), errp.cross_validation.report, data.erp};
      });
}

void ErrpStage::takeTraining(Cycle& cycle) {
  if (!cycle.clock.ready(training_)) return;
  ErrpPart& out = cycle.record.errp;
  try {
    Outcome outcome = training_.get();
    setModel(std::make_shared<const bci::P300Model>(std::move(outcome.model)), true);
    trained_erp_ = std::make_shared<const bci::ErpCurves>(std::move(outcome.erp));
    auc_ = outcome.report.auc;
    out.trained = outcome.report;
  } catch (const std::exception& error) {
    out.training_error = error.what();
  }
}

void ErrpStage::step(Cycle& cycle) {
  ErrpPart& out = cycle.record.errp;
  if (const auto& started = cycle.previous.paradigm.selection_started) {
    calibrating_ = started->target.has_value();
    if (!calibrating_ && keep_signal_) {
      // Online: the feedback block's signal is no longer needed.
      keep_signal_ = false;
      signal_.clear();
      signal_.shrink_to_fit();
    }
  }
  for (const Request& request : cycle.record.requests) {
    if (const auto* use = std::get_if<UseModelRequest>(&request)) {
      try {
        auc_ = use->model->errp_auc;
        setModel(use->model->errp);
      } catch (const std::exception& error) {
        s_.log.write("model_refused", cycle.time_s, {{"reason", error.what()}});
        out.training_error = error.what();
      }
    } else if (std::holds_alternative<TrainRequest>(request) && settings_.enabled) {
      startTraining();
    } else if (std::holds_alternative<RecalibrateRequest>(request) &&
               cycle.previous.paradigm.review && keep_signal_) {
      // A new feedback block comes: the classifier is trained on it alone.
      setModel(nullptr, true);
      feedbacks_.clear();
    }
  }
  const Presentation& shown = cycle.record.presentation;
  if (shown.feedback) {
    const auto& error = shown.feedback->error;
    if (calibrating_ && keep_signal_ && error) {
      // The calibration block: error feedback is the ErrP classifier's target.
      const int duration = static_cast<int>(settings_.flash_s * settings_.info.rate_hz + 0.5);
      feedbacks_.push_back({shown.sample,
                            *error ? bci::kErrorFeedbackCode : bci::kCorrectFeedbackCode, *error,
                            duration, true});
    }
    if (epocher_) {
      pending_ = shown.sample;
      epocher_->addEvent({shown.sample, 1, false, 0, false});
    }
  }
  for (const bci::Block& eeg : cycle.record.eeg.eeg_blocks) {
    if (keep_signal_) {
      for (int s = 0; s < eeg.samples; ++s) {
        for (int c = 0; c < eeg.channels; ++c) signal_.push_back(eeg.at(c, s));
      }
      samples_ += eeg.samples;
    }
    if (!epocher_) continue;
    // The ErrP's own band on the raw signal.
    bci::Block block = eeg;
    filters_->process(block);
    for (const bci::Epoch& epoch : epocher_->push(block)) {
      if (epoch.event.sample != pending_) continue;
      out.score = std::make_pair(pending_, model_->classifier->score(extractor_->features(epoch)));
      pending_ = -1;
    }
  }
  takeTraining(cycle);
  out.model = model_;
  out.auc = auc_;
  out.erp = trained_erp_;
  out.training = training_.valid();
  out.enabled = settings_.enabled;
}

void ErrpStage::report(nlohmann::json& summary) const {
  if (!settings_.enabled) return;
  summary["errp"]["classifier"] = model_ != nullptr;
  summary["errp"]["threshold"] = settings_.threshold;
  if (model_ && !std::isnan(auc_)) summary["errp"]["calibration_auc"] = auc_;
}

}  // namespace arbci::session
