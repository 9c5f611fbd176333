// The session file and its schema: every key has one default, declared once in the schema (a
// file that names one key leaves every other at the schema's default, and the library structs
// the session fills default to the same values); no two entries name one key; a bad value or key
// is refused with a message naming the key, the value and what is allowed; docs/settings.md is
// the schema's.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "arbci/bci/errp_feedback.h"
#include "arbci/bci/settings.h"
#include "arbci/session/session.h"
#include "arbci/session/session_config.h"
#include "arbci/session/settings_schema.h"
#include "arbci/vision/settings.h"
#include "support/test_files.h"

#include <cmath>
#include <optional>

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

// Every key's full path in the schema (sections and list items by their dotted names).
void collectKeys(const core::Table& table, const std::string& path, std::vector<std::string>& out) {
  for (const core::Key& key : table.keys()) {
    const std::string name = path.empty() ? key.name : path + "." + key.name;
    out.push_back(name);
    if (key.table) collectKeys(*key.table, name + (key.type == core::Type::List ? "[]" : ""), out);
  }
}

TEST(SessionConfig, AFileNamingOneKeyKeepsEveryOtherDefault) {
  const SessionConfig defaults = SessionConfig::load(std::nullopt);
  const SessionConfig c =
      SessionConfig::load(sessionFile("one_key", R"({"paradigm": {"trials": 7}})"));
  EXPECT_EQ(c.paradigm.trials, 7);
  EXPECT_NE(defaults.paradigm.trials, 7);
  nlohmann::json expected = defaults.toJson();
  expected["paradigm"]["trials"] = 7;
  EXPECT_EQ(c.toJson(), expected);
}

// The one place a default is written is the schema: an empty session file runs exactly the
// schema's defaults, and the structs of bci/ and vision/ that a session fills default to the same.
TEST(SessionSchema, EveryDefaultIsWhatARunWithAnEmptySessionFileUses) {
  const SessionConfig empty = SessionConfig::load(sessionFile("empty", "{}"));
  EXPECT_EQ(empty.toJson(), sessionSchema().defaults());
  EXPECT_EQ(SessionConfig{}.toJson(), sessionSchema().defaults());
  // The library structs carry no defaults of their own.
  EXPECT_EQ(bci::paradigmSchema().write(bci::ParadigmSettings{}),
            bci::paradigmSchema().write(empty.paradigm));
  EXPECT_EQ(bci::pipelineSchema().write(bci::PipelineSettings{}),
            bci::pipelineSchema().write(empty.classifier.pipeline));
  // The calibration run's folds are the session's own setting (arbci train's default is more).
  bci::TrainingSettings training;
  training.folds = empty.classifier.training.folds;
  EXPECT_EQ(bci::trainingSchema().write(training),
            bci::trainingSchema().write(empty.classifier.training));
  EXPECT_EQ(empty.classifier.training.folds, 4);
  EXPECT_EQ(vision::detectorSchema().write(vision::DetectorConfig{}),
            vision::detectorSchema().write(empty.tracker.detector));
  const bci::SimulatedSubjectConfig subject;
  EXPECT_EQ(subject.montage, empty.eeg.montage);
  EXPECT_EQ(subject.rate_hz, empty.eeg.rate_hz);
  EXPECT_EQ(subject.block_size, empty.eeg.block_size);
  EXPECT_EQ(subject.seed, empty.eeg.seed);
  EXPECT_EQ(subject.line_hz, empty.eeg.line_hz);
  EXPECT_EQ(subject.photodiode_channel, empty.eeg.photodiode_channel);
  // The values the defaults have always had (the simulated session's).
  EXPECT_EQ(empty.paradigm.sequences, 8);
  EXPECT_EQ(empty.paradigm.certainty, 0.999);
  EXPECT_EQ(empty.classifier.pipeline.filter.notch_hz, 50.0);
  EXPECT_EQ(empty.eeg.rate_hz, 256.0);
  EXPECT_EQ(empty.world.objects.size(), 4u);
}

TEST(SessionSchema, NoTwoEntriesNameTheSameKey) {
  std::vector<std::string> keys;
  collectKeys(sessionSchema(), "", keys);
  std::set<std::string> unique(keys.begin(), keys.end());
  EXPECT_EQ(unique.size(), keys.size());
  EXPECT_GT(keys.size(), 100u);
  for (const char* key : {"display_hz", "paradigm.flash_ms", "errp.enabled", "classifier.method",
                          "eeg.lsl.name", "eeg.eegdev.device", "world.objects[].id"})
    EXPECT_TRUE(unique.count(key)) << key;
}

