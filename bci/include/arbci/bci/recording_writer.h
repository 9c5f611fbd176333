// Writes a session's EEG as it runs to a BDF+ file (24-bit, annotations in a "BDF Annotations"
// signal) that MNE, EEGLAB, EDFbrowser and BioSig open.
//
// Written here rather than through EDFlib or BioSig because both keep the events in memory and
// write them (and the record count) only when the file is closed: a crash would lose every event.
// This writer appends each 0.25 s data record, with the events known by then, as soon as its
// samples arrive and updates the header's record count right after, so the file on disk is
// always complete up to its last record; a background thread forces it to the disk once a second.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "arbci/bci/signal.h"

namespace arbci::bci {

struct RecordingWriterOptions {
  // Physical range of the 24-bit samples (+-8000 uV: 0.00095 uV resolution); values beyond it are
  // clipped (and counted).
  double range_microvolts = 8000.0;
  std::string subject = "X";
  std::string recording_id = "ARBCI";
  // The whole signal's length, when known before writing (a conversion): records are sized to
  // divide it (about 0.25 s each), so the file ends with the signal, with no padding.
  std::int64_t known_samples = 0;
};

class RecordingWriter {
 public:
  // Creates (or replaces) `path`; throws RecordingError naming the file when it cannot.
  // `parameters` are written as "Param name=value" annotations at time 0.
  RecordingWriter(const std::filesystem::path& path, const SignalInfo& info,
                  const std::map<std::string, std::string>& parameters = {},
                  const RecordingWriterOptions& options = {});
  ~RecordingWriter();  // closes
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  // Blocks must follow each other without gaps.
  void write(const Block& block);
  // "Stim <code> T" (target) or "Stim <code> N", with the flash's duration.
  void addStimulus(const StimulusEvent& event);
  // Phase changes, selections, robot commands.
  void addAnnotation(const Annotation& annotation);
  // Writes the last partial record (padded, and marked so ARBCI's reader trims the padding).
  void close();

  std::int64_t samplesWritten() const;
  std::int64_t clippedSamples() const;
  // Samples of padding that completed the last record (0 when records divide the signal).
  std::int64_t paddedSamples() const;
  // The beginnings of the annotations cut to fit a record (parameters among them).
  const std::vector<std::string>& shortenedTexts() const;
  // Annotations longer than a record's annotation area (about 450 characters), cut to fit.
  std::int64_t shortenedAnnotations() const;
  const std::filesystem::path& path() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace arbci::bci
