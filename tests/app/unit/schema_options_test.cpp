// Every command-line option that sets a settings key is made from the key (support/
// schema_option.h): the test walks every option of `arbci` and `arbci-robotd` and fails on one
// named as a key (`--decimate-hz` for classifier.decimate_hz, `--rate` for rate_hz) that was made
// otherwise, unless it is listed below with why it is not the key.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>

#include "arbci/bci/settings.h"
#include "arbci/robot/settings.h"
#include "arbci/session/settings_schema.h"
#include "arbci/vision/settings.h"
#include "commands/commands.h"
#include "robotd/robotd_options.h"
#include "support/schema_option.h"

namespace arbci::app {
namespace {

void collectNames(const core::Table& table, std::set<std::string>& out) {
  for (const core::Key& key : table.keys()) {
    out.insert(key.name);
    if (key.table) collectNames(*key.table, out);
  }
}

std::set<std::string> keyNames() {
  std::set<std::string> names;
  for (const core::Table* table : std::initializer_list<const core::Table*>{
           &session::sessionSchema(), &robot::configSchema(), &robot::linkSchema(),
           &vision::detectorSchema(), &bci::trainingSchema(), &bci::subjectSchema()})
    collectNames(*table, names);
  return names;
}

// "--decimate-hz" -> "decimate_hz"
std::string asKeyName(const std::string& option) {
  std::string name = option.substr(option.find_first_not_of('-'));
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

// The key an option is named as: its own name, or its name with the key's unit after it.
std::string keyNamed(const std::string& option, const std::set<std::string>& keys) {
  const std::string name = asKeyName(option);
  if (keys.count(name)) return name;
  for (const char* unit : {"_hz", "_ms", "_s", "_m", "_mm"})
    if (keys.count(name + unit)) return name + unit;
  return "";
}

std::string pathOf(const CLI::App* command) {
  std::string path;
  for (const CLI::App* c = command; c; c = c->get_parent())
    path = c->get_name() + (path.empty() ? "" : " " + path);
  return path;
}

// Options named as a key that are not the key, each with its reason.
const std::map<std::string, std::string> kNotTheKey = {
    {"arbci-robotd --port",
     "a backend may listen on any free port (0); a session cannot "
     "connect to one, so robot.port's range does not hold"},
    {"arbci-robotd --key-file", "the backend's copy of the key: it reads no session file"},
    {"arbci screenshot --size", "the image's WIDTHxHEIGHT in pixels, not a reference's size_m"},
    {"arbci marker make --id", "the ids to print, not an object's id"},
    {"arbci marker train --id", "the id the pattern is given, not an object's id"},
    {"arbci detect --video", "the video detect reads, not a session camera's"},
    {"arbci detect --device", "the camera detect reads, not a session camera's"},
    {"arbci detect --threshold", "the marker threshold (mode or level), not errp.threshold"},
    {"arbci detect --undistort", "how corners are undistorted, not hmd.undistort (the lens)"},
    {"arbci calibrate --right", "the right camera's images, not cameras.right"},
    {"arbci eeg stream --name", "the name the outlet publishes, not the one a session looks for"},
    {"arbci eeg simulate --rows", "the simulated speller matrix's rows, not the table's grid"},
    {"arbci eeg simulate --columns", "the simulated speller matrix's columns, not the grid's"},
    {"arbci train --errp", "what is trained, not the errp section"},
    {"arbci evaluate --model", "the model evaluated, not the one a session loads"},
    {"arbci evaluate --sequences", "a cap on the flashes scored offline, not paradigm.sequences"},
};

void walk(const CLI::App* command, const std::set<std::string>& keys,
          std::vector<std::string>& found, std::set<std::string>& named) {
  std::set<std::string> made;
  for (const SchemaOptionUse& use : schemaOptions())
    if (use.command == command) made.insert(use.option);
  for (const CLI::Option* option : command->get_options()) {
    for (const std::string& name : option->get_lnames()) {
      const std::string long_name = "--" + name;
      const std::string key = keyNamed(long_name, keys);
      if (key.empty() || made.count(long_name)) continue;
      const std::string what = pathOf(command) + " " + long_name;
      named.insert(what);
      if (!kNotTheKey.count(what)) found.push_back(what + " (the key " + key + ")");
    }
  }
  for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; }))
    walk(sub, keys, found, named);
}

TEST(SchemaOptions, EveryOptionNamedAsASettingsKeyIsMadeFromTheKey) {
  int exit_code = 0;
  CLI::App arbci{"", "arbci"};
  addCommands(arbci, exit_code);
  CLI::App robotd{"", "arbci-robotd"};
  RobotdOptions robotd_options;
  addRobotdOptions(robotd, robotd_options);

  const std::set<std::string> keys = keyNames();
  std::vector<std::string> found;
  std::set<std::string> named;
  walk(&arbci, keys, found, named);
  walk(&robotd, keys, found, named);
  // Each listed one is still an option named as a key (a list of the present, not the past).
  for (const auto& [what, why] : kNotTheKey) EXPECT_TRUE(named.count(what)) << what << ": " << why;
  for (const std::string& f : found)
    ADD_FAILURE() << "an option named as a settings key but not made from it: " << f
                  << " (make it with schemaOption, or list it in kNotTheKey with the reason)";

  // The walk sees the options that are made from keys, so it would see one that is not.
  std::set<std::string> made;
  for (const SchemaOptionUse& use : schemaOptions())
    made.insert(pathOf(use.command) + " " + use.option);
  for (const char* option : {"arbci train --decimate-hz", "arbci detect --kind",
                             "arbci eeg simulate --rate", "arbci-robotd --watchdog-ms"})
    EXPECT_TRUE(made.count(option)) << option;
}

}  // namespace
}  // namespace arbci::app
