#include "session/eeg_stage.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ostream>
#include <thread>

#include "arbci/bci/eegdev_source.h"
#include "arbci/bci/errp_feedback.h"
#include "arbci/bci/file_source.h"
#include "arbci/bci/filters.h"
#include "arbci/bci/lsl_source.h"
#include "arbci/bci/simulated_subject.h"

namespace arbci::app {
namespace {

// A live simulated subject holds each block back this long, as a USB amplifier's buffer does;
// it knows its own delay, so its stamps stay true (a real amplifier's is measured by
// `arbci timing-check` and set as eeg.latency_ms).
constexpr double kSimulatedTransportS = 0.020;

std::unique_ptr<bci::EegSource> openSource(const EegStageSettings& settings,
                                           std::shared_ptr<bci::SampleClock> clock) {
  const EegSettings& eeg = settings.eeg;
  if (eeg.source == "lsl") {
    bci::LslSourceSettings lsl;
    lsl.name = eeg.lsl_name;
    lsl.type = eeg.lsl_type;
    lsl.resolve_timeout_s = eeg.lsl_resolve_timeout_s;
    lsl.block_size = eeg.block_size;
    lsl.expected_rate_hz = eeg.rate_hz;
    lsl.config = settings.lsl;
    try {
      return std::make_unique<bci::LslSource>(lsl);
    } catch (const bci::lsl::LslError& e) {
      throw SessionConfigError(settings.session_file + ": eeg.source = \"lsl\": " + e.what());
    }
  }
  if (eeg.source == "eegdev") {
    bci::EegdevSourceSettings device;
    device.device = eeg.eegdev_device;
    device.block_size = eeg.block_size;
    device.expected_rate_hz = eeg.rate_hz;
    try {
      return std::make_unique<bci::EegdevSource>(device);
    } catch (const bci::EegdevError& e) {
      throw SessionConfigError(settings.session_file + ": eeg.source = \"eegdev\": " + e.what());
    }
  }
  if (eeg.source == "file") {
    bci::Recording replay = bci::readRecording(eeg.file);
    replay.stimuli.clear();  // the session presents its own stimuli
    return std::make_unique<bci::FileSource>(std::move(replay), clock, eeg.block_size);
  }
  return std::make_unique<bci::SimulatedSubject>(simulatedSubjectOf(eeg), clock);
}

}  // namespace

bci::SimulatedSubjectConfig simulatedSubjectOf(const EegSettings& eeg) {
  bci::SimulatedSubjectConfig subject;
  subject.montage = eeg.montage;
  subject.rate_hz = eeg.rate_hz;
  subject.block_size = eeg.block_size;
  subject.seed = eeg.seed;
  subject.line_hz = eeg.line_hz;
  subject.photodiode = !eeg.photodiode_channel.empty();
  subject.photodiode_channel = eeg.photodiode_channel;
  bci::SubjectProfile profile = bci::SubjectProfile::drawn(eeg.seed);
  profile.p3_amplitude_uv *= eeg.erp_scale;
  profile.n2_amplitude_uv *= eeg.erp_scale;
  profile.errp_ne_amplitude_uv *= eeg.errp_scale;
  profile.errp_pe_amplitude_uv *= eeg.errp_scale;
  subject.profile = profile;
  return subject;
}

EegStageSettings EegStageSettings::of(const SessionConfig& config) {
  EegStageSettings s;
  s.eeg = config.eeg;
  s.pipeline = config.pipeline;
  s.flash_s = config.paradigm.flashSeconds();
  s.object_stimuli = static_cast<int>(config.world.objects.size());
  s.model_file = config.model_file;
  s.session_file = config.source;
  s.errp = config.paradigm.errp;
  if (s.errp) s.errp_pipeline = config.errp.pipeline(config.pipeline, config.eeg.montage);
  s.errp_training = config.errp.training();
  if (config.eeg.source == "lsl" || config.lsl.markers) s.lsl = config.lsl.config(config.source);
  s.lsl_markers = config.lsl.markers;
  s.marker_stream = config.lsl.marker_stream;
  return s;
}

void EegStageSettings::validate() const {
  for (const auto& [key, file] :
       {std::pair{"eeg.file", eeg.file}, std::pair{"classifier.model", model_file}}) {
    if (!file.empty() && !std::filesystem::exists(file))
      throw SessionConfigError(session_file + ": " + key + " = \"" + file + "\": no such file");
  }
}

EegStage::EegStage(const EegStageSettings& settings, const std::filesystem::path& recording_path,
                   bool stepped, const std::map<std::string, std::string>& parameters,
                   SessionLog& log, std::ostream* progress)
    : settings_(settings), stepped_(stepped), log_(log), progress_(progress) {
  const EegSettings& eeg = settings_.eeg;
  std::shared_ptr<bci::SampleClock> clock;
  if (stepped)
    clock = std::make_shared<bci::ManualClock>();
  else
    clock =
        std::make_shared<bci::WallClock>(eeg.source == "simulated" ? kSimulatedTransportS : 0.0);
  bci::AcquisitionSettings acquisition;
  acquisition.latency_s = eeg.latency_ms / 1000.0;
  acquisition_ = std::make_unique<bci::Acquisition>(
      openSource(settings_, clock), clock,
      stepped ? bci::Acquisition::Mode::Stepped : bci::Acquisition::Mode::Live, acquisition);
  const bci::SignalInfo& all = acquisition_->info();
  eeg_info_ = all;
  if (!eeg.photodiode_channel.empty()) {
    const auto found = std::find(all.channels.begin(), all.channels.end(), eeg.photodiode_channel);
    if (found == all.channels.end()) {
      std::string names;
      for (const auto& c : all.channels) names += (names.empty() ? "" : ", ") + c;
      throw SessionConfigError(
          settings_.session_file + ": eeg.photodiode_channel = \"" + eeg.photodiode_channel +
          "\": the EEG source has no such channel (it has: " + names + "; use \"\" for none)");
    }
    photodiode_ = static_cast<int>(found - all.channels.begin());
    eeg_info_.channels.erase(eeg_info_.channels.begin() + photodiode_);
  }
  writer_ = std::make_unique<bci::RecordingWriter>(recording_path, all, parameters);
  filters_ = std::make_unique<bci::FilterChain>(settings_.pipeline.filter, eeg_info_);
  epocher_ = std::make_unique<bci::Epocher>(eeg_info_.channelCount(), eeg_info_.rate_hz,
                                            settings_.pipeline.window, 10.0);
  calibration_.source = "calibration run";
  calibration_.format = "memory";
  calibration_.info = eeg_info_;
  calibration_.parameters["Paradigm"] =
      "single stimulus, " + std::to_string(settings_.object_stimuli) + " stimuli";
  recent_.assign(static_cast<size_t>(eeg_info_.channelCount()), {});
  if (!settings_.model_file.empty()) setModel(bci::P300Model::load(settings_.model_file));
  if (settings_.lsl_markers) {
    bci::lsl::StreamInfo info;
    info.name = settings_.marker_stream;
    info.type = "Markers";
    info.channel_count = 1;
    info.channel_format = bci::lsl::ChannelFormat::String;
    info.source_id = "arbci-session-markers:" + settings_.marker_stream;
    try {
      markers_ = std::make_unique<bci::lsl::Outlet>(info, settings_.lsl);
    } catch (const bci::lsl::LslError& e) {
      throw SessionConfigError(settings_.session_file + ": lsl.markers: " + e.what());
    }
    log_.write("lsl_markers", 0.0,
               {{"stream", info.name},
                {"port", markers_->info().v4data_port},
                {"scope", settings_.lsl.describe()}});
  }
  acquisition_->start();
}

void EegStage::step(CycleContext& cycle) {
  time_s_ = cycle.time_s;
  if (stepped_) advanceTo(cycle.time_s);
  poll();
  if (lostSamples() != lost_logged_) {
    log_.write("lost_samples", cycle.time_s,
               {{"total", lostSamples()}, {"new", lostSamples() - lost_logged_}});
    if (progress_)
      *progress_ << "\nwarning: " << lostSamples() - lost_logged_
                 << " EEG samples lost (see the recording's annotations)\n";
    lost_logged_ = lostSamples();
  }
  // A live source's fault (an LSL stream gone), logged when it starts and when it ends.
  std::string fault;
  acquisition_->withSource([&](bci::EegSource& source) { fault = source.fault(); });
  if (fault != fault_logged_) {
    log_.write("eeg_source", cycle.time_s,
               {{"fault", fault}, {"state", fault.empty() ? "delivering" : "fault"}});
    if (progress_)
      *progress_ << "\n"
                 << (fault.empty() ? "EEG source delivering again" : "warning: " + fault) << "\n";
    fault_logged_ = fault;
  }
  cycle.eeg_sample = sampleAt(cycle.host_s);
}

std::string EegStage::sourceLine() const {
  std::string line;
  acquisition_->withSource([&](bci::EegSource& source) { line = source.describe(); });
  return line;
}

std::string EegStage::sourceFault() const {
  std::string fault;
  acquisition_->withSource([&](bci::EegSource& source) { fault = source.fault(); });
  return fault;
}

void EegStage::stop(const CycleContext& cycle, const std::string& reason) {
  if (!stepped_) drainUntil(bci::hostSeconds() + 0.1, 1.0);
  annotate(sampleAt(cycle.host_s), "Session ended: " + reason);
  close();
}

EegStage::~EegStage() {
  try {
    if (training_.valid()) training_.wait();
    close();
  } catch (const std::exception&) {
    // A destructor does not throw; the recording holds what was written.
  }
}

void EegStage::advanceTo(double seconds) {
  acquisition_->advanceTo(seconds);
}

std::int64_t EegStage::sampleAt(double host_s) const {
  return acquisition_->firstSampleAtOrAfter(host_s);
}

void EegStage::displayed(double host_s, bool patch_lit) {
  acquisition_->withSource([&](bci::EegSource& s) { s.displayed(host_s, patch_lit); });
}

void EegStage::setModel(bci::P300Model model) {
  model.checkCompatible(info(), "the EEG source");
  trained_erp_.reset();  // the averages belong to the model this session trained, not this one
  trained_errp_erp_.reset();
  if (model.pipeline.zero_phase) {
    // Online filtering must be causal: the features lag where the model's did not.
    const std::string text =
        "the model was trained with zero-phase (offline) filters; the session filters causally, "
        "so its features lag the model's: train without --zero-phase for online use";
    log_.write("model_warning", time_s_, {{"text", text}});
    if (progress_) *progress_ << "\nwarning: " << text << "\n";
  }
  extractor_.emplace(model.extractor(info()));
  // The online filter and window follow the model's pipeline.
  filters_ = std::make_unique<bci::FilterChain>(model.pipeline.filter, info());
  errp_extractor_.reset();
  errp_epocher_.reset();
  if (model.errp) {
    model.errp->checkCompatible(info(), "the EEG source (for the ErrP classifier)");
    errp_filters_ = std::make_unique<bci::FilterChain>(model.errp->pipeline.filter, info());
    errp_extractor_.emplace(model.errp->extractor(info()));
    errp_epocher_ = std::make_unique<bci::Epocher>(eeg_info_.channelCount(), eeg_info_.rate_hz,
                                                   model.errp->pipeline.window, 10.0);
  }
  model_ = std::move(model);
  keep_signal_ = false;
  calibration_.data.clear();
  calibration_.data.shrink_to_fit();
}

bci::Block EegStage::eegOnly(const bci::Block& block) const {
  if (photodiode_ < 0) return block;
  bci::Block out(block.first_sample, block.channels - 1, block.samples);
  out.data = bci::withoutChannel(block.data, block.channels, block.samples, photodiode_);
  return out;
}

void EegStage::poll() {
  for (const bci::SampleLoss& loss : acquisition_->takeLosses()) {
    writer_->addAnnotation({loss.first_sample,
                            "Lost " + std::to_string(loss.samples) + " samples: " + loss.reason,
                            static_cast<int>(loss.samples)});
    lost_spans_.emplace_back(loss.first_sample, loss.first_sample + loss.samples);
  }
  for (const bci::Block& recorded : acquisition_->take()) {
    writer_->write(recorded);
    bci::Block block = eegOnly(recorded);
    if (keep_signal_) {
      // Stored sample-major while collecting (appending is cheap); transposed when training.
      for (int s = 0; s < block.samples; ++s) {
        for (int c = 0; c < block.channels; ++c) calibration_.data.push_back(block.at(c, s));
      }
      calibration_.samples += block.samples;
    }
    if (errp_epocher_) {
      // The ErrP's own band on the raw signal.
      bci::Block errp_block = block;
      errp_filters_->process(errp_block);
      for (const bci::Epoch& epoch : errp_epocher_->push(errp_block)) {
        if (epoch.event.sample != errp_pending_) continue;
        errp_score_ = model_->errp->classifier->score(errp_extractor_->features(epoch));
        errp_pending_ = -1;
      }
    }
    filters_->process(block);
    for (int c = 0; c < block.channels; ++c) {
      auto& r = recent_[static_cast<size_t>(c)];
      for (int s = 0; s < block.samples; ++s) r.push_back(block.at(c, s));
      if (r.size() > 4096) r.erase(r.begin(), r.end() - 2048);
    }
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
        log_.write("epoch_discarded", time_s_,
                   {{"sample", epoch.event.sample},
                    {"code", record.code},
                    {"reason", "it overlaps lost EEG samples"}});
        continue;
      }
      if (accumulator_ && extractor_)
        accumulator_->add(record.code, model_->classifier->score(extractor_->features(epoch)));
    }
  }
}

