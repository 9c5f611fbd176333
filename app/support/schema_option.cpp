#include "support/schema_option.h"

#include <cmath>
#include <regex>
#include <stdexcept>
#include <type_traits>

#include "support/cli_error.h"

namespace arbci::app {
namespace {

std::vector<SchemaOptionUse>& uses() {
  static std::vector<SchemaOptionUse> all;
  return all;
}

std::string help(const core::Key& key, const std::string& more) {
  std::string text = key.doc;
  if (!key.unit.empty()) text += " (" + key.unit + ")";
  if (!more.empty()) text += "; " + more;
  return text;
}

CLI::Option* noted(CLI::App& command, CLI::Option* option, const core::Key& key,
                   bool own_default = false) {
  uses().push_back({&command, option->get_name(), &key, own_default});
  return option;
}

// The key's range, as the session file's check has it (an infinite end: unbounded).
template <class T>
void range(CLI::Option* option, const core::Key& key) {
  const bool low = std::isfinite(key.low), high = std::isfinite(key.high);
  if (!low && !high) return;
  option->check(CLI::Range(low ? static_cast<T>(key.low) : std::numeric_limits<T>::lowest(),
                           high ? static_cast<T>(key.high) : std::numeric_limits<T>::max()));
}

// A programming error: the option's variable is not of the key's type.
void expectType(const std::string& name, const core::Key& key, core::Type type, const char* what) {
  if (key.type != type) throw std::logic_error(name + ": the key " + key.name + " is not " + what);
}

// A number or an integer option: the key's type, range and doc.
template <class T>
void expectNumber(const std::string& name, const core::Key& key) {
  if constexpr (std::is_same_v<T, int>)
    expectType(name, key, core::Type::Integer, "an integer");
  else
    expectType(name, key, core::Type::Number, "a number");
}

template <class T>
CLI::Option* numberOption(CLI::App& command, const std::string& name, T& value,
                          const core::Key& key, const std::string& more) {
  expectNumber<T>(name, key);
  value = key.fallback.get<T>();
  CLI::Option* option = command.add_option(name, value, help(key, more))->capture_default_str();
  range<T>(option, key);
  return noted(command, option, key);
}

template <class T>
CLI::Option* numberOptionOwnDefault(CLI::App& command, const std::string& name, T& value,
                                    const core::Key& key, T own, const std::string& why) {
  expectNumber<T>(name, key);
  value = own;
  CLI::Option* option =
      command.add_option(name, value, help(key, "default " + core::formatNumber(own) + ": " + why));
  range<T>(option, key);
  return noted(command, option, key, true);
}

}  // namespace

CLI::Option* schemaOption(CLI::App& command, const std::string& name, double& value,
                          const core::Key& key, const std::string& more) {
  return numberOption(command, name, value, key, more);
}

CLI::Option* schemaOption(CLI::App& command, const std::string& name, int& value,
                          const core::Key& key, const std::string& more) {
  return numberOption(command, name, value, key, more);
}

CLI::Option* schemaOption(CLI::App& command, const std::string& name, std::string& value,
                          const core::Key& key, const std::string& more) {
  expectType(name, key, core::Type::Text, "a text");
  value = key.fallback.get<std::string>();
  CLI::Option* option = command.add_option(name, value, help(key, more))->capture_default_str();
  if (key.choices) option->check(CLI::IsMember(key.choices()));
  return noted(command, option, key);
}

CLI::Option* schemaOption(CLI::App& command, const std::string& name, std::vector<double>& value,
                          const core::Key& key, const std::string& more) {
  expectType(name, key, core::Type::Numbers, "a list of numbers");
  value = key.fallback.get<std::vector<double>>();
  std::string shown;
  for (double v : value) shown += (shown.empty() ? "" : ",") + core::formatNumber(v);
  CLI::Option* option =
      command.add_option(name, value, help(key, more))->delimiter(',')->default_str(shown);
  if (key.min_items == key.max_items) option->expected(static_cast<int>(key.min_items));
  range<double>(option, key);
  return noted(command, option, key);
}

CLI::Option* schemaOption(CLI::App& command, const std::string& name,
                          std::vector<std::string>& value, const core::Key& key,
                          const std::string& more) {
  expectType(name, key, core::Type::Texts, "a list of texts");
  value = key.fallback.get<std::vector<std::string>>();
  CLI::Option* option = command.add_option(name, value, help(key, more))->delimiter(',');
  return noted(command, option, key);
}

CLI::Option* schemaOptionOwnDefault(CLI::App& command, const std::string& name, double& value,
                                    const core::Key& key, double own, const std::string& why) {
  return numberOptionOwnDefault(command, name, value, key, own, why);
}

CLI::Option* schemaOptionOwnDefault(CLI::App& command, const std::string& name, int& value,
                                    const core::Key& key, int own, const std::string& why) {
  return numberOptionOwnDefault(command, name, value, key, own, why);
}

CLI::Option* schemaOverride(CLI::App& command, const std::string& name, std::optional<int>& value,
                            const core::Key& key) {
  expectType(name, key, core::Type::Integer, "an integer");
  value.reset();
  CLI::Option* option =
      command.add_option(name, value, help(key, "in place of the session file's " + key.name));
  range<int>(option, key);
  return noted(command, option, key, true);
}

CLI::Option* schemaFlag(CLI::App& command, const std::string& name, bool& value,
                        const core::Key& key, const std::string& more) {
  if (key.type != core::Type::Boolean || key.fallback.get<bool>())
    throw std::logic_error(name + ": the key " + key.name + " is not a true/false off by default");
  value = false;
  return noted(command, command.add_flag(name, value, help(key, more)), key);
}

const std::vector<SchemaOptionUse>& schemaOptions() {
  return uses();
}

void checkSchemaRules(const core::Table& table, const nlohmann::json& given,
                      const CLI::App& command) {
  try {
    table.resolve(given, {"", ""});
  } catch (const core::SettingsError& error) {
    std::string message = error.what();
    if (message.rfind(": ", 0) == 0) message.erase(0, 2);  // no file: the command line
    for (const SchemaOptionUse& use : uses())
      if (use.command == &command)
        message =
            std::regex_replace(message, std::regex("\\b" + use.key->name + "\\b"), use.option);
    throw CliError(message);
  }
}

}  // namespace arbci::app
