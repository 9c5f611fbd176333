#include "arbci/core/schema.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace arbci::core {
namespace {

std::string joined(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

std::string rangeText(const Key& key) {
  if (key.type == Type::Integer)
    return "[" + std::to_string(static_cast<long long>(key.low)) + ", " +
           std::to_string(static_cast<long long>(key.high)) + "]";
  return "[" + formatNumber(key.low) + ", " + formatNumber(key.high) + "]";
}

std::string countText(const Key& key) {
  std::string count = std::to_string(key.min_items);
  if (key.max_items != key.min_items) {
    if (key.max_items == std::numeric_limits<std::size_t>::max())
      count = "at least " + count;
    else
      count.append(1, '-').append(std::to_string(key.max_items));
  }
  return count;
}

}  // namespace

const char* toString(Type type) {
  switch (type) {
    case Type::Number:
      return "number";
    case Type::Integer:
      return "integer";
    case Type::Boolean:
      return "true/false";
    case Type::Text:
      return "text";
    case Type::Numbers:
      return "list of numbers";
    case Type::Texts:
      return "list of texts";
    case Type::Section:
      return "section";
    case Type::List:
      return "list";
  }
  return "?";
}

std::string formatNumber(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream out;
  out.precision(10);
  out << v;
  return out.str();
}

void Place::fail(const std::string& key, const std::string& what) const {
  throw SettingsError(file + ": " + name(key) + " " + what);
}

const Key* Table::find(const std::string& key) const {
  const auto found =
      std::find_if(keys_.begin(), keys_.end(), [&](const Key& k) { return k.name == key; });
  return found == keys_.end() ? nullptr : &*found;
}

Key& Table::add(Key key) {
  // Two entries that name one key could disagree on its default: a table refuses the second.
  if (find(key.name)) throw std::logic_error(name_ + "." + key.name + " is declared twice");
  keys_.push_back(std::move(key));
  return keys_.back();
}

nlohmann::json Table::defaults() const {
  nlohmann::json out = nlohmann::json::object();
  for (const Key& key : keys_) {
    if (key.required) continue;
    out[key.name] = key.type == Type::Section ? key.table->defaults() : key.fallback;
  }
  return out;
}

nlohmann::json Table::check(const Key& key, const nlohmann::json& v, const Place& where) const {
  const std::string& name = key.name;
  switch (key.type) {
    case Type::Number: {
      if (!v.is_number()) where.fail(name, "= " + v.dump() + " must be a number");
      const double d = v.get<double>();
      if (!(d >= key.low && d <= key.high))
        where.fail(name, "= " + v.dump() + " must lie in " + rangeText(key));
      return v;
    }
    case Type::Integer: {
      if (!v.is_number_integer()) where.fail(name, "= " + v.dump() + " must be an integer");
      const auto i = v.get<long long>();
      if (static_cast<double>(i) < key.low || static_cast<double>(i) > key.high)
        where.fail(name, "= " + std::to_string(i) + " must lie in " + rangeText(key));
      return v;
    }
    case Type::Boolean:
      if (!v.is_boolean()) where.fail(name, "= " + v.dump() + " must be true or false");
      return v;
    case Type::Text: {
      if (!v.is_string()) where.fail(name, "= " + v.dump() + " must be a string");
      if (key.choices) {
        const std::vector<std::string> allowed = key.choices();
        if (std::find(allowed.begin(), allowed.end(), v.get<std::string>()) == allowed.end())
          where.fail(name, "= " + v.dump() + " must be one of " + joined(allowed, ", "));
      }
      return v;
    }
    case Type::Numbers: {
      if (!v.is_array() || v.size() < key.min_items || v.size() > key.max_items)
        where.fail(name, "= " + v.dump() + " must be a list of " + countText(key) + " numbers");
      for (const nlohmann::json& e : v) {
        if (!e.is_number()) where.fail(name, "= " + v.dump() + " must contain numbers only");
        const double d = e.get<double>();
        if (!(d >= key.low && d <= key.high))
          where.fail(name, "= " + v.dump() + " must hold numbers in " + rangeText(key));
      }
      return v;
    }
    case Type::Texts: {
      bool texts = v.is_array() && v.size() >= key.min_items;
      for (const nlohmann::json& e : v) texts = texts && e.is_string();
      if (!texts)
        where.fail(name, "= " + v.dump() + " must be a list of " +
                             (key.min_items > 0 ? countText(key) + " " : std::string()) +
                             "texts (" + key.doc + ")");
      return v;
    }
    case Type::Section:
      return key.table->resolve(v, Place{where.file, where.name(name)});
    case Type::List: {
      if (!v.is_array() || v.size() < key.min_items)
        where.fail(name, "must be a list of at least " + std::to_string(key.min_items) + " (" +
                             key.doc + ")");
      nlohmann::json out = nlohmann::json::array();
      for (std::size_t i = 0; i < v.size(); ++i)
        out.push_back(key.table->resolve(
            v[i], Place{where.file, where.name(name) + "[" + std::to_string(i) + "]"}));
      return out;
    }
  }
  return v;
}

nlohmann::json Table::resolve(const nlohmann::json& given, const Place& where) const {
  if (!given.is_object()) where.fail("", "must be an object");
  for (const auto& [key, value] : given.items()) {
    if (find(key)) continue;
    std::vector<std::string> known;
    for (const Key& k : keys_) known.push_back(k.name);
    std::sort(known.begin(), known.end());
    where.fail(key, "is not a known key (known here: " + joined(known, ", ") + ")");
  }
  nlohmann::json out = nlohmann::json::object();
  for (const Key& key : keys_) {
    const auto found = given.find(key.name);
    if (found != given.end()) {
      out[key.name] = check(key, *found, where);
    } else if (key.type == Type::Section) {
      out[key.name] =
          key.table->resolve(nlohmann::json::object(), Place{where.file, where.name(key.name)});
    } else {
      out[key.name] = key.fallback;
    }
  }
  for (const Rule& rule : rules_) {
    if (const auto broken = rule(out)) where.fail(broken->first, broken->second);
  }
  return out;
}

std::string markdown(const Table& table, const std::string& path) {
  std::ostringstream out;
  out << "## `" << (path.empty() ? table.name() : path) << "`\n\n" << table.doc() << "\n\n";
  out << "| key | type | allowed | default | what it is |\n| --- | --- | --- | --- | --- |\n";
  std::vector<std::pair<std::string, const Table*>> nested;
  for (const Key& key : table.keys()) {
    std::string allowed;
    switch (key.type) {
      case Type::Number:
      case Type::Integer:
        allowed = rangeText(key);
        break;
      case Type::Numbers:
        allowed = countText(key) + " numbers";
        if (std::isfinite(key.low) || std::isfinite(key.high)) allowed += " in " + rangeText(key);
        break;
      case Type::Text:
        if (key.choices) allowed = joined(key.choices(), ", ");
        break;
      case Type::Section:
      case Type::List:
        nested.emplace_back(path.empty() ? key.name : path + "." + key.name, key.table);
        allowed = key.type == Type::List ? "see below (each item)" : "see below";
        break;
      default:
        break;
    }
    if (!key.unit.empty()) allowed += (allowed.empty() ? "" : " ") + key.unit;
    std::string fallback;
    if (key.type != Type::Section) fallback.append("`").append(key.fallback.dump()).append("`");
    if (key.type == Type::List && key.fallback.size() > 1)
      fallback = std::to_string(key.fallback.size()) + " items (docs/settings.md's full file)";
    out << "| `" << key.name << "` | " << toString(key.type) << " | " << allowed << " | "
        << fallback << " | " << key.doc << " |\n";
  }
  out << "\n";
  for (const auto& [sub, sub_table] : nested) out << markdown(*sub_table, sub);
  return out.str();
}

}  // namespace arbci::core
