// A command-line option that sets a settings key is made from the key (core/schema.h): its help is
// the key's doc and unit, its default the key's, its check the key's range or choices. Nothing of
// the key is written again beside the option, so `arbci train --decimate-hz` allows what
// classifier.decimate_hz allows. Each option made so is noted (schemaOptions()), and a test walks
// every command's options and fails on one that sets a key without going through here.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "arbci/core/schema.h"

namespace arbci::app {

// `value` starts at the key's default. `more`: what the command adds to the key's doc (how the
// option differs from the session's use of it), "" for nothing.
CLI::Option* schemaOption(CLI::App& command, const std::string& name, double& value,
                          const core::Key& key, const std::string& more = "");
CLI::Option* schemaOption(CLI::App& command, const std::string& name, int& value,
                          const core::Key& key, const std::string& more = "");
CLI::Option* schemaOption(CLI::App& command, const std::string& name, std::string& value,
                          const core::Key& key, const std::string& more = "");
// A list of numbers or texts, given comma-separated ("0,800"; "Fz,Cz,Pz").
CLI::Option* schemaOption(CLI::App& command, const std::string& name, std::vector<double>& value,
                          const core::Key& key, const std::string& more = "");
CLI::Option* schemaOption(CLI::App& command, const std::string& name,
                          std::vector<std::string>& value, const core::Key& key,
                          const std::string& more = "");
// The key's doc and range, with a default the command has for its own reason (`own`, said in
// `why`): `arbci detect --border` 0 takes each marker family's own border.
CLI::Option* schemaOptionOwnDefault(CLI::App& command, const std::string& name, double& value,
                                    const core::Key& key, double own, const std::string& why);
CLI::Option* schemaOptionOwnDefault(CLI::App& command, const std::string& name, int& value,
                                    const core::Key& key, int own, const std::string& why);
// The key's doc and range for an option that, given, takes the place of the session file's
// value (`arbci run --trials`): it has no default of its own.
CLI::Option* schemaOverride(CLI::App& command, const std::string& name, std::optional<int>& value,
                            const core::Key& key);
// A true/false key as a flag (its default must be false).
CLI::Option* schemaFlag(CLI::App& command, const std::string& name, bool& value,
                        const core::Key& key, const std::string& more = "");

// The settings `command`'s options gave (`given`, as the table writes them) checked by the
// table's rules (p_remove above p_enter, a window that ends after it starts): a CliError naming
// the options (--p-remove), not the keys, when one fails.
void checkSchemaRules(const core::Table& table, const nlohmann::json& given,
                      const CLI::App& command);

struct SchemaOptionUse {
  const CLI::App* command;
  std::string option;  // "--decimate-hz"
  const core::Key* key;
  bool own_default = false;  // the command's own default, not the key's (schemaOptionOwnDefault)
};
// Every option made through schemaOption() or schemaFlag() so far.
const std::vector<SchemaOptionUse>& schemaOptions();

}  // namespace arbci::app
