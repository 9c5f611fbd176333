// Writes XDF files (the format LabRecorder records, spec 1.0) for the tests: our own writer, so
// that the reader (libxdf) is checked against a file whose every sample and event is known.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace arbci::test {

struct XdfNumericStream {
  std::string name, type = "EEG";
  double rate = 256.0;
  std::vector<std::string> labels;
  std::string unit = "microvolts";
  std::vector<std::vector<float>> samples;  // [sample][channel]
  double first_timestamp = 100.0;
};

struct XdfMarker {
  double timestamp = 0.0;
  std::string text;
};

// One numeric stream (stream 1, chunks of 100 samples, each stamped) and one string Markers
// stream (stream 2), with a clock offset chunk for each and their footers.
void writeXdf(const std::filesystem::path& path, const XdfNumericStream& eeg,
              const std::vector<XdfMarker>& markers);

}  // namespace arbci::test
