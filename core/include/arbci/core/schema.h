// The settings schema: one table per family or stage, each key with its type, the values it
// allows, its default and a line of documentation. From the tables come the session file's
// parser and its error messages (the key, the value and what is allowed), the defaults a run uses
// when a file leaves a key out (the one place a default is written), the settings panel and
// docs/settings.md. A Schema<S> binds a table to a struct, so the struct carries no default of
// its own: its constructor takes the table's.
#pragma once

#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace arbci::core {

class SettingsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Type { Number, Integer, Boolean, Text, Numbers, Texts, Section, List };
const char* toString(Type type);  // "number", "integer", "true/false", ...

class Table;

// One key of a table.
struct Key {
  std::string name;
  Type type;
  nlohmann::json fallback;  // the default (Section: none, the table's own defaults apply)
  std::string doc;          // one line
  std::string unit;         // for docs and panels ("ms", "Hz", "m"); empty: none
  double low = -std::numeric_limits<double>::infinity();  // Number, Integer, each of Numbers
  double high = std::numeric_limits<double>::infinity();
  std::size_t min_items = 0, max_items = std::numeric_limits<std::size_t>::max();
  // Text: the values allowed (a registry's names; empty: any text).
  std::function<std::vector<std::string>()> choices;
  const Table* table = nullptr;  // Section, List: the table of the section or of each item
  // No default: a file (or a list's item) must give it; `doc` says what to give.
  bool required = false;

  Key(std::string key_name, Type key_type, nlohmann::json key_fallback, std::string key_doc,
      std::string key_unit = "", double key_low = -std::numeric_limits<double>::infinity(),
      double key_high = std::numeric_limits<double>::infinity())
      : name(std::move(key_name)),
        type(key_type),
        fallback(std::move(key_fallback)),
        doc(std::move(key_doc)),
        unit(std::move(key_unit)),
        low(key_low),
        high(key_high) {}
};

// Where a table's object sits, for messages: the file and the dotted path ("world.objects[2]").
struct Place {
  std::string file;
  std::string path;
  std::string name(const std::string& key) const {
    return path.empty() ? key : key.empty() ? path : path + "." + key;
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
};

// A rule between keys of one table (min_sequences <= sequences, an id that is not the
// reference's): given the table's resolved object, the key to blame and why, or nothing.
using Rule = std::function<std::optional<std::pair<std::string, std::string>>(
    const nlohmann::json& resolved)>;

class Table {
 public:
  Table(std::string name, std::string doc) : name_(std::move(name)), doc_(std::move(doc)) {}
  virtual ~Table() = default;
  // Built once (a function's static) and referred to by pointer: moved, never copied.
  Table(Table&&) = default;
  Table& operator=(Table&&) = default;
  Table(const Table&) = delete;
  Table& operator=(const Table&) = delete;

  const std::string& name() const { return name_; }
  const std::string& doc() const { return doc_; }
  const std::vector<Key>& keys() const { return keys_; }
  const Key* find(const std::string& key) const;

  // Every key at its default, sections nested.
  nlohmann::json defaults() const;
  // `given` (an object, possibly empty) over the defaults, checked: every key known, every value
  // of its type and within what its key allows, every rule kept. Throws SettingsError
  // "FILE: PATH.KEY = VALUE must ...".
  nlohmann::json resolve(const nlohmann::json& given, const Place& where) const;
  Table& rule(Rule rule) {
    rules_.push_back(std::move(rule));
    return *this;
  }
  // The rules of `other`, whose keys this table holds under the same names (adopted or merged).
  Table& rulesOf(const Table& other) {
    rules_.insert(rules_.end(), other.rules_.begin(), other.rules_.end());
    return *this;
  }

 protected:
  Key& add(Key key);

 private:
  nlohmann::json check(const Key& key, const nlohmann::json& value, const Place& where) const;
  std::string name_, doc_;
  std::vector<Key> keys_;
  std::vector<Rule> rules_;
};

// `key` with another default and doc (Schema::like).
inline Key likeKey(const Key& key, nlohmann::json fallback, std::string doc) {
  Key k = key;
  k.fallback = std::move(fallback);
  k.doc = std::move(doc);
  return k;
}

// A table bound to the struct S: each key reads and writes a member (or, for a value the file
// holds otherwise than the struct, through a pair of functions).
template <class S>
class Schema : public Table {
 public:
  using Table::Table;
  using Read = std::function<void(S&, const nlohmann::json&)>;
  using Write = std::function<nlohmann::json(const S&)>;

