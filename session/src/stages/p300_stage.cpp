#include "arbci/session/stages/p300_stage.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "arbci/bci/learning_from_use.h"
#include "arbci/bci/p300_dataset.h"
#include "arbci/session/session_config.h"

namespace arbci::session {

P300Stage::P300Stage(const P300Settings& settings, const StageServices& services)
    : settings_(settings), s_(services) {
  const bci::SignalInfo& info = settings_.info;
  filters_ = std::make_unique<bci::FilterChain>(settings_.pipeline.filter, info);
  filter_settings_ = settings_.pipeline.filter;
  epocher_ = std::make_unique<bci::Epocher>(info.channelCount(), info.rate_hz,
                                            settings_.pipeline.window, kHistoryS);
  calibration_.source = "calibration run";
  calibration_.format = "memory";
  calibration_.info = info;
  calibration_.parameters["Paradigm"] =
      "single stimulus, " + std::to_string(settings_.object_stimuli) + " stimuli";
  if (!settings_.model_file.empty()) setModel(bci::P300Model::load(settings_.model_file), 0.0);
  if (learns()) {
    state_.adapting = !settings_.learn;
    state_.trusted = state_.adapting;
    published_ = std::make_shared<const LearningState>(state_);
  }
}

P300Stage::~P300Stage() {
  if (training_.valid()) training_.wait();
  if (refit_.valid()) refit_.wait();
}

void P300Stage::setModel(const bci::P300Model& model, double time_s, bool calibrated) {
  model.checkCompatible(settings_.info, "the EEG source");
  trained_erp_.reset();  // the averages belong to the model this session trained, not this one
  if (model.pipeline.zero_phase) {
    // Online filtering must be causal: the features lag where the model's did not.
    const std::string text =
        "the model was trained with zero-phase (offline) filters; the session filters causally, "
        "so its features lag the model's: train without --zero-phase for online use";
    s_.log.write("model_warning", time_s, {{"text", text}});
    s_.tell.say(time_s, Severity::Warning, text);
  }
  extractor_.emplace(model.extractor(settings_.info));
  // The online filter follows the model's pipeline. The same filter goes on as it is: a fresh one
  // would start in the middle of the signal, and its start-up would reach the next epochs.
  if (!(model.pipeline.filter == filter_settings_)) refilter(model.pipeline.filter);
  model_ = std::make_shared<const bci::P300Model>(model);
  model_selections_ = std::numeric_limits<int>::max();  // trained on labels, or given
  if (calibrated || learns()) return;
  keep_signal_ = false;
  calibration_.data.clear();
  calibration_.data.shrink_to_fit();
}

void P300Stage::refilter(const bci::FilterSettings& filter) {
  // Another filter: it starts on the raw signal kept (its history's first sample its steady
  // state), and the epochs not yet cut are cut from its output over that history, so no flash
  // still to be scored sees two filters or the new one's start.
  filters_ = std::make_unique<bci::FilterChain>(filter, settings_.info);
  filter_settings_ = filter;
  const bci::SignalInfo& info = settings_.info;
  missed_before_ += epocher_->missed();
  epocher_ = std::make_unique<bci::Epocher>(info.channelCount(), info.rate_hz,
                                            settings_.pipeline.window, kHistoryS);
  for (const auto& [sample, flash] : flashes_) epocher_->addEvent(flash.event);
  for (bci::Block block : raw_history_) {
    filters_->process(block);
    refiltered_.push_back(std::move(block));
  }
}

void P300Stage::keepRaw(const bci::Block& block) {
  raw_history_.push_back(block);
  std::int64_t kept = 0;
  for (const bci::Block& b : raw_history_) kept += b.samples;
  const auto limit = static_cast<std::int64_t>(kHistoryS * settings_.info.rate_hz);
  while (!raw_history_.empty() && kept - raw_history_.front().samples >= limit) {
    kept -= raw_history_.front().samples;
    raw_history_.pop_front();
  }
}

void P300Stage::recalibrate() {
  // The calibration run starts over: no model until it is trained again, on the new run's
  // selections only (the signal is kept whole: the new flashes index into it).
  model_.reset();
  extractor_.reset();
  accumulator_.reset();
  trained_erp_.reset();
  calibration_.stimuli.clear();
  calibration_selection_.clear();
}

void P300Stage::completeSelection() {
  complete_ = selection_;
  // Only models that could have been trusted (fitted on as many selections as trust asks, or not
  // learnt at all) say what a trusted one can show: the first, fitted on two or three selections,
  // would hold every later model to their chance-level scores.
  if (!current_scored_.code.empty() && model_selections_ >= settings_.trust.min_selections)
    held_out_.push_back(std::move(current_scored_));
  current_scored_ = {};
}

void P300Stage::startSelection(const SelectionStart& selection) {
  if (current_learnable_) completeSelection();  // the selection just over
  current_scored_ = {};
  current_learnable_ = learns() && !selection.target && selection.objects;
  if (learns() && selection.target) known_[selection.selection] = *selection.target - 1;
  layout_ = selection.layout;
  current_epochs_.clear();
  if (!selection.target && keep_signal_ && model_ && !learns()) {
    // Online: the calibration signal is no longer needed.
    keep_signal_ = false;
    calibration_.data.clear();
    calibration_.data.shrink_to_fit();
  }
  if (selection.retake_of && keep_signal_) {
    // Its flashes so far are no whole selection: gone from what training sees (the recording
    // keeps them, with the paradigm's annotation).
    const int cut = *selection.retake_of;
    size_t kept = 0;
    for (size_t i = 0; i < calibration_.stimuli.size(); ++i) {
      if (calibration_selection_[i] == cut) continue;
      calibration_.stimuli[kept] = calibration_.stimuli[i];
      calibration_selection_[kept++] = calibration_selection_[i];
    }
    calibration_.stimuli.resize(kept);
    calibration_selection_.resize(kept);
    left_out_.push_back(cut);
  }
  selection_ = selection.selection;
  if (selection.trial > 0) trial_of_[selection.selection] = selection.trial;
  calibrating_ = selection.target.has_value();
  presented_ = scored_ = 0;
  // The online selection just over joins those of its kind; the new one is decided under the
  // model's score model held to what they showed.
  if (online_kind_ >= 0 && !online_scored_.code.empty())
    decided_[online_kind_].push_back(std::move(online_scored_));
  online_scored_ = {};
  online_kind_ = selection.target ? -1 : (selection.objects ? 0 : 1);
  accumulator_.reset();
  if (model_) accumulator_.emplace(selection.layout, scoreModelNow());
}

bci::ScoreModel P300Stage::scoreModelNow() {
  bci::ScoreModel model = model_->score_model;
  held_out_now_.reset();
  // Learnt object selections are bounded at each fit (startRefit), by the selections its rule
  // keeps; every other online kind here, by the selections of that kind decided so far.
  if (online_kind_ < 0 || (learns() && online_kind_ == 0)) return model;
  const auto& decided = decided_[online_kind_];
  if (static_cast<int>(decided.size()) < bci::kMinHeldOutSelections) return model;
  held_out_now_ = bci::boundByHeldOut(model, decided, layout_).held_out;
  return model;
}

bci::Recording P300Stage::keptSignal() const {
  // A copy, channel-major as a recording holds its samples: the cycle keeps recording meanwhile.
  bci::Recording recording = calibration_;
  const int channels = settings_.info.channelCount();
  recording.data.assign(calibration_.data.size(), 0.0f);
  for (std::int64_t s = 0; s < calibration_.samples; ++s) {
    for (int c = 0; c < channels; ++c) {
      recording.data[static_cast<size_t>(c * calibration_.samples + s)] =
          calibration_.data[static_cast<size_t>(s * channels + c)];
    }
  }
  return recording;
}

void P300Stage::startTraining(const std::string& method) {
  bci::Recording recording = keptSignal();
  bci::TrainingSettings training = settings_.training;
  training.method = method;
  std::vector<int> trained_on = calibration_selection_;
  trained_on.erase(std::unique(trained_on.begin(), trained_on.end()), trained_on.end());
  // Selections as the paradigm numbered them, never as gaps split them: one interrupted and
  // resumed is one selection with a pause inside.
  bci::DatasetOptions options;
  for (size_t i = 0; i < calibration_.stimuli.size(); ++i)
    if (i == 0 || calibration_selection_[i] != calibration_selection_[i - 1])
      options.selection_starts.push_back(calibration_.stimuli[i].sample);
  training_ = std::async(
      std::launch::async,
      [recording = std::move(recording), pipeline = bci::withMethodRate(settings_.pipeline, method),
       training, trained_on = std::move(trained_on), left_out = left_out_, options]() {
        // Below the cycle's priority (Linux nice is per thread): on a machine with few cores the
        // frames come first and the training takes what is left.
        ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
        const bci::P300Dataset data = bci::buildDataset({recording}, pipeline, {}, options);
        bci::TrainingResult result = bci::trainModel(data, pipeline, training);
        result.model.provenance["training_files"] = {"this session's calibration run"};
        return Outcome{std::move(result.model), result.cross_validation.report, data.erp,
                       trained_on, left_out};
      });
}

void P300Stage::takeTraining(Cycle& cycle) {
  P300Part& out = cycle.record.p300;
  if (!cycle.clock.ready(training_)) return;
  try {
    Outcome outcome = training_.get();  // rethrows the worker's error
    setModel(outcome.model, cycle.time_s, true);
    trained_erp_ = std::make_shared<const bci::ErpCurves>(std::move(outcome.erp));
    frozen_ = model_;
    out.trained = outcome.report;
    out.trained_on = std::move(outcome.trained_on);
    out.left_out = std::move(outcome.left_out);
  } catch (const std::exception& error) {
    out.training_error = error.what();
  }
}

void P300Stage::startRefit() {
  // As startTraining, fitted below the cycle's priority: the selections complete so far only
  // (not one under way).
  fitted_ = complete_;
  bci::Recording recording = keptSignal();
  recording.stimuli.clear();
  std::vector<int> numbers;
  for (size_t i = 0; i < calibration_.stimuli.size(); ++i) {
    if (calibration_selection_[i] > fitted_) continue;
    recording.stimuli.push_back(calibration_.stimuli[i]);
    numbers.push_back(calibration_selection_[i]);
  }
  bci::TrainingSettings training = settings_.training;
  training.method = model_ ? model_->method : settings_.training.method;
  const std::shared_ptr<const bci::P300Model> frozen = state_.adapting ? frozen_ : nullptr;
  state_.fitting = true;
  std::map<int, int> previous;
  for (const auto& [number, code] : state_.post_hoc) previous[number] = code - 1;
  refit_ = std::async(
      std::launch::async,
      [recording = std::move(recording), numbers = std::move(numbers), known = known_, previous,
       pipeline = bci::withMethodRate(settings_.pipeline, training.method), training, frozen,
       held_out = held_out_, objects = bci::ParadigmLayout::single(settings_.object_stimuli)]() {
        ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
        LearningOutcome out;
        out.fit = bci::learnFromUse(recording, numbers, known, previous, pipeline, training);
        // Its certainty may claim no more than the selections decided so far, scored by models
        // that had not seen them, show.
        out.separation = bci::boundByHeldOut(out.fit.model.score_model, held_out, objects);
        out.fit.model.provenance["training_files"] = {"this session's selections"};
        out.fit.model.provenance["labels"] =
            known.empty() ? "found without labels (learning from use)"
                          : "the calibration run's, and those found for the rest (adapting)";
        if (frozen) out.frozen = bci::decodeSelections(*frozen, recording, numbers, pipeline);
        return out;
      });
}

void P300Stage::takeRefit(Cycle& cycle) {
  if (!refit_.valid() || !cycle.clock.ready(refit_)) return;
  state_.fitting = false;
  state_.fitted_through = fitted_;
  try {
    LearningOutcome outcome = refit_.get();
    bci::LearnedSelections& fit = outcome.fit;
    std::map<int, int> before;
    for (const auto& [number, code] : state_.post_hoc) before[number] = code - 1;
    const bci::Trust trust = bci::judgeTrust(fit, before, settings_.trust);
    ++state_.fits;
    state_.error.clear();
    state_.selections = static_cast<int>(fit.numbers.size());
    state_.agreeing = fit.agreeing;
    state_.restarts = fit.restarts;
    state_.consistency = fit.consistency;
    state_.beats_shuffled = fit.beats_shuffled;
    state_.shuffles = fit.shuffles;
    state_.changed = trust.changed;
    state_.post_hoc.clear();
    for (size_t k = 0; k < fit.numbers.size(); ++k) {
      if (known_.count(fit.numbers[k])) continue;  // cued: not decoded
      state_.post_hoc[fit.numbers[k]] = fit.choice[k] + 1;
    }
    state_.frozen = std::move(outcome.frozen);
    if (!state_.adapting) {
      state_.trusted = trust.trusted;
      state_.waiting_for = trust.waiting_for;
    }
    s_.log.write("learning_fit", cycle.time_s,
                 {{"fit", state_.fits},
                  {"selections", state_.selections},
                  {"agreeing", fit.agreeing},
                  {"restarts", fit.restarts},
                  {"consistency", fit.consistency},
                  {"explained", fit.explained},
                  {"shuffled_explained", fit.shuffled_explained},
                  {"beats_shuffled", fit.beats_shuffled},
                  {"p3_uv", fit.p3_uv ? nlohmann::json(*fit.p3_uv) : nlohmann::json(nullptr)},
                  {"separation_fitted", outcome.separation.fitted},
                  {"separation_held_out", outcome.separation.held_out
                                              ? nlohmann::json(*outcome.separation.held_out)
                                              : nlohmann::json(nullptr)},
                  {"post_hoc", byTrial(state_.post_hoc)},
                  {"changed", trialsOf(trust.changed)},
                  {"trusted", state_.trusted},
                  {"waiting_for", state_.waiting_for}});
    // The new model decides from here, the current selection's epochs scored again by it; the
    // online filters go on as they are (the pipeline is the session's).
    extractor_.emplace(fit.model.extractor(settings_.info));
    model_ = std::make_shared<const bci::P300Model>(std::move(fit.model));
    model_selections_ = static_cast<int>(fit.numbers.size());
    scoreCurrentAgain();
  } catch (const std::exception& error) {
    // The model before it is kept: a failed fit changes nothing the arm acts on.
    state_.error = error.what();
    s_.log.write("learning_fit_failed", cycle.time_s, {{"reason", error.what()}});
  }
  published_ = std::make_shared<const LearningState>(state_);
}

// The log names a learnt selection by its trial, as the experimenter counts them.
nlohmann::json P300Stage::byTrial(const std::map<int, int>& by_selection) const {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [number, code] : by_selection) {
    const auto trial = trial_of_.find(number);
    out[std::to_string(trial != trial_of_.end() ? trial->second : 0)] = code;
  }
  return out;
}