bool EegStage::touchesLoss(std::int64_t onset) const {
  // The epoch's window, and a second before it for the filters to settle after a gap.
  const double rate = eeg_info_.rate_hz;
  const auto from = onset + static_cast<std::int64_t>(
                                std::floor((settings_.pipeline.window.start_s - 1.0) * rate));
  const auto to =
      onset + static_cast<std::int64_t>(std::ceil(settings_.pipeline.window.end_s * rate));
  for (const auto& [first, end] : lost_spans_)
    if (first < to && end > from) return true;
  return false;
}

void EegStage::startSelection(bool objects, const bci::ParadigmLayout& layout,
                              const std::set<int>& attended, std::optional<int> target) {
  ++selection_;
  selection_objects_ = objects;
  target_ = target;
  truth_ = target ? std::set<int>{*target} : attended;
  presented_ = scored_ = 0;
  acquisition_->withSource([&](bci::EegSource& s) { s.attend(attended); });
  accumulator_.reset();
  if (model_) accumulator_.emplace(layout, model_->score_model);
}

void EegStage::publish(const std::string& text, double host_s) {
  if (!markers_) return;
  markers_->pushStrings({text}, stepped_ ? bci::lsl::localClock() : host_s);
}

void EegStage::flash(int code, std::int64_t sample, double host_s) {
  const bool target = truth_.count(code) > 0, known = !truth_.empty();
  const int nominal_duration = static_cast<int>(settings_.flash_s * eeg_info_.rate_hz + 0.5);
  bci::StimulusEvent event{sample, code, target, nominal_duration, known};
  acquisition_->withSource([&](bci::EegSource& s) { s.present(event); });
  if (target_ && keep_signal_) calibration_.stimuli.push_back(event);
  const FlashRecord record{selection_, code, target, selection_objects_, known};
  flashes_[sample] = record;
  unrecorded_[sample] = record;
  epocher_->addEvent(event);
  ++presented_;
  publish("flash " + std::to_string(selection_objects_ ? code : code + 100) + " " +
              (known ? (target ? "target" : "nontarget") : "unknown"),
          host_s);
}

