// Writes XDF files (the format LabRecorder records, spec 1.0) for the tests: our own writer, so
// that the reader is checked against a file whose every sample and event is known, including
// what real files hold (clock resets, breaks, empty streams, string markers of several channels).
#pragma once

#include <filesystem>
#include <string>
#include <utility>
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
  XdfMarker(double at, std::string what, std::vector<std::string> rest = {})
      : timestamp(at), text(std::move(what)), more(std::move(rest)) {}
  double timestamp = 0.0;
  std::string text;
  std::vector<std::string> more;  // channels 2.. (XdfExtras::marker_channels)
};

struct XdfExtras {
  std::vector<double> eeg_stamps;  // per sample; empty: first_timestamp + s / rate
  // Clock offset chunks (collection time, offset); empty: one (first_timestamp, 0) each.
  std::vector<std::pair<double, double>> eeg_offsets, marker_offsets;
  int marker_channels = 1;
  // The marker stream's desc/arbci/parameter elements, as ARBCI's outlets write them.
  std::vector<std::pair<std::string, std::string>> marker_parameters;
  bool empty_stream = false;  // a third stream (float32, 100 Hz) with a header and no sample
  bool footers = true;
  bool empty_stream_footer = true;  // with `footers`: the empty stream's too
};

// One numeric stream (stream 1, chunks of 100 samples, each stamped) and one string Markers
// stream (stream 2), with their clock offsets and footers.
void writeXdf(const std::filesystem::path& path, const XdfNumericStream& eeg,
              const std::vector<XdfMarker>& markers, const XdfExtras& extras = {});

}  // namespace arbci::test