// docs/settings.md is generated from the schema (arbci settings --markdown): it is never stale.
// A key's default as a literal in the sources ("0.5", "\"bch\""); none for the trivial ones (0,
// 1, -1, true, false, ""): a member set to those is a neutral start, not a restated default.
std::optional<std::string> literalOf(const nlohmann::json& v) {
  if (v.is_string()) {
    if (v.get<std::string>().empty()) return std::nullopt;
    return std::regex_replace(v.dump(), std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)");
  }
  if (!v.is_number()) return std::nullopt;
  const double x = v.get<double>();
  if (x == 0.0 || x == 1.0 || x == -1.0) return std::nullopt;
  if (x == std::floor(x)) return std::to_string(static_cast<long long>(x)) + R"((\.0*)?)";
  std::string text = core::formatNumber(x);
  return std::regex_replace(text, std::regex(R"(\.)"), R"(\.)");
}

void collectDefaults(const core::Table& table, std::map<std::string, std::set<std::string>>& out) {
  for (const core::Key& key : table.keys()) {
    if (key.table) collectDefaults(*key.table, out);
    if (const auto literal = literalOf(key.fallback)) out[key.name].insert(*literal);
  }
}

// Every default is written once, in the schema: no source writes a key's default beside its
// name (`max_pose_age_s = 0.5`) in a struct of its own, where it could drift from the schema's.
TEST(SessionSchema, NoSourceWritesASchemaDefaultBesideItsKeyName) {
  std::map<std::string, std::set<std::string>> defaults;
  collectDefaults(sessionSchema(), defaults);
  // Names the sources also use for something else (another threshold, an id, a seed parameter).
  const std::set<std::string> other_meanings = {"id", "threshold", "seed", "enabled"};
  // Where the schema takes a default from (the one place it is written): tracker.border is the
  // default marker family's own.
  const std::map<std::string, std::string> taken_from = {
      {"border", "vision/src/families/bch_family.cpp"}};
  std::vector<std::string> found;
  for (const char* folder : {"core", "vision", "bci", "robot", "session", "render", "ui", "app"}) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(
             std::string(ARBCI_SOURCE_DIR) + "/" + folder)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".h" && ext != ".cpp") continue;
      const std::string relative =
          std::filesystem::relative(entry.path(), ARBCI_SOURCE_DIR).generic_string();
      std::ifstream in(entry.path());
      int number = 0;
      for (std::string line; std::getline(in, line);) {
        ++number;
        line = line.substr(0, line.find("//"));
        for (const auto& [name, literals] : defaults) {
          if (other_meanings.count(name) || line.find(name) == std::string::npos) continue;
          if (taken_from.count(name) && taken_from.at(name) == relative) continue;
          for (const std::string& literal : literals) {
            const std::regex restated("\\b" + name + R"(\s*(=|\{)\s*)" + literal + R"((?![\w.]))");
            if (std::regex_search(line, restated))
              found.push_back(entry.path().string() + ":" + std::to_string(number) + ": " + line);
          }
        }
      }
    }
  }
  for (const std::string& f : found) ADD_FAILURE() << "a schema default written again: " << f;
}

TEST(SessionSchema, DocsSettingsIsTheSchemas) {
  std::ifstream in(std::string(ARBCI_SOURCE_DIR) + "/docs/settings.md");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find(settingsMarkdown()), std::string::npos)
      << "docs/settings.md is out of date: regenerate it with "
         "`build/release/arbci settings --markdown > docs/settings.md`";
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
  const std::string minimum = errorOf(R"({"paradigm": {"sequences": 4, "min_sequences": 5}})");
  EXPECT_NE(minimum.find("paradigm.min_sequences = 5 must lie in [1, 4]"), std::string::npos)
      << minimum;
  const std::string reference =
      errorOf(R"({"world": {"objects": [{"id": 10, "position": [0, 0.4, 0]},
    {"id": 0, "position": [0.1, 0.4, 0]}]}})");
  EXPECT_NE(reference.find("world.objects[1].id = 0 is the reference marker's id"),
            std::string::npos)
      << reference;
  const std::string method = errorOf(R"({"classifier": {"method": "svm"}})");
  EXPECT_NE(method.find("classifier.method = \"svm\" must be one of swlda, slda"),
            std::string::npos)
      << method;
}

