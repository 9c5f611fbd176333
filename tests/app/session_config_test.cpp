// The session file: the embedded session is the one source of defaults (a file that names one key
// leaves every other as the embedded file has it), and a bad value or key is refused with a
// message naming the key, the value and what is allowed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "arbci/assets.h"
#include "arbci/session/session.h"
#include "arbci/session/session_config.h"
#include "support/test_files.h"

namespace arbci::session {
namespace {

std::filesystem::path sessionFile(const std::string& name, const std::string& json) {
  const auto path = test::freshTempPath("config_test", name + ".json");
  std::ofstream(path) << json;
  return path;
}

std::string errorOf(const std::string& json) {
  try {
    SessionConfig::load(sessionFile("bad", json));
  } catch (const SessionConfigError& error) {
    return error.what();
  }
  return "";
}

TEST(SessionConfig, AFileNamingOneKeyKeepsEveryOtherEmbeddedDefault) {
  const SessionConfig embedded = SessionConfig::load(std::nullopt);
  const SessionConfig c =
      SessionConfig::load(sessionFile("one_key", R"({"paradigm": {"trials": 7}})"));
  EXPECT_EQ(c.paradigm.trials, 7);
  EXPECT_NE(embedded.paradigm.trials, 7);
  EXPECT_EQ(c.paradigm.flash_ms, embedded.paradigm.flash_ms);
  EXPECT_EQ(c.paradigm.isi_ms, embedded.paradigm.isi_ms);
  EXPECT_EQ(c.paradigm.sequences, embedded.paradigm.sequences);
  EXPECT_EQ(c.paradigm.min_sequences, embedded.paradigm.min_sequences);
  EXPECT_EQ(c.paradigm.certainty, embedded.paradigm.certainty);
  EXPECT_EQ(c.paradigm.calibration_selections, embedded.paradigm.calibration_selections);
  EXPECT_EQ(c.paradigm.cue_s, embedded.paradigm.cue_s);
  EXPECT_EQ(c.pipeline.window.end_s, embedded.pipeline.window.end_s);
  EXPECT_EQ(c.pipeline.decimate_hz, embedded.pipeline.decimate_hz);
  EXPECT_EQ(c.pipeline.filter.lowpass_hz, embedded.pipeline.filter.lowpass_hz);
  EXPECT_EQ(c.eeg.photodiode_channel, "Photodiode");
  EXPECT_EQ(c.eeg.latency_ms, 0.0);
}

TEST(SessionConfig, TheEmbeddedFileSetsWhatTheParserWouldOtherwiseDefault) {
  // Changing a default in the embedded file (not in code) is what a change of default means:
  // a file that sets a classifier value keeps the embedded window.
  const SessionConfig c =
      SessionConfig::load(sessionFile("classifier", R"({"classifier": {"decimate_hz": 32}})"));
  EXPECT_EQ(c.pipeline.decimate_hz, 32.0);
  EXPECT_EQ(c.pipeline.window.start_s, 0.0);
  EXPECT_EQ(c.pipeline.window.end_s, 0.8);
}

// The embedded file is the one source of defaults: it must set every key the parser reads, so no
// value in code is ever a session's default. Taking any key out of it is refused, naming the key.
TEST(SessionConfig, TheEmbeddedDefaultsMustSetEveryKey) {
  const std::string embedded(assets::embedded("sessions/simulated.json"));
  EXPECT_NO_THROW(SessionConfig::defaults(embedded, "embedded"));
  for (const auto& [setting, dotted] :
       {std::pair{"\"cue_s\": 1.5,", "paradigm.cue_s"},
        std::pair{"\"notch_hz\": 50, ", "classifier.notch_hz"},
        std::pair{"\"speed_factor\": 8, ", "robot.speed_factor"},
        std::pair{"\"photodiode_channel\": \"Photodiode\",", "eeg.photodiode_channel"},
        std::pair{"\"blur_px\": 0.5,", "cameras.blur_px"}}) {
    std::string lacking = embedded;
    const size_t at = lacking.find(setting);
    ASSERT_NE(at, std::string::npos) << setting;
    lacking.erase(at, std::string(setting).size());
    std::string message;
    try {
      SessionConfig::defaults(lacking, "embedded");
    } catch (const SessionConfigError& error) {
      message = error.what();
    }
    EXPECT_NE(message.find(std::string(dotted) + " has no default"), std::string::npos) << message;
  }
}

TEST(SessionConfig, ErrorsNameTheKeyTheValueAndWhatIsAllowed) {
  const std::string range = errorOf(R"({"paradigm": {"flash_ms": 1}})");
  EXPECT_NE(range.find("paradigm.flash_ms = 1"), std::string::npos) << range;
  EXPECT_NE(range.find("[5, 2000]"), std::string::npos) << range;
  const std::string unknown = errorOf(R"({"paradigm": {"flashms": 60}})");
  EXPECT_NE(unknown.find("paradigm.flashms is not a known key"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("flash_ms"), std::string::npos) << unknown;
  const std::string latency = errorOf(R"({"eeg": {"latency_ms": -3}})");
  EXPECT_NE(latency.find("eeg.latency_ms = -3"), std::string::npos) << latency;
  const std::string source = errorOf(R"({"eeg": {"source": "amplifier"}})");
  EXPECT_NE(source.find("eeg.source"), std::string::npos) << source;
  EXPECT_NE(source.find("simulated"), std::string::npos) << source;
}

TEST(SessionConfig, TheTrackerSearchesAtFullOrHalfResolution) {
  EXPECT_EQ(SessionConfig::load(sessionFile("decimate", R"({"tracker": {"search_decimate": 2}})"))
                .tracker_search_decimate,
            2);
  const std::string refused = errorOf(R"({"tracker": {"search_decimate": 4}})");
  EXPECT_NE(refused.find("tracker.search_decimate = 4"), std::string::npos) << refused;
  EXPECT_NE(refused.find("[1, 2]"), std::string::npos) << refused;
}

// The ErrP classifier takes the whole montage by default (its xDAWN filter finds the response),
// a list of channels picks those the montage has, and a list with none of them is refused.
TEST(SessionConfig, ErrpChannelsAreTheMontageOrThoseOfTheListItHas) {
  const SessionConfig embedded = SessionConfig::load(std::nullopt);
  EXPECT_EQ(embedded.errp.method, "riemann");
  EXPECT_EQ(embedded.errp.xdawn_filters, 1);
  EXPECT_EQ(embedded.errp.pipeline(embedded.pipeline, embedded.eeg.montage).channels,
            embedded.eeg.montage);
  const SessionConfig listed = SessionConfig::load(sessionFile(
      "errp_channels", R"({"errp": {"channels": ["FCz", "Fz", "Cz"], "method": "slda"}})"));
  EXPECT_EQ(listed.errp.pipeline(listed.pipeline, listed.eeg.montage).channels,
            (std::vector<std::string>{"Fz", "Cz"}));
  const std::string none = errorOf(R"({"errp": {"enabled": true, "channels": ["FC5", "FC6"]}})");
  EXPECT_NE(none.find("errp.channels: the EEG montage has none of FC5, FC6"), std::string::npos)
      << none;
  const std::string filters = errorOf(R"({"errp": {"xdawn_filters": 0}})");
  EXPECT_NE(filters.find("errp.xdawn_filters = 0"), std::string::npos) << filters;
}

// Before the run each stage checks what its settings name can be used, and says which key.
std::string validationErrorOf(const std::string& json) {
  const SessionConfig config = SessionConfig::load(sessionFile("resources", json));
  try {
    checkNamedResources(config);
  } catch (const SessionConfigError& error) {
    return error.what();
  }
  return "";
}

TEST(StageSettings, EachStageNamesTheKeyOfAFileOrDeviceItCannotUse) {
  EXPECT_EQ(validationErrorOf("{}"), "");
  const std::string missing = "/nonexistent/arbci/file";
  EXPECT_NE(validationErrorOf(R"({"eeg": {"source": "file", "file": ")" + missing + R"("}})")
                .find("eeg.file = \"" + missing + "\": no such file"),
            std::string::npos);
  EXPECT_NE(validationErrorOf(R"({"classifier": {"model": ")" + missing + R"("}})")
                .find("classifier.model = \"" + missing + "\": no such file"),
            std::string::npos);
  EXPECT_NE(
      validationErrorOf(R"({"robot": {"backend": "remote", "key_file": ")" + missing + R"("}})")
          .find("robot.key_file = \"" + missing + "\": no such file"),
      std::string::npos);
  EXPECT_NE(validationErrorOf(R"({"cameras": {"source": "devices", "left": {"video": ")" + missing +
                              R"(", "calibration": ")" + missing + R"("}}})")
                .find("cameras.left.video = \"" + missing + "\": no such file"),
            std::string::npos);
  const std::string calibration =
      ARBCI_SHARED_DATA_DIR "/vision/opencv_samples_chessboard/left_intrinsics.yml";
  EXPECT_NE(validationErrorOf(R"({"cameras": {"source": "devices", "left": {"device": 63, )"
                              R"("calibration": ")" +
                              calibration + R"("}}})")
                .find("cameras.left.device = 63: /dev/video63 does not exist"),
            std::string::npos);
}

}  // namespace
}  // namespace arbci::session
