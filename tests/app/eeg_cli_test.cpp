// `arbci eeg`: info on the BCI2000 sample data, simulate and convert, an independent reader
// (BioSig's save2gdf) agreeing, a recording killed mid-session still readable, and one-line
// errors for bad files.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "arbci/bci/recording.h"
#include "support/run_process.h"
#include "support/shared_data.h"
#include "support/test_files.h"

namespace arbci::test {
namespace {

const std::string kArbci = ARBCI_EXECUTABLE;

const std::string kScratch = "arbci_eeg_cli_test";

TEST(EegCommand, InfoGivesChannelsRateDurationAndEventsByCode) {
  const ProcessResult r =
      runProcess(kArbci, {"eeg", "info", sharedData("eeg/bci2000_samplefiles/eeg3_1.dat")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("channels:  8 (Fz Cz P3 Pz P4 PO7 Oz PO8)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rate:      256 Hz"), std::string::npos);
  EXPECT_NE(r.out.find("samples:   56840 (222.03 s)"), std::string::npos);
  EXPECT_NE(r.out.find("stimuli:   720 (120 targets)"), std::string::npos);
  EXPECT_NE(r.out.find("code   8:    60 (15 targets)"), std::string::npos);
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(EegCommand, SimulateThenConvertAndAnIndependentReaderAgrees) {
  const auto bdf = scratchPath(kScratch, "sim.bdf");
  ProcessResult r =
      runProcess(kArbci, {"eeg", "simulate", "--seconds", "30", "--rows", "3", "--columns", "3",
                          "--sequences", "5", "--out", bdf.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("100%"), std::string::npos);  // progress
  const bci::Recording ours = bci::readRecording(bdf);
  EXPECT_EQ(ours.samples, 30 * 256);
  ASSERT_EQ(ours.stimuli.size(), 90u);  // 3 selections of 7.4 s: 5 sequences of 6 flashes
  // Row/column: each sequence flashes 6 codes, 2 of them the target's row and column.
  int targets = 0;
  for (const auto& e : ours.stimuli) targets += e.target;
  EXPECT_EQ(targets * 3, static_cast<int>(ours.stimuli.size()));

  // BioSig's own converter writes GDF 2 from it; the GDF reads back with the same content.
  const auto gdf = scratchPath(kScratch, "sim.gdf");
  std::filesystem::remove(gdf);
  r = runProcess(SAVE2GDF_EXECUTABLE, {"-f=GDF", bdf.string(), gdf.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const bci::Recording theirs = bci::readRecording(gdf);
  EXPECT_EQ(theirs.format, "GDF");
  EXPECT_EQ(theirs.info.channels, ours.info.channels);
  EXPECT_EQ(theirs.info.rate_hz, 256.0);
  EXPECT_EQ(theirs.stimuli.size(), ours.stimuli.size());
  EXPECT_EQ(theirs.annotations.size(), ours.annotations.size());
  EXPECT_EQ(theirs.stimuli.back().sample, ours.stimuli.back().sample);

  // BCI2000 to BDF+: the same stimuli and samples.
  const auto converted = scratchPath(kScratch, "eeg3_1.bdf");
  r = runProcess(kArbci, {"eeg", "convert", sharedData("eeg/bci2000_samplefiles/eeg3_1.dat"),
                          converted.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const bci::Recording original =
      bci::readRecording(sharedData("eeg/bci2000_samplefiles/eeg3_1.dat"));
  const bci::Recording copy = bci::readRecording(converted);
  ASSERT_EQ(copy.samples, original.samples);
  ASSERT_EQ(copy.stimuli.size(), 720u);
  for (size_t i = 0; i < copy.stimuli.size(); i += 37) {
    EXPECT_EQ(copy.stimuli[i].sample, original.stimuli[i].sample);
    EXPECT_EQ(copy.stimuli[i].target, original.stimuli[i].target);
  }
  EXPECT_NEAR(copy.at(5, 30000), original.at(5, 30000), 0.001);
  EXPECT_EQ(copy.parameters.at("SamplingRate"), original.parameters.at("SamplingRate"));
  // What any EDF reader sees (MNE among them): records x record duration from the header, with
  // no padding, 222.03 s.
  std::ifstream header(converted, std::ios::binary);
  std::string fixed(256, '\0');
  header.read(fixed.data(), 256);
  const double records = std::stod(fixed.substr(236, 8)),
               record_s = std::stod(fixed.substr(244, 8));
  EXPECT_NEAR(records * record_s, original.samples / original.info.rate_hz,
              1.0 / original.info.rate_hz);
  EXPECT_EQ(r.out.find("padding"), std::string::npos) << r.out;
  // The one parameter too long for a record is named.
  EXPECT_NE(r.out.find("cut to fit a record: \"Param Classifier="), std::string::npos) << r.out;
}

TEST(EegCommand, ARecordingKilledMidWayIsReadableUpToItsLastRecord) {
  const auto bdf = scratchPath(kScratch, "killed.bdf");
  std::filesystem::remove(bdf);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    dup2(null, STDERR_FILENO);
    dup2(null, STDOUT_FILENO);
    execl(kArbci.c_str(), kArbci.c_str(), "eeg", "simulate", "--paced", "--seconds", "60", "--out",
          bdf.c_str(), nullptr);
    _exit(127);
  }
  // The header's count of data records, as the file says it now (-1 before it has one).
  const auto records = [&bdf] {
    std::ifstream in(bdf, std::ios::binary);
    std::string field(8, ' ');
    if (!in.seekg(236) || !in.read(field.data(), 8)) return -1;
    try {
      return std::stoi(field);
    } catch (const std::exception&) {
      return -1;
    }
  };
  // Killed once it has written a few records (a paced recording writes each as it completes).
  using Clock = std::chrono::steady_clock;
  const auto give_up = Clock::now() + std::chrono::seconds(60);
  while (Clock::now() < give_up && records() < 8)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const int seen = records();
  ASSERT_GE(seen, 8) << "the recording never got going";
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));

  // No salvage needed: the header always says how many whole records the file holds, and none of
  // those written before the kill is lost (what a kill can lose is the record being filled).
  const bci::Recording r = bci::readRecording(bdf);
  EXPECT_FALSE(r.truncated);
  EXPECT_GE(records(), seen);
  EXPECT_GT(r.samples, 0);
  EXPECT_FALSE(r.stimuli.empty());
  EXPECT_EQ(r.parameters.at("Source"), "ARBCI simulated subject");
  for (const auto& e : r.stimuli) EXPECT_LT(e.sample, r.samples + 256);
}

TEST(EegCommand, BadFilesGiveOneLineNamingTheFileAndWhatIsWrong) {
  const auto truncated = scratchPath(kScratch, "truncated.dat");
  {
    std::ifstream in(sharedData("eeg/bci2000_samplefiles/eeg3_1.dat"), std::ios::binary);
    std::string bytes(2000000, '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    std::ofstream(truncated, std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  const auto unknown = scratchPath(kScratch, "unknown.edf");
  std::ofstream(unknown) << "this is not EEG";
  // A BDF whose header declares no signals (BioSig says "memory allocation failed").
  const auto empty = scratchPath(kScratch, "no_signals.bdf");
  {
    std::string header(256, ' ');
    header[0] = '\xff';
    auto put = [&header](size_t at, const std::string& text) {
      header.replace(at, text.size(), text);
    };
    put(1, "BIOSEMI");
    put(168, "01.01.26");
    put(176, "00.00.00");
    put(184, "256");
    put(192, "24BIT");
    put(236, "1");
    put(244, "1");
    put(252, "0");
    std::ofstream(empty, std::ios::binary) << header;
  }
  for (const auto& [file, reason] : std::vector<std::pair<std::string, std::string>>{
           {empty.string(), "declares no signal channels"},
           {truncated.string(), "cut short"},
           {unknown.string(), "unknown format"},
           {scratchPath(kScratch, "none.gdf").string(), "no such file"}}) {
    const ProcessResult r = runProcess(kArbci, {"eeg", "info", file});
    EXPECT_EQ(r.exit_code, 1) << file;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(reason), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  // The truncated file can be salvaged.
  const ProcessResult salvaged =
      runProcess(kArbci, {"eeg", "info", "--salvage", truncated.string()});
  EXPECT_EQ(salvaged.exit_code, 0) << salvaged.err;
  EXPECT_NE(salvaged.out.find("truncated:"), std::string::npos) << salvaged.out;
  const ProcessResult wrong_out = runProcess(
      kArbci, {"eeg", "convert", sharedData("eeg/bci2000_samplefiles/eeg3_1.dat"), "x.edf"});
  EXPECT_EQ(wrong_out.exit_code, 1);
  EXPECT_NE(wrong_out.err.find("*.bdf"), std::string::npos);
}

}  // namespace
}  // namespace arbci::test