void EegStage::flashEnded(std::int64_t onset_sample, int duration_samples) {
  const auto found = unrecorded_.find(onset_sample);
  if (found == unrecorded_.end()) return;
  const FlashRecord& r = found->second;
  writer_->addStimulus(
      {onset_sample, r.objects ? r.code : r.code + 100, r.target, duration_samples, r.known});
  unrecorded_.erase(found);
}

void EegStage::annotate(std::int64_t sample, const std::string& text) {
  writer_->addAnnotation({sample, text, 0});
  if (markers_) {
    // When the sample was taken: its distance from the newest one, on the host clock.
    const double now = bci::hostSeconds();
    publish(text,
            now + (static_cast<double>(sample) - acquisition_->sampleAt(now)) / eeg_info_.rate_hz);
  }
}

void EegStage::feedback(const std::set<int>& codes, bool objects, std::optional<bool> error,
                        std::int64_t sample) {
  acquisition_->withSource([&](bci::EegSource& s) { s.feedback(sample, codes); });
  std::string text = "Feedback ";
  for (int code : codes) {
    if (text.back() != ' ') text += '+';
    text += std::to_string(objects ? code : code + 100);  // as the recording codes the grid
  }
  text += error ? (*error ? " error" : " correct") : " unknown";
  annotate(sample, text);
  if (target_ && keep_signal_ && error) {
    // The calibration block: code 1 error feedback (the ErrP classifier's target), 2 correct.
    const int duration = static_cast<int>(settings_.flash_s * eeg_info_.rate_hz + 0.5);
    errp_stimuli_.push_back({sample, *error ? bci::kErrorFeedbackCode : bci::kCorrectFeedbackCode,
                             *error, duration, true});
  }
  if (errp_epocher_) {
    errp_score_.reset();
    errp_pending_ = sample;
    errp_epocher_->addEvent({sample, 1, false, 0, false});
  }
}

