// A family of interchangeable parts (EEG sources, classifiers, marker families, robot drivers,
// panels, camera sources) by name: each entry is a name, a line of documentation, a factory and
// the schema of its own settings. The command line's choices, the session file's validation, the
// panels' lists and the docs' tables are all read from the family's registry, so adding a member
// is one new file and one registration line (docs/architecture.md).
#pragma once

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace arbci::core {

class Table;  // arbci/core/schema.h

template <class Factory>
class Registry {
 public:
  struct Entry {
    std::string name;
    std::string doc;  // one line, for --help and docs/settings.md
    Factory make;
    const Table* settings = nullptr;  // its own keys (nullptr: none)
  };

  // `family` names the parts in messages ("EEG source"); `key` is the setting that chooses one
  // ("eeg.source").
  Registry(std::string family, std::string key)
      : family_(std::move(family)), key_(std::move(key)) {}

  // Throws std::logic_error when the name is taken: two parts cannot answer to one name.
  Registry& add(Entry entry) {
    if (find(entry.name))
      throw std::logic_error(family_ + " '" + entry.name + "' is registered twice");
    entries_.push_back(std::move(entry));
    return *this;
  }
  const Entry* find(const std::string& name) const {
    const auto found = std::find_if(entries_.begin(), entries_.end(),
                                    [&](const Entry& e) { return e.name == name; });
    return found == entries_.end() ? nullptr : &*found;
  }
  // Throws std::invalid_argument naming the known ones.
  const Entry& at(const std::string& name) const {
    if (const Entry* entry = find(name)) return *entry;
    throw std::invalid_argument("unknown " + family_ + " '" + name + "' (" + key_ +
                                " must be one of " + list() + ")");
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const Entry& e : entries_) out.push_back(e.name);
    return out;
  }
  // "swlda, slda, xdawn, riemann" (in registration order).
  std::string list(const std::string& separator = ", ") const {
    std::string out;
    for (const Entry& e : entries_) out += (out.empty() ? "" : separator) + e.name;
    return out;
  }
  // One line per entry, "  name: doc\n", for a --help text.
  std::string describe() const {
    std::string out;
    for (const Entry& e : entries_) out += "  " + e.name + ": " + e.doc + "\n";
    return out;
  }
  const std::vector<Entry>& entries() const { return entries_; }
  const std::string& family() const { return family_; }
  const std::string& key() const { return key_; }

 private:
  std::string family_, key_;
  std::vector<Entry> entries_;
};

}  // namespace arbci::core
