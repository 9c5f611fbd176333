// A whole EEG recording in memory: signals in microvolts, stimulus events, other annotations and
// parameters. Read from BCI2000 .dat (header, parameters, the state vector and samples parsed
// here: BioSig reads the samples but drops the states), and from GDF, EDF(+) and BDF(+) through
// BioSig -- including ARBCI's own session recordings (BDF+, see recording_writer.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "arbci/bci/signal.h"

namespace arbci::bci {

// A file that cannot be read as a recording; the message is one line naming the file and what is
// wrong with it.
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Recording {
  std::string source;  // the file
  std::string format;  // "BCI2000", "BDF+", "EDF+", "GDF", ...
  SignalInfo info;
  std::int64_t samples = 0;
  std::vector<float> data;  // channel-major microvolts: data[c * samples + s]
  std::vector<StimulusEvent> stimuli;
  std::vector<Annotation> annotations;
  std::map<std::string, std::string>
      parameters;  // BCI2000 parameters (value text) or session parameters
  std::map<std::string, std::vector<std::int32_t>> states;  // BCI2000 states, one value per sample
  // The file was cut short and was read up to its last complete record (salvage mode).
  bool truncated = false;
  std::string truncation_note;
  // What the reader had to make of the file, one line each (an XDF's clock resets re-anchored,
  // breaks in its EEG, markers outside the EEG): printed by `arbci eeg info`.
  std::vector<std::string> notes;

  float at(int channel, std::int64_t sample) const {
    return data[static_cast<size_t>(channel) * samples + sample];
  }
  double seconds() const { return samples / info.rate_hz; }
};

struct ReadOptions {
  // Read a file cut short (by a crash) up to its last complete record instead of refusing it.
  bool salvage_truncated = false;
};

// The format is recognised from the file's first bytes. Throws RecordingError.
Recording readRecording(const std::filesystem::path& path, const ReadOptions& options = {});
Recording readBci2000(const std::filesystem::path& path, const ReadOptions& options = {});
Recording readWithBiosig(const std::filesystem::path& path, const ReadOptions& options = {});
// XDF (LabRecorder) by a reader of our own (bci/src/xdf/): the first regular stream of type EEG
// with samples (else the regular one with most channels), its stamps and every string stream's
// on the recorder's clock (clock resets re-anchored, stretches dejittered, breaks annotated), the
// markers as stimuli ("flash <code> target", "<code> nontarget", a bare code) or annotations,
// each at the first EEG sample at or after it; ARBCI's marker streams' parameters (the stimulus
// layout) as the recording's. A file cut short, or whose streams lack their footers, is refused
// unless salvaging. See docs/eeg.md.
Recording readXdf(const std::filesystem::path& path, const ReadOptions& options = {});

// A BCI2000 parameter's numeric value with its unit: "256Hz" -> 256, "800ms" -> 0.8 (seconds),
// "0.019muV" -> 0.019. Throws RecordingError naming the parameter when it is missing or not a
// number.
double bci2000Number(const Recording& recording, const std::string& name, int index = 0);
// The value tokens of a BCI2000 parameter (URL-decoded), without the count of a list.
std::vector<std::string> bci2000Values(const Recording& recording, const std::string& name);

}  // namespace arbci::bci
