// Session recordings: what the simulated source produces is written to BDF+ as it runs and read
// back without losing a sample or an event; EDFlib, an independent reader, sees the same file;
// a file cut short is refused with a reason or salvaged up to its last complete record.
#include <edflib.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "arbci/bci/recording.h"
#include "arbci/bci/recording_writer.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/bci/stimulus_sequence.h"
#include "support/file_size_limit.h"
#include "support/test_files.h"

namespace arbci::bci {
namespace {

struct Session {
  std::vector<Block> blocks;
  std::vector<StimulusEvent> stimuli;
  std::vector<Annotation> annotations;
  SignalInfo info;
};

// 20 s of the simulated subject with flashes every 180 ms and a selection every 5 s, written to
// `path` block by block as a session does.
Session recordSession(const std::filesystem::path& path, bool close = true) {
  auto clock = std::make_shared<UnboundedClock>();
  SimulatedSubject subject(SimulatedSubjectConfig{}, clock);
  Session session;
  session.info = subject.info();
  RecordingWriter writer(path, subject.info(), {{"Subject", "S01"}, {"FlashMs", "60"}});
  StimulusSequencer sequencer(4, 3);
  std::vector<int> order;
  std::int64_t next_flash = 100;
  subject.attend({2});
  while (subject.samplesGenerated() < 20 * 256) {
    const std::int64_t end = subject.samplesGenerated() + subject.info().block_size;
    while (next_flash < end) {
      if (order.empty()) order = sequencer.next();
      const StimulusEvent e{next_flash, order.back(), order.back() == 2, 15};
      order.pop_back();
      subject.present(e);
      writer.addStimulus(e);
      session.stimuli.push_back(e);
      if (next_flash % 1280 < 46) {
        const Annotation a{next_flash, "Selection object 2", 0};
        writer.addAnnotation(a);
        session.annotations.push_back(a);
      }
      next_flash += 46;
    }
    for (Block& b : subject.poll(1)) {
      writer.write(b);
      session.blocks.push_back(std::move(b));
    }
  }
  if (close) writer.close();
  return session;
}

std::filesystem::path temporary(const std::string& name) {
  return std::filesystem::temp_directory_path() / name;
}

TEST(Recording, RoundTripLosesNoSampleAndNoEvent) {
  const auto path = temporary("arbci_roundtrip.bdf");
  const Session session = recordSession(path);
  const Recording r = readRecording(path);
  EXPECT_EQ(r.format, "BDF+");
  EXPECT_EQ(r.info.channels, session.info.channels);
  EXPECT_EQ(r.info.rate_hz, 256.0);
  ASSERT_EQ(r.samples, 342 * 15);  // every block written; the padding of the last record is trimmed
  double worst = 0.0;
  for (const Block& b : session.blocks) {
    for (int c = 0; c < b.channels; ++c) {
      for (int s = 0; s < b.samples; ++s)
        worst = std::max(worst, std::abs(double(b.at(c, s)) - r.at(c, b.first_sample + s)));
    }
  }
  EXPECT_LT(worst, 0.0006);  // half a step of 16000 uV / 2^24
  ASSERT_EQ(r.stimuli.size(), session.stimuli.size());
  for (size_t i = 0; i < r.stimuli.size(); ++i) {
    EXPECT_EQ(r.stimuli[i].sample, session.stimuli[i].sample);
    EXPECT_EQ(r.stimuli[i].code, session.stimuli[i].code);
    EXPECT_EQ(r.stimuli[i].target, session.stimuli[i].target);
    EXPECT_EQ(r.stimuli[i].duration_samples, 15);
  }
  ASSERT_EQ(r.annotations.size(), session.annotations.size());
  EXPECT_EQ(r.annotations.front().text, "Selection object 2");
  EXPECT_EQ(r.annotations.front().sample, session.annotations.front().sample);
  EXPECT_EQ(r.parameters.at("Subject"), "S01");
  EXPECT_EQ(r.parameters.at("FlashMs"), "60");
}

TEST(Recording, EdflibReadsTheSameChannelsRateAndEvents) {
  const auto path = temporary("arbci_edflib.bdf");
  const Session session = recordSession(path);
  edf_hdr_struct header{};
  ASSERT_EQ(edfopen_file_readonly(path.c_str(), &header, EDFLIB_READ_ALL_ANNOTATIONS), 0)
      << "EDFlib error " << header.filetype;
  EXPECT_EQ(header.filetype, EDFLIB_FILETYPE_BDFPLUS);
  EXPECT_EQ(header.edfsignals, 8);
  EXPECT_STREQ(header.signalparam[3].label, "Pz              ");
  EXPECT_EQ(
      header.signalparam[0].smp_in_datarecord * EDFLIB_TIME_DIMENSION / header.datarecord_duration,
      256);
  // Every stimulus and selection, the two parameters and the end-of-signal mark.
  EXPECT_EQ(header.annotations_in_file,
            static_cast<long long>(session.stimuli.size() + session.annotations.size() + 3));
  edf_annotation_struct annotation{};
  ASSERT_EQ(edf_get_annotation(header.handle, 2, &annotation), 0);
  int stim_code = 0;
  char kind = 0;
  ASSERT_EQ(std::sscanf(annotation.annotation, "Stim %d %c", &stim_code, &kind), 2)
      << annotation.annotation;
  EXPECT_EQ(stim_code, session.stimuli[0].code);
  EXPECT_EQ(annotation.onset, session.stimuli[0].sample * EDFLIB_TIME_DIMENSION / 256);
  // Samples agree with what was written.
  std::vector<double> pz(256);
  ASSERT_EQ(edfread_physical_samples(header.handle, 3, 256, pz.data()), 256);
  for (int s = 0; s < 256; s += 17) EXPECT_NEAR(pz[s], session.blocks[s / 15].at(3, s % 15), 0.001);
  edfclose_file(header.handle);
}

TEST(Recording, FileCutShortIsRefusedWithAReasonOrSalvaged) {
  const auto path = temporary("arbci_cut.bdf");
  recordSession(path);
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 5000);  // mid-record
  try {
    readRecording(path);
    FAIL() << "a truncated file was read without salvage";
  } catch (const RecordingError& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("cut short"), std::string::npos) << error.what();
  }
  ReadOptions salvage;
  salvage.salvage_truncated = true;
  const Recording r = readRecording(path, salvage);
  EXPECT_TRUE(r.truncated);
  const int record_bytes = 8 * 64 * 3 + 513;
  const std::int64_t complete_records = 20 * 4 + 1 - (5000 + record_bytes - 1) / record_bytes;
  EXPECT_EQ(r.samples, complete_records * 64);
  EXPECT_GT(r.stimuli.size(), 90u);
}

