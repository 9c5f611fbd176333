#include "session/eeg_stage.h"

#include <algorithm>

#include "arbci/bci/file_source.h"
#include "arbci/bci/filters.h"
#include "arbci/bci/simulated_subject.h"

namespace arbci::app {

EegStage::EegStage(const SessionConfig& config, const std::filesystem::path& recording_path,
                   std::shared_ptr<bci::SampleClock> clock,
                   const std::map<std::string, std::string>& parameters)
    : config_(config), clock_(std::move(clock)) {
  if (config.eeg.source == "file") {
    bci::Recording replay = bci::readRecording(config.eeg.file);
    replay.stimuli.clear();  // the session presents its own stimuli
    source_ = std::make_unique<bci::FileSource>(std::move(replay), clock_, config.eeg.block_size);
  } else {
    bci::SimulatedSubjectConfig subject;
    subject.montage = config.eeg.montage;
    subject.rate_hz = config.eeg.rate_hz;
    subject.block_size = config.eeg.block_size;
    subject.seed = config.eeg.seed;
    subject.line_hz = config.eeg.line_hz;
    bci::SubjectProfile profile = bci::SubjectProfile::drawn(config.eeg.seed);
    profile.p3_amplitude_uv *= config.eeg.erp_scale;
    profile.n2_amplitude_uv *= config.eeg.erp_scale;
    subject.profile = profile;
    source_ = std::make_unique<bci::SimulatedSubject>(subject, clock_);
  }
  writer_ = std::make_unique<bci::RecordingWriter>(recording_path, source_->info(), parameters);
  filters_ = std::make_unique<bci::FilterChain>(config.pipeline.filter, source_->info());
  epocher_ = std::make_unique<bci::Epocher>(source_->info().channelCount(), source_->info().rate_hz,
                                            config.pipeline.window, 10.0);
  calibration_.source = "calibration run";
  calibration_.format = "memory";
  calibration_.info = source_->info();
  calibration_.parameters["Paradigm"] =
      "single stimulus, " + std::to_string(config.world.objects.size()) + " stimuli";
  recent_.assign(static_cast<size_t>(source_->info().channelCount()), {});
}

EegStage::~EegStage() {
  try {
    close();
  } catch (const std::exception&) {
    // A destructor does not throw; the recording holds what was written.
  }
}

std::int64_t EegStage::sampleAt(double seconds) const {
  return static_cast<std::int64_t>(seconds * info().rate_hz);
}

void EegStage::setModel(bci::P300Model model) {
  model.checkCompatible(info(), "the EEG source");
  extractor_.emplace(model.extractor(info()));
  // The online filter and window follow the model's pipeline.
  filters_ = std::make_unique<bci::FilterChain>(model.pipeline.filter, info());
  model_ = std::move(model);
  keep_signal_ = false;
  calibration_.data.clear();
  calibration_.data.shrink_to_fit();
}

void EegStage::poll() {
  for (bci::Block& block : source_->poll(256)) {
    if (block.first_sample != next_sample_) lost_ += block.first_sample - next_sample_;
    next_sample_ = block.endSample();
    writer_->write(block);
    if (keep_signal_) {
      // Stored sample-major while collecting (appending is cheap); transposed when training.
      for (int s = 0; s < block.samples; ++s) {
        for (int c = 0; c < block.channels; ++c) calibration_.data.push_back(block.at(c, s));
      }
      calibration_.samples += block.samples;
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
      if (accumulator_ && extractor_)
        accumulator_->add(record.code, model_->classifier->score(extractor_->features(epoch)));
    }
  }
}

void EegStage::startSelection(bool objects, const bci::ParadigmLayout& layout,
                              const std::set<int>& attended, std::optional<int> target) {
  ++selection_;
  selection_objects_ = objects;
  target_ = target;
  presented_ = scored_ = 0;
  source_->attend(attended);
  accumulator_.reset();
  if (model_) accumulator_.emplace(layout, model_->score_model);
}

void EegStage::flash(int code, std::int64_t sample, int duration_samples) {
  bci::StimulusEvent event{sample, code, target_ && *target_ == code, duration_samples};
  source_->present(event);
  bci::StimulusEvent recorded = event;
  if (!selection_objects_) recorded.code += 100;
  writer_->addStimulus(recorded);
  if (target_ && keep_signal_) calibration_.stimuli.push_back(event);
  flashes_[sample] = {selection_, code};
  epocher_->addEvent(event);
  ++presented_;
}

void EegStage::annotate(std::int64_t sample, const std::string& text) {
  writer_->addAnnotation({sample, text, 0});
}

bci::EvaluationReport EegStage::train(const std::string& method, const bci::Progress& progress) {
  // Channel-major, as a recording holds its samples.
  bci::Recording recording = calibration_;
  const int channels = info().channelCount();
  recording.data.assign(calibration_.data.size(), 0.0f);
  for (std::int64_t s = 0; s < calibration_.samples; ++s) {
    for (int c = 0; c < channels; ++c) {
      recording.data[static_cast<size_t>(c * calibration_.samples + s)] =
          calibration_.data[static_cast<size_t>(s * channels + c)];
    }
  }
  bci::TrainingSettings settings;
  settings.method = method;
  settings.folds = 4;
  const bci::P300Dataset data = bci::buildDataset({recording}, config_.pipeline, progress);
  bci::TrainingResult result = bci::trainModel(data, config_.pipeline, settings, progress);
  result.model.provenance["training_files"] = {"this session's calibration run"};
  setModel(std::move(result.model));
  return result.cross_validation.report;
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

void EegStage::close() {
  if (writer_) writer_->close();
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