  Schema& number(std::string key, double S::*member, double fallback, double low, double high,
                 std::string doc, std::string unit = "") {
    Key k{std::move(key), Type::Number, fallback, std::move(doc), std::move(unit), low, high};
    return bind(std::move(k), member);
  }
  Schema& integer(std::string key, int S::*member, int fallback, int low, int high, std::string doc,
                  std::string unit = "") {
    Key k{std::move(key),  Type::Integer, fallback,    std::move(doc),
          std::move(unit), double(low),   double(high)};
    return bind(std::move(k), member);
  }
  Schema& boolean(std::string key, bool S::*member, bool fallback, std::string doc) {
    return bind(Key{std::move(key), Type::Boolean, fallback, std::move(doc)}, member);
  }
  Schema& text(std::string key, std::string S::*member, std::string fallback, std::string doc,
               std::function<std::vector<std::string>()> choices = {}) {
    Key k{std::move(key), Type::Text, fallback, std::move(doc)};
    k.choices = std::move(choices);
    return bind(std::move(k), member);
  }
  Schema& numbers(std::string key, std::vector<double> S::*member, std::vector<double> fallback,
                  std::size_t min_items, std::size_t max_items, std::string doc,
                  std::string unit = "") {
    Key k{std::move(key), Type::Numbers, fallback, std::move(doc), std::move(unit)};
    k.min_items = min_items;
    k.max_items = max_items;
    return bind(std::move(k), member);
  }
  Schema& texts(std::string key, std::vector<std::string> S::*member,
                std::vector<std::string> fallback, std::size_t min_items, std::string doc) {
    Key k{std::move(key), Type::Texts, fallback, std::move(doc)};
    k.min_items = min_items;
    return bind(std::move(k), member);
  }
  template <class T>
  Schema& section(std::string key, T S::*member, const Schema<T>& table) {
    Key k{std::move(key), Type::Section, nullptr, table.doc()};
    k.table = &table;
    return custom(
        std::move(k), [member, &table](S& s, const nlohmann::json& j) { table.read(j, s.*member); },
        [member, &table](const S& s) { return table.write(s.*member); });
  }
  template <class T>
  Schema& list(std::string key, std::vector<T> S::*member, const Schema<T>& item,
               nlohmann::json fallback, std::size_t min_items, std::string doc) {
    Key k{std::move(key), Type::List, std::move(fallback), std::move(doc)};
    k.table = &item;
    k.min_items = min_items;
    return custom(
        std::move(k),
        [member, &item](S& s, const nlohmann::json& j) {
          (s.*member).clear();
          for (const nlohmann::json& e : j) {
            T t;
            item.read(e, t);
            (s.*member).push_back(std::move(t));
          }
        },
        [member, &item](const S& s) {
          nlohmann::json out = nlohmann::json::array();
          for (const T& t : s.*member) out.push_back(item.write(t));
          return out;
        });
  }
  // Three numbers, [x, y, z], into any type built from three doubles whose parts read as .x, .y,
  // .z or [0], [1], [2] (a point in metres, a colour).
  template <class V>
  Schema& vector3(std::string key, V S::*member, nlohmann::json fallback, std::string doc,
                  std::string unit, bool required = false) {
    Key k{std::move(key), Type::Numbers, std::move(fallback), std::move(doc), std::move(unit)};
    k.min_items = k.max_items = 3;
    k.required = required;
    return custom(
        std::move(k),
        [member](S& s, const nlohmann::json& j) {
          s.*member = V{j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
        },
        [member](const S& s) {
          const V& v = s.*member;
          if constexpr (requires { v.x; })
            return nlohmann::json::array({v.x, v.y, v.z});
          else
            return nlohmann::json::array({v[0], v[1], v[2]});
        });
  }
  // A value the struct keeps otherwise than the file (another unit, another library's type).
  Schema& custom(Key key, Read read, Write write) {
    add(std::move(key));
    bindings_.push_back({std::move(read), std::move(write)});
    return *this;
  }
  // A key whose value a file must give (a list item's id): no default.
  template <class V>
  Schema& required(Key key, V S::*member) {
    key.required = true;
    return bind(std::move(key), member);
  }
  // Every key of `other` (declared where its struct lives) at this level, read into `member`: the
  // key keeps the one default and range it was declared with.
  template <class T>
  Schema& merge(const Schema<T>& other, T S::*member) {
    for (std::size_t i = 0; i < other.keys().size(); ++i)
      adopt(other, other.keys()[i].name, member);
    return *this;
  }
  // One key of `other`, read into `member`'s struct, renamed `as` here when given.
  template <class T>
  Schema& adopt(const Schema<T>& other, const std::string& key, T S::*member,
                const std::string& as = "") {
    Key k = other.at(key);
    if (!as.empty()) k.name = as;
    const std::size_t i = other.indexOf(key);
    return custom(
        std::move(k),
        [&other, i, member](S& s, const nlohmann::json& j) { other.readKey(i, j, s.*member); },
        [&other, i, member](const S& s) { return other.writeKey(i, s.*member); });
  }
  // One key of `other`, which binds S itself (a key declared with S's module but shown here).
  Schema& adopt(const Schema<S>& other, const std::string& key, const std::string& as = "") {
    Key k = other.at(key);
    if (!as.empty()) k.name = as;
    const std::size_t i = other.indexOf(key);
    return custom(
        std::move(k), [&other, i](S& s, const nlohmann::json& j) { other.readKey(i, j, s); },
        [&other, i](const S& s) { return other.writeKey(i, s); });
  }
  // A key of another table (its name, type, unit, range and choices) for another use of the same
  // setting, with this use's own default and doc: the ErrP's decimate_hz is the pipeline's, at
  // 20 Hz. The range stays the one declared.
  template <class V>
  Schema& like(const Key& other, V S::*member, nlohmann::json fallback, std::string doc) {
    return custom(
        likeKey(other, std::move(fallback), std::move(doc)),
        [member](S& s, const nlohmann::json& j) { s.*member = j.get<V>(); },
        [member](const S& s) { return nlohmann::json(s.*member); });
  }
  // The same for a value the struct keeps otherwise than the file.
  Schema& like(const Key& other, nlohmann::json fallback, std::string doc, Read read, Write write) {
    return custom(likeKey(other, std::move(fallback), std::move(doc)), std::move(read),
                  std::move(write));
  }
  // A section of the file read into S itself (its keys bound to members of S).
  Schema& sectionOf(std::string key, const Schema<S>& table) {
    Key k{std::move(key), Type::Section, nullptr, table.doc()};
    k.table = &table;
    return custom(
        std::move(k), [&table](S& s, const nlohmann::json& j) { table.read(j, s); },
        [&table](const S& s) { return table.write(s); });
  }

  const Key& at(const std::string& key) const { return keys()[indexOf(key)]; }
  std::size_t indexOf(const std::string& key) const {
    for (std::size_t i = 0; i < keys().size(); ++i)
      if (keys()[i].name == key) return i;
    throw std::logic_error(name() + " has no key " + key);
  }
  void readKey(std::size_t i, const nlohmann::json& value, S& s) const {
    bindings_[i].read(s, value);
  }
  nlohmann::json writeKey(std::size_t i, const S& s) const { return bindings_[i].write(s); }

  // Every member at its key's default: the struct's constructor calls it.
  void applyDefaults(S& s) const { read(defaults(), s); }
  // The members from a resolved object (resolve() first: no check is made here).
  void read(const nlohmann::json& resolved, S& s) const {
    for (std::size_t i = 0; i < keys().size(); ++i) {
      const auto found = resolved.find(keys()[i].name);
      if (found != resolved.end()) bindings_[i].read(s, *found);
    }
  }
  nlohmann::json write(const S& s) const {
    nlohmann::json out = nlohmann::json::object();
    for (std::size_t i = 0; i < keys().size(); ++i) out[keys()[i].name] = bindings_[i].write(s);
    return out;
  }

 private:
  template <class V>
  Schema& bind(Key key, V S::*member) {
    return custom(
        std::move(key), [member](S& s, const nlohmann::json& j) { s.*member = j.get<V>(); },
        [member](const S& s) { return nlohmann::json(s.*member); });
  }
  struct Binding {
    Read read;
    Write write;
  };
  std::vector<Binding> bindings_;
};

// A number as the messages and docs write it: 0.5, 20, 1e+05.
std::string formatNumber(double value);

// docs/settings.md's section for `table` at `path` (nested sections follow, depth first).
std::string markdown(const Table& table, const std::string& path);

}  // namespace arbci::core