std::optional<double> EegStage::takeErrpScore() {
  return std::exchange(errp_score_, std::nullopt);
}

void EegStage::startTraining(const std::string& method) {
  // A copy, channel-major as a recording holds its samples: the cycle keeps recording meanwhile.
  bci::Recording recording = calibration_;
  const int channels = info().channelCount();
  recording.data.assign(calibration_.data.size(), 0.0f);
  for (std::int64_t s = 0; s < calibration_.samples; ++s) {
    for (int c = 0; c < channels; ++c) {
      recording.data[static_cast<size_t>(c * calibration_.samples + s)] =
          calibration_.data[static_cast<size_t>(s * channels + c)];
    }
  }
  const bci::PipelineSettings pipeline = settings_.pipeline;
  // The ErrP block's feedbacks on the same signal, when there are any.
  std::optional<bci::Recording> errp_recording;
  if (settings_.errp) {
    errp_recording.emplace();
    errp_recording->source = "calibration run, ErrP feedback block";
    errp_recording->format = "memory";
    errp_recording->info = recording.info;
    errp_recording->samples = recording.samples;
    errp_recording->parameters["Paradigm"] = "single stimulus, 2 stimuli";
    errp_recording->stimuli = errp_stimuli_;
  }
  training_ = std::async(std::launch::async, [recording = std::move(recording),
                                              errp_recording = std::move(errp_recording), pipeline,
                                              method, errp_pipeline = settings_.errp_pipeline,
                                              errp_settings = settings_.errp_training]() mutable {
    // Below the cycle's priority (Linux nice is per thread): on a machine with few cores the
    // frames come first and the training takes what is left.
    ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
    bci::TrainingSettings settings;
    settings.method = method;
    settings.folds = 4;
    const bci::P300Dataset data = bci::buildDataset({recording}, pipeline);
    bci::TrainingResult result = bci::trainModel(data, pipeline, settings);
    result.model.provenance["training_files"] = {"this session's calibration run"};
    TrainingOutcome outcome{
        std::move(result.model), result.cross_validation.report, {}, "", data.erp, std::nullopt};
    if (errp_recording) {
      try {
        errp_recording->data = std::move(recording.data);
        const bci::P300Dataset errp_data = bci::buildDataset({*errp_recording}, errp_pipeline);
        bci::TrainingResult errp = bci::trainModel(errp_data, errp_pipeline, errp_settings);
        errp.model.provenance["training_files"] = {"this session's ErrP feedback block"};
        outcome.errp_report = errp.cross_validation.report;
        outcome.errp_erp = errp_data.erp;
        outcome.model.errp_auc = errp.cross_validation.report.auc;
        outcome.model.errp = std::make_shared<const bci::P300Model>(std::move(errp.model));
      } catch (const std::exception& error) {
        outcome.errp_failure = error.what();
      }
    }
    return outcome;
  });
}

