#include "arbci/session/stages/recording_stage.h"

namespace arbci::session {
namespace {

bci::StimulusEvent stimulusOf(std::int64_t onset, const Flash& f, int duration) {
  return {onset, f.objects ? f.code : f.code + 100, f.target, duration, f.known};
}

}  // namespace

RecordingStage::RecordingStage(const RecordingSettings& settings, const StageServices& services)
    : s_(services),
      writer_(std::make_unique<bci::RecordingWriter>(settings.path, settings.info,
                                                     settings.parameters)) {}

void RecordingStage::record(Cycle& cycle) {
  for (const bci::Annotation& note : cycle.previous.annotations) writer_->addAnnotation(note);
  const Presentation& shown = cycle.record.presentation;
  for (const Presentation::Ended& ended : shown.ended) {
    const auto found = unrecorded_.find(ended.onset_sample);
    if (found == unrecorded_.end()) continue;
    writer_->addStimulus(stimulusOf(ended.onset_sample, found->second, ended.duration_samples));
    unrecorded_.erase(found);
  }
  for (const Presentation::Onset& onset : shown.onsets) unrecorded_[onset.sample] = onset.flash;
  if (shown.feedback) writer_->addAnnotation({shown.sample, shown.feedback->text(), 0});
  const EegPart& eeg = cycle.record.eeg;
  for (const bci::SampleLoss& loss : eeg.losses) {
    writer_->addAnnotation({loss.first_sample,
                            "Lost " + std::to_string(loss.samples) + " samples: " + loss.reason,
                            static_cast<int>(loss.samples)});
  }
  for (const bci::Block& block : eeg.blocks) writer_->write(block);
  cycle.record.recording.samples = writer_->samplesWritten();
}

// A write that fails (a full disk, an I/O error) ends the run: data that cannot be kept must not
// be collected. Every record written before it stays readable (the header counts whole records).
void RecordingStage::step(Cycle& cycle) {
  for (const NoteRequest* note : requestsOf<NoteRequest>(cycle.record.requests)) {
    s_.log.write("note", cycle.time_s, {{"text", note->text}, {"sample", cycle.eeg_sample}});
    s_.tell.say(cycle.time_s, Severity::Info, "note: " + note->text);
    cycle.annotate(cycle.eeg_sample, "Note: " + note->text);
    notes_.push_back({{"t", cycle.time_s}, {"text", note->text}});
  }
  if (!failed_.empty()) return;
  try {
    record(cycle);
  } catch (const bci::RecordingError& error) {
    failed_ = error.what();
    s_.log.write("recording_failed", cycle.time_s,
                 {{"text", failed_}, {"samples", writer_->samplesWritten()}});
    cycle.end("the recording failed: " + failed_ + " (the samples before it are kept)", "fault");
  }
}

void RecordingStage::stop(Cycle& cycle, const std::string& reason) {
  if (!failed_.empty()) return;  // nothing more can be written; what was written is whole
  try {
    record(cycle);
    writer_->addAnnotation({cycle.clock.sampleAt(cycle.host_s), "Session ended: " + reason, 0});
    for (const auto& [sample, flash] : unrecorded_)
      writer_->addStimulus(stimulusOf(sample, flash, 0));
    unrecorded_.clear();
    writer_->close();
  } catch (const bci::RecordingError& error) {
    failed_ = error.what();
    s_.log.write("recording_failed", cycle.time_s,
                 {{"text", failed_}, {"samples", writer_->samplesWritten()}});
  }
}

void RecordingStage::report(nlohmann::json& summary) const {
  summary["eeg"]["recording"] = writer_->path().filename().string();
  summary["eeg"]["samples"] = writer_->samplesWritten();
  if (!failed_.empty()) summary["eeg"]["recording_error"] = failed_;
  summary["notes"] = notes_;
}

}  // namespace arbci::session
