// The XDF reader against damaged files, systematically: every writer-made file (zero-sample
// streams, 2-channel string markers, a clock reset, a break) cut at every byte, each bit of its
// first 2 KB flipped, bytes overwritten, and two files spliced at many points. Every case either
// reads or is refused with a RecordingError; nothing else (a crash, another exception) is
// allowed. Run it under the debug preset's sanitizers for memory errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "arbci/bci/recording.h"
#include "support/test_files.h"
#include "support/xdf_writer.h"

namespace arbci::bci {
namespace {

test::XdfNumericStream eegStream(int samples) {
  test::XdfNumericStream s;
  s.name = "Amp";
  s.labels = {"Fz", "Cz", "Pz"};
  for (int i = 0; i < samples; ++i)
    s.samples.push_back({static_cast<float>(i), static_cast<float>(std::sin(i * 0.1)), 1.0f});
  return s;
}

// The files the cases start from: what LabRecorder writes, and what real files hold.
std::vector<std::string> seeds() {
  std::vector<std::string> out;
  const auto path = test::freshTempPath("xdf_fuzz", "seed.xdf");
  const test::XdfNumericStream eeg = eegStream(300);
  const double t0 = eeg.first_timestamp;
  test::writeXdf(path, eeg, {{t0 + 0.1, "flash 1 target"}, {t0 + 0.5, "note"}});
  out.push_back(test::fileBytes(path));
  test::XdfExtras extras;
  extras.empty_stream = true;
  extras.marker_channels = 2;
  test::writeXdf(path, eeg, {{t0 + 0.2, "flash 2 nontarget", {"detail"}}}, extras);
  out.push_back(test::fileBytes(path));
  test::XdfExtras reset;
  for (int s = 0; s < 300; ++s)
    reset.eeg_stamps.push_back(s < 150 ? 500000.0 + s / 256.0
                                       : 10.0 + s / 256.0 + (s >= 200 ? 2.0 : 0.0));
  reset.eeg_offsets = {{500000.0, -499000.0}, {500000.5, -499000.0}, {10.7, 990.0}, {13.0, 990.0}};
  reset.marker_offsets = reset.eeg_offsets;
  test::writeXdf(path, eeg, {{500000.1, "flash 1 target"}, {11.0, "flash 2 target"}}, reset);
  out.push_back(test::fileBytes(path));
  return out;
}

// Reads `bytes` as a file: true when read, false when refused; fails the test on anything else.
bool readsOrRefuses(const std::string& bytes, const std::filesystem::path& path, bool salvage) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  ReadOptions options;
  options.salvage_truncated = salvage;
  try {
    const Recording r = readRecording(path, options);
    EXPECT_EQ(r.data.size(), static_cast<size_t>(r.samples) * r.info.channels.size());
    for (const StimulusEvent& e : r.stimuli) EXPECT_TRUE(e.sample >= 0 && e.sample < r.samples);
    return true;
  } catch (const RecordingError&) {
    return false;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a RecordingError: " << e.what();
    return false;
  }
}

TEST(XdfFuzz, CutFlippedOverwrittenAndSplicedFilesAreReadOrRefusedNeverACrash) {
  const auto path = test::freshTempPath("xdf_fuzz", "case.xdf");
  const std::vector<std::string> files = seeds();
  int cases = 0, read = 0;
  std::uint32_t state = 2026;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return state >> 8;
  };
  for (const std::string& file : files) {
    for (size_t at = 0; at < file.size(); ++at, ++cases)
      read += readsOrRefuses(file.substr(0, at), path, at % 2 == 0);
    for (size_t bit = 0; bit < std::min<size_t>(file.size(), 2048) * 8; ++bit, ++cases) {
      std::string copy = file;
      copy[bit / 8] = static_cast<char>(copy[bit / 8] ^ (1 << (bit % 8)));
      read += readsOrRefuses(copy, path, bit % 3 == 0);
    }
    for (int k = 0; k < 2000; ++k, ++cases) {
      std::string copy = file;
      const size_t where = next() % copy.size();
      for (size_t i = where; i < std::min(copy.size(), where + 1 + next() % 8); ++i)
        copy[i] = static_cast<char>(next());
      read += readsOrRefuses(copy, path, k % 2 == 0);
    }
  }
  for (int k = 0; k < 3000; ++k, ++cases) {
    const std::string& a = files[next() % files.size()];
    const std::string& b = files[next() % files.size()];
    const std::string spliced = a.substr(0, next() % a.size()) + b.substr(next() % b.size());
    read += readsOrRefuses(spliced, path, k % 2 == 0);
  }
  EXPECT_GT(cases, 50000) << read << " read, " << cases - read << " refused";
}

}  // namespace
}  // namespace arbci::bci