std::vector<int> P300Stage::trialsOf(const std::vector<int>& selections) const {
  std::vector<int> out;
  for (int number : selections) {
    const auto trial = trial_of_.find(number);
    out.push_back(trial != trial_of_.end() ? trial->second : 0);
  }
  return out;
}

void P300Stage::scoreCurrentAgain() {
  accumulator_.emplace(layout_, scoreModelNow());
  online_scored_ = {};
  current_scored_ = {};
  for (const auto& [code, epoch] : current_epochs_) scoreEpoch(code, epoch);
}

void P300Stage::scoreEpoch(int code, const bci::Epoch& epoch) {
  const double score = model_->classifier->score(extractor_->features(epoch));
  accumulator_->add(code, score);
  if (online_kind_ >= 0) {
    online_scored_.code.push_back(code);
    online_scored_.z.push_back(bci::standardised(model_->score_model, score));
  }
  if (current_learnable_) {
    current_scored_.code.push_back(code);
    current_scored_.z.push_back(bci::standardised(model_->score_model, score));
  }
}

void P300Stage::stop(Cycle& cycle, const std::string& /*reason*/) {
  if (!learns()) return;
  // The last fit, over every selection decided, gives the session's post-hoc decodings.
  if (current_learnable_ && presented_ > 0 && scored_ >= presented_) completeSelection();
  for (int round = 0; round < 2; ++round) {
    if (refit_.valid()) {
      refit_.wait();
      takeRefit(cycle);
    }
    if (complete_ > fitted_) startRefit();
  }
  cycle.record.p300.learning = published_;
}