std::optional<TrainingOutcome> EegStage::trainingResult(bool wait) {
  if (!training_.valid()) return std::nullopt;
  if (!wait && training_.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
    return std::nullopt;
  TrainingOutcome outcome = training_.get();  // rethrows the worker's error
  setModel(outcome.model);
  trained_erp_ = outcome.erp;
  trained_errp_erp_ = outcome.errp_erp;
  return outcome;
}

bool EegStage::selectionScored() const {
  return presented_ > 0 && scored_ >= presented_;
}

int EegStage::scoredSequences() const {
  return accumulator_ ? accumulator_->completeSequences() : 0;
}

bci::Decision EegStage::decide() const {
  return accumulator_ ? accumulator_->decide() : bci::Decision{};
}

std::int64_t EegStage::missedEpochs() const {
  return epocher_->missed();
}

std::int64_t EegStage::samplesRecorded() const {
  return writer_ ? writer_->samplesWritten() : 0;
}

void EegStage::drainUntil(double host_s, double timeout_s) {
  if (acquisition_->mode() != bci::Acquisition::Mode::Live) return;
  const std::int64_t wanted = sampleAt(host_s);
  const double give_up = bci::hostSeconds() + timeout_s;
  while (samplesRecorded() < wanted && bci::hostSeconds() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    poll();
  }
}

void EegStage::close() {
  if (acquisition_) acquisition_->stop();
  if (writer_) {
    for (const auto& [sample, r] : unrecorded_)
      writer_->addStimulus({sample, r.objects ? r.code : r.code + 100, r.target, 0, r.known});
    unrecorded_.clear();
    writer_->close();
  }
}

std::vector<std::vector<float>> EegStage::recentSignal(int samples) const {
  std::vector<std::vector<float>> out;
  for (const auto& r : recent_)
    out.emplace_back(
        r.end() - std::min<std::ptrdiff_t>(samples, static_cast<std::ptrdiff_t>(r.size())),
        r.end());
  return out;
}

}  // namespace arbci::app