TEST(Recording, UnwritablePathNamesTheFile) {
  SignalInfo info;
  info.rate_hz = 256.0;
  info.channels = {"Cz"};
  try {
    RecordingWriter writer("/nonexistent-folder/x.bdf", info);
    FAIL();
  } catch (const RecordingError& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent-folder/x.bdf"), std::string::npos);
  }
}

// A disk that fills during a session (here: a file-size limit, which fails writes as a full disk
// does): the write that fails throws an error naming the file, and the writer then closes and
// goes away without terminating the process (its syncing thread ends with it).
TEST(Recording, AFullDiskIsAnErrorNamingTheFileNotATerminate) {
  const auto path = test::freshTempPath("recording", "full.bdf");
  SignalInfo info;
  info.rate_hz = 256.0;
  info.channels = {"Cz", "Pz"};
  std::string error;
  std::optional<test::FileSizeLimit> limit;  // lifted after the writer has gone
  {
    RecordingWriter writer(path, info);
    limit.emplace(64 * 1024);
    try {
      for (int b = 0; b < 1000; ++b) {
        Block block(b * 256, 2, 256);
        writer.write(block);
        writer.addAnnotation({b * 256, "a note", 0});
      }
    } catch (const RecordingError& e) {
      error = e.what();
    }
  }  // destroyed with a record it cannot write: no std::terminate
  EXPECT_NE(error.find(path.string()), std::string::npos) << error;
  EXPECT_NE(error.find("write failed"), std::string::npos) << error;
}

TEST(Recording, BadFilesGiveOneLineNamingTheFileNeverACrash) {
  const auto dir = temporary("arbci_bad_eeg");
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return dir / name;
  };
  std::string edf_garbage = std::string("0       ").append(248, 'x');
  std::string bci_lying =
      "HeaderLen= 999999 SourceCh= 8 StatevectorLen= 4\r\n[ State Vector Definition ]\r\n";
  std::string bci_no_rate =
      "HeaderLen= 90 SourceCh= 2 StatevectorLen= 1\r\n[ Parameter Definition ]\r\n";
  bci_no_rate.resize(90, ' ');
  bci_no_rate += std::string(10, '\0');
  const std::vector<std::pair<std::filesystem::path, std::string>> cases{
      {write("empty.dat", ""), "empty"},
      {write("text.gdf", "hello world, no EEG here"), "unknown format"},
      {write("garbage.edf", edf_garbage), ""},
      {write("lying.dat", bci_lying), "HeaderLen"},
      {write("norate.dat", bci_no_rate), "SamplingRate"},
      {dir / "missing.bdf", "no such file"},
      {dir, "directory"},
  };
  for (const auto& [path, reason] : cases) {
    try {
      readRecording(path);
      ADD_FAILURE() << path << " was read";
    } catch (const RecordingError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(path.string()), std::string::npos) << message;
      EXPECT_NE(message.find(reason), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

}  // namespace
}  // namespace arbci::bci