bool P300Stage::touchesLoss(std::int64_t onset) const {
  // The epoch's window, and a second before it for the filters to settle after a gap.
  const double rate = settings_.info.rate_hz;
  const auto from = onset + static_cast<std::int64_t>(
                                std::floor((settings_.pipeline.window.start_s - 1.0) * rate));
  const auto to =
      onset + static_cast<std::int64_t>(std::ceil(settings_.pipeline.window.end_s * rate));
  for (const auto& [first, end] : lost_spans_)
    if (first < to && end > from) return true;
  return false;
}

void P300Stage::process(const bci::Block& eeg, double time_s) {
  bci::Block block = eeg;
  if (keep_signal_) {
    // Stored sample-major while collecting (appending is cheap); transposed when training.
    for (int s = 0; s < block.samples; ++s) {
      for (int c = 0; c < block.channels; ++c) calibration_.data.push_back(block.at(c, s));
    }
    calibration_.samples += block.samples;
  }
  keepRaw(block);
  filters_->process(block);
  // After a change of filter: its output over the history first (refilter()).
  std::vector<bci::Block> filtered = std::move(refiltered_);
  refiltered_.clear();
  filtered.push_back(std::move(block));
  for (const bci::Block& b : filtered) cutEpochs(b, time_s);
}

void P300Stage::cutEpochs(const bci::Block& block, double time_s) {
  for (const bci::Epoch& epoch : epocher_->push(block)) {
    const auto found = flashes_.find(epoch.event.sample);
    if (found == flashes_.end()) continue;
    const FlashRecord record = found->second;
    flashes_.erase(found);
    if (record.selection != selection_) continue;
    ++scored_;
    if (touchesLoss(epoch.event.sample)) {
      // Zeros in place of lost samples (or the filters' ringing after them): no evidence.
      ++discarded_;
      s_.log.write("epoch_discarded", time_s,
                   {{"sample", epoch.event.sample},
                    {"code", record.code},
                    {"reason", "it overlaps lost EEG samples"}});
      continue;
    }
    if (learns()) current_epochs_.emplace_back(record.code, epoch);
    if (accumulator_ && extractor_) scoreEpoch(record.code, epoch);
  }
}