TEST(SessionConfig, TheTrackerSearchesAtFullOrHalfResolution) {
  EXPECT_EQ(SessionConfig::load(sessionFile("decimate", R"({"tracker": {"search_decimate": 2}})"))
                .tracker.detector.search_decimate,
            2);
  const std::string refused = errorOf(R"({"tracker": {"search_decimate": 4}})");
  EXPECT_NE(refused.find("tracker.search_decimate = 4"), std::string::npos) << refused;
  EXPECT_NE(refused.find("[1, 2]"), std::string::npos) << refused;
  const std::string kind = errorOf(R"({"tracker": {"kind": "aruco"}})");
  EXPECT_NE(kind.find("tracker.kind = \"aruco\" must be one of bch, simple"), std::string::npos)
      << kind;
}

// The ErrP classifier takes the whole montage by default (its xDAWN filter finds the response),
// a list of channels picks those the montage has, and a list with none of them is refused.
TEST(SessionConfig, ErrpChannelsAreTheMontageOrThoseOfTheListItHas) {
  const SessionConfig embedded = SessionConfig::load(std::nullopt);
  EXPECT_EQ(embedded.errp.method, "shift-lda");
  EXPECT_EQ(embedded.errp.xdawn_filters, 1);
  EXPECT_EQ(embedded.errp.pipeline(embedded.classifier.pipeline, embedded.eeg.montage).channels,
            embedded.eeg.montage);
  const SessionConfig listed = SessionConfig::load(sessionFile(
      "errp_channels", R"({"errp": {"channels": ["FCz", "Fz", "Cz"], "method": "slda"}})"));
  EXPECT_EQ(listed.errp.pipeline(listed.classifier.pipeline, listed.eeg.montage).channels,
            (std::vector<std::string>{"Fz", "Cz"}));
  const std::string none = errorOf(R"({"errp": {"enabled": true, "channels": ["FC5", "FC6"]}})");
  EXPECT_NE(none.find("errp.channels = [\"FC5\",\"FC6\"]: the EEG montage has none of them"),
            std::string::npos)
      << none;
  // The training's range (0: the method's own), the ErrP's default.
  const std::string filters = errorOf(R"({"errp": {"xdawn_filters": 65}})");
  EXPECT_NE(filters.find("errp.xdawn_filters = 65"), std::string::npos) << filters;
}

// An ErrP calibration block too small for its folds is refused at load with the minimum, not
// found out after the whole calibration run; the default block (100) trains.
TEST(SessionConfig, AnErrpCalibrationTooSmallForItsFoldsIsRefusedWithTheMinimum) {
  const int least = bci::minimumCalibrationFeedbacks(0.25, 5);
  EXPECT_GT(least, 40);
  EXPECT_LE(least, 100);
  const std::string small = errorOf(R"({"errp": {"enabled": true, "calibration_feedbacks": 40}})");
  EXPECT_NE(small.find("errp.calibration_feedbacks = 40 is too few to train the ErrP classifier "
                       "with errp.folds = 5 and a wrong share of 0.25: at least " +
                       std::to_string(least)),
            std::string::npos)
      << small;
  EXPECT_NO_THROW(
      SessionConfig::load(sessionFile("errp_enough", R"({"errp": {"enabled": true}})")));
  // With fewer folds each held-out block is larger, so more feedbacks are needed.
  EXPECT_GE(bci::minimumCalibrationFeedbacks(0.25, 2), least);
  EXPECT_LE(bci::minimumCalibrationFeedbacks(0.25, 10), least);
}

// A run without a calibration run learns from its trials and trusts no model before
// learning_min_selections of them: with fewer trials the arm could never move, which is said
// before Start, naming the key.
TEST(SessionConfig, ANoCalibrationRunTooShortForTheLearnerToTrustIsRefused) {
  const std::string short_run = errorOf(R"({"paradigm": {"calibration": "none"}})");
  EXPECT_NE(short_run.find("paradigm.trials = 3 with paradigm.calibration \"none\""),
            std::string::npos)
      << short_run;
  EXPECT_NE(short_run.find("at least 5 trials"), std::string::npos) << short_run;
  EXPECT_NO_THROW(SessionConfig::load(
      sessionFile("learning_enough", R"({"paradigm": {"calibration": "none", "trials": 5}})")));
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
