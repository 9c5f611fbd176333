// The recording stage on hand-built records: every block as acquired into the BDF+ file, the
// last cycle's notes, each flash with its label once its duration is known, the feedback shown,
// every stretch of lost samples — read back from the file by the project's reader.
#include <gtest/gtest.h>

#include "arbci/bci/recording.h"
#include "arbci/session/stages/recording_stage.h"
#include "support/file_size_limit.h"
#include "support/stage_bench.h"

namespace arbci::session {
namespace {

bci::SignalInfo twoChannels() {
  bci::SignalInfo info;
  info.rate_hz = 256.0;
  info.block_size = 16;
  info.channels = {"Cz", "Pz"};
  return info;
}

// A block whose samples count up from `first` (channel 2 negated), in microvolts.
bci::Block block(std::int64_t first) {
  bci::Block b(first, 2, 16);
  for (int k = 0; k < 16; ++k) {
    b.at(0, k) = static_cast<float>(first + k);
    b.at(1, k) = -static_cast<float>(first + k);
  }
  return b;
}

class RecordingStageTest : public ::testing::Test {
 protected:
  RecordingStageTest()
      : bench_("recording"),
        path_(bench_.folder() / "recording.bdf"),
        stage_(std::make_unique<RecordingStage>(
            RecordingSettings{path_, twoChannels(), {{"Session", "test"}}}, bench_.services())) {}
  // Steps with this cycle's blocks from `first` (whole seconds: BDF records of one second).
  void cycleWith(std::int64_t first, int blocks) {
    for (int i = 0; i < blocks; ++i) bench_.record.eeg.blocks.push_back(block(first + 16 * i));
    bench_.step(*stage_);
    bench_.next();
  }
  bci::Recording closeAndRead(const std::string& reason = "finished") {
    Cycle c = bench_.cycle();
    stage_->stop(c, reason);
    return bci::readRecording(path_);
  }
  test::StageBench bench_;
  std::filesystem::path path_;
  std::unique_ptr<RecordingStage> stage_;
};

TEST_F(RecordingStageTest, EveryBlockIsWrittenAsAcquired) {
  cycleWith(0, 16);
  EXPECT_EQ(bench_.previous.recording.samples, 256);
  cycleWith(256, 16);
  const bci::Recording r = closeAndRead();
  ASSERT_EQ(r.samples, 512);
  ASSERT_EQ(r.info.channels, twoChannels().channels);
  for (std::int64_t s : {0, 17, 300, 511}) {
    EXPECT_NEAR(r.at(0, s), static_cast<float>(s), 0.05) << s;
    EXPECT_NEAR(r.at(1, s), -static_cast<float>(s), 0.05) << s;
  }
  EXPECT_EQ(r.parameters.at("Session"), "test");
}

TEST_F(RecordingStageTest, AFlashIsRecordedWithItsLabelOnceItsDurationIsKnown) {
  bench_.record.presentation.onsets.push_back({Flash{3, true, true, true, 1}, 40});
  bench_.record.presentation.onsets.push_back({Flash{2, false, false, true, 1}, 100});
  cycleWith(0, 16);
  bench_.record.presentation.ended.push_back({40, 17});
  bench_.record.presentation.ended.push_back({100, 15});
  cycleWith(256, 16);
  const bci::Recording r = closeAndRead();
  ASSERT_EQ(r.stimuli.size(), 2u);
  EXPECT_EQ(r.stimuli[0].sample, 40);
  EXPECT_EQ(r.stimuli[0].code, 3);
  EXPECT_TRUE(r.stimuli[0].target);
  EXPECT_EQ(r.stimuli[0].duration_samples, 17);
  // A grid flash is recorded as 100 + its code.
  EXPECT_EQ(r.stimuli[1].code, 102);
  EXPECT_FALSE(r.stimuli[1].target);
}

TEST_F(RecordingStageTest, NotesLossesAndFeedbackAreRecordedAndTheEndSaysWhy) {
  // The last cycle's notes go into this cycle's part of the file.
  bench_.previous.annotations.push_back({20, "Phase calibration: flashing", 0});
  bench_.record.eeg.losses.push_back({64, 32, "gap in the stream"});
  bench_.record.presentation.feedback = FeedbackShown{{1}, true, true};
  bench_.record.presentation.sample = 120;
  cycleWith(0, 16);
  const bci::Recording r = closeAndRead("aborted (by the experimenter)");
  std::vector<std::string> texts;
  for (const bci::Annotation& a : r.annotations) texts.push_back(a.text);
  const auto has = [&](const std::string& text) {
    return std::find(texts.begin(), texts.end(), text) != texts.end();
  };
  EXPECT_TRUE(has("Phase calibration: flashing"));
  EXPECT_TRUE(has("Lost 32 samples: gap in the stream"));
  EXPECT_TRUE(has("Feedback 1 error"));
  EXPECT_TRUE(has("Session ended: aborted (by the experimenter)"));
}

TEST_F(RecordingStageTest, TheExperimentersNoteGoesIntoTheRecordingAndTheLog) {
  cycleWith(0, 8);
  bench_.record.eeg_sample = 128;
  bench_.record.requests.push_back(NoteRequest{"Cz re-gelled, subject yawned"});
  cycleWith(128, 8);
  cycleWith(256, 16);
  const bci::Recording r = closeAndRead();
  bool noted = false;
  for (const bci::Annotation& a : r.annotations)
    noted |= a.text == "Note: Cz re-gelled, subject yawned" && a.sample == 128;
  EXPECT_TRUE(noted);
  const auto logged = bench_.logged("note");
  ASSERT_EQ(logged.size(), 1u);
  EXPECT_EQ(logged[0]["text"], "Cz re-gelled, subject yawned");
  EXPECT_TRUE(bench_.toldOf("note: Cz re-gelled"));
}

TEST_F(RecordingStageTest, AFlashStillLitAtTheEndIsRecordedWithoutADuration) {
  bench_.record.presentation.onsets.push_back({Flash{4, true, false, true, 1}, 200});
  cycleWith(0, 16);
  const bci::Recording r = closeAndRead();
  ASSERT_EQ(r.stimuli.size(), 1u);
  EXPECT_EQ(r.stimuli[0].code, 4);
  EXPECT_EQ(r.stimuli[0].duration_samples, 0);
}

TEST(RecordingStage, AFileThatCannotBeCreatedIsRefusedNamingIt) {
  test::StageBench bench("recording_refused");
  const std::filesystem::path path = bench.folder() / "no such folder" / "recording.bdf";
  try {
    RecordingStage stage(RecordingSettings{path, twoChannels(), {}}, bench.services());
    FAIL() << "a recording in a missing folder was created";
  } catch (const std::exception& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
  }
}

// A disk that fills mid-run (a file-size limit fails the writes as a full disk does): the run
// ends as a fault naming the file and the system's reason, nothing more is written, the stop does
// not throw, and every second written before the failure reads back exactly.
TEST_F(RecordingStageTest, AWriteThatFailsEndsTheRunAndKeepsWhatWasWritten) {
  std::int64_t first = 0;
  {
    test::FileSizeLimit limit(40 * 1024);
    for (int second = 0; second < 60 && bench_.record.end_reason.empty(); ++second) {
      for (int i = 0; i < 16; ++i) bench_.record.eeg.blocks.push_back(block(first + 16 * i));
      first += 256;
      bench_.step(*stage_);
      if (bench_.record.end_reason.empty()) bench_.next();
    }
    EXPECT_EQ(bench_.record.end_kind, "fault");
    EXPECT_NE(bench_.record.end_reason.find("recording.bdf: write failed"), std::string::npos)
        << bench_.record.end_reason;
    Cycle c = bench_.cycle();
    stage_->stop(c, bench_.record.end_reason);  // writes nothing more, throws nothing
  }
  nlohmann::json summary;
  stage_->report(summary);
  EXPECT_NE(summary["eeg"]["recording_error"].get<std::string>().find("write failed"),
            std::string::npos);
  const bci::Recording r = bci::readRecording(path_);
  EXPECT_GT(r.samples, 256 * 5);
  EXPECT_LT(r.samples, first);
  for (std::int64_t s = 0; s < r.samples; s += 97) {
    EXPECT_NEAR(r.at(0, s), static_cast<float>(s), 0.05) << s;
    EXPECT_NEAR(r.at(1, s), -static_cast<float>(s), 0.05) << s;
  }
}

}  // namespace
}  // namespace arbci::session