void P300Stage::step(Cycle& cycle) {
  // What the paradigm and the experimenter asked for last cycle, in order: a new selection, a
  // model to use, training.
  if (const auto& started = cycle.previous.paradigm.selection_started) startSelection(*started);
  for (const Request& request : cycle.record.requests) {
    if (const auto* use = std::get_if<UseModelRequest>(&request)) {
      try {
        setModel(*use->model, cycle.time_s);
        s_.log.write("model", cycle.time_s,
                     {{"method", use->model->method}, {"provenance", use->model->provenance}});
      } catch (const std::exception& error) {
        s_.log.write("model_refused", cycle.time_s, {{"reason", error.what()}});
        s_.tell.say(cycle.time_s, Severity::Error, std::string("model refused: ") + error.what());
        cycle.record.p300.training_error = error.what();
      }
    } else if (const auto* train = std::get_if<TrainRequest>(&request)) {
      startTraining(train->method);
    } else if (std::holds_alternative<RecalibrateRequest>(request) &&
               cycle.previous.paradigm.review && keep_signal_) {
      recalibrate();
    }
  }
  // The flashes the last frame showed for the first time.
  const int duration = static_cast<int>(settings_.flash_s * settings_.info.rate_hz + 0.5);
  for (const Presentation::Onset& onset : cycle.record.presentation.onsets) {
    const Flash& f = onset.flash;
    const bci::StimulusEvent event{onset.sample, f.code, f.target, duration, f.known};
    const bool cut = std::find(left_out_.begin(), left_out_.end(), f.selection) != left_out_.end();
    if (calibrating_ && keep_signal_ && !cut) {
      calibration_.stimuli.push_back(event);
      calibration_selection_.push_back(f.selection);
    } else if (current_learnable_ && f.code <= settings_.object_stimuli) {
      // What the subject attended is what is to be learnt: never the label.
      calibration_.stimuli.push_back({onset.sample, f.code, false, duration, false});
      calibration_selection_.push_back(selection_);
    }
    flashes_[onset.sample] = {selection_, f.code, event};
    epocher_->addEvent(event);
    ++presented_;
  }
  const EegPart& eeg = cycle.record.eeg;
  for (const bci::SampleLoss& loss : eeg.losses)
    lost_spans_.emplace_back(loss.first_sample, loss.first_sample + loss.samples);
  for (const bci::Block& block : eeg.eeg_blocks) process(block, cycle.time_s);
  takeTraining(cycle);
  if (learns()) {
    // An object selection decided (its epochs all scored): fit it in with the rest.
    if (current_learnable_ && cycle.previous.paradigm.phase == bci::Phase::ObjectSelected &&
        presented_ > 0 && scored_ >= presented_ && complete_ != selection_) {
      completeSelection();
      state_.awaited_through = complete_;
      published_ = std::make_shared<const LearningState>(state_);
    }
    takeRefit(cycle);
    if (complete_ > fitted_ && !refit_.valid()) {
      startRefit();
      published_ = std::make_shared<const LearningState>(state_);
    }
    cycle.record.p300.learning = published_;
  }

  P300Part& out = cycle.record.p300;
  out.selection = selection_;
  out.presented = presented_;
  out.scored = scored_;
  out.sequences = accumulator_ ? accumulator_->completeSequences() : 0;
  out.decision = accumulator_ ? accumulator_->decide() : bci::Decision{};
  if (accumulator_) out.scored_by = accumulator_->scoreModel();
  out.held_out_separation = held_out_now_;
  out.model = model_;
  out.erp = trained_erp_;
  out.training = training_.valid();
}

void P300Stage::report(nlohmann::json& summary) const {
  summary["eeg"]["missed_epochs"] = missed_before_ + epocher_->missed();
  summary["eeg"]["discarded_epochs"] = discarded_;
}

}  // namespace arbci::session
