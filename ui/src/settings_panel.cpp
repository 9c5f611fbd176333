// The session's settings in the window, built from the settings schema: every key with the
// widget of its type, its unit and range, and its documentation as a tooltip; each edit checked
// at once by the same code and with the same messages as a session file. Before Start they can be
// applied to the run about to start (the window opens the session again with them, as BCI2000's
// Set Config); once it runs they are shown read-only, to be saved for the next run.
#include <imgui.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "arbci/core/schema.h"
#include "arbci/session/session.h"
#include "arbci/session/settings_schema.h"
#include "arbci/ui/panel_registry.h"
#include "widgets.h"

namespace arbci::ui {
namespace {

// "a, b, c" for a list of numbers or texts, as typed.
std::string listText(const nlohmann::json& list) {
  std::string out;
  if (!list.is_array()) return list.dump();
  for (const nlohmann::json& v : list) {
    if (!out.empty()) out += ", ";
    out += v.is_string() ? v.get<std::string>() : core::formatNumber(v.get<double>());
  }
  return out;
}

// The list typed: numbers where each item reads as one (else the item as text, which the check
// then refuses with the schema's message), texts as they are.
nlohmann::json parseList(const std::string& text, bool numbers) {
  nlohmann::json out = nlohmann::json::array();
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto first = item.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    item = item.substr(first, item.find_last_not_of(" \t") - first + 1);
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (numbers && end && *end == '\0')
      out.push_back(value);
    else
      out.push_back(item);
  }
  return out;
}

void keyTooltip(const core::Key& key) {
  if (!ImGui::IsItemHovered()) return;
  std::string text = key.doc;
  if (!key.unit.empty()) text += "\nunit: " + key.unit;
  if (key.type == core::Type::Number || key.type == core::Type::Integer) {
    if (std::isfinite(key.low) || std::isfinite(key.high))
      text += "\nallowed: " + (std::isfinite(key.low) ? core::formatNumber(key.low) : "-inf") +
              " to " + (std::isfinite(key.high) ? core::formatNumber(key.high) : "inf");
  }
  if (!key.fallback.is_null()) text += "\ndefault: " + key.fallback.dump();
  ImGui::SetTooltip("%s", text.c_str());
}

// "" when `settings` would start a session, else the message a file with them would get, naming
// `file`: as `arbci run --session FILE` reads it (the schema's checks, then the files it names).
std::string checkSettings(const nlohmann::json& settings, const std::string& file) {
  try {
    const session::SessionConfig config = session::SessionConfig::parse(settings, file);
    session::checkNamedResources(config);
  } catch (const std::exception& error) {
    return error.what();
  }
  return "";
}

// "saved FILE (arbci run --session FILE)", or why not.
std::string saveSettings(const nlohmann::json& settings, const std::string& file) {
  if (const std::string why = checkSettings(settings, file); !why.empty()) return why;
  std::ofstream out(file);
  out << settings.dump(2) << "\n";
  if (!out) return file + ": cannot write the session file";
  return "saved " + file + " (arbci run --session " + file + ")";
}

constexpr const char* kNothingToApply = "these are already the run's settings";

class SettingsPanel final : public Panel {
 public:
  const char* title() const override { return "Settings"; }
  void draw(const PanelInput& in) override;

 private:
  void initialise(const PanelInput& in);
  void check();
  bool editTable(const core::Table& table, nlohmann::json& object, const std::string& path);
  bool editKey(const core::Key& key, nlohmann::json& value, const std::string& path);
  bool initialised_ = false;
  bool applied_ = false;  // posted: the next frame's settings are the session's new ones
  nlohmann::json document_;
  std::string error_, message_;
  char filter_[128] = "";
  char save_path_[512] = "session.json";
};

void SettingsPanel::initialise(const PanelInput& in) {
  if (initialised_) return;
  initialised_ = true;
  document_ = in.settings.toJson();
  check();
}

void SettingsPanel::check() {
  error_ = checkSettings(document_, save_path_);
}

// One key's widget; returns true when the value changed.
bool SettingsPanel::editKey(const core::Key& key, nlohmann::json& value, const std::string& path) {
  const std::string label = key.name + (key.unit.empty() ? "" : " (" + key.unit + ")");
  ImGui::PushID(path.c_str());
  bool changed = false;
  const float width = std::max(120.0f, ImGui::GetContentRegionAvail().x * 0.45f);
  ImGui::SetNextItemWidth(width);
  switch (key.type) {
    case core::Type::Number: {
      double v = value.is_number() ? value.get<double>() : 0.0;
      if (ImGui::InputDouble(label.c_str(), &v, 0.0, 0.0, "%g")) {
        value = v;
        changed = true;
      }
      break;
    }
    case core::Type::Integer: {
      int v = value.is_number() ? value.get<int>() : 0;
      if (ImGui::InputInt(label.c_str(), &v, 0, 0)) {  // typed: no step buttons
        value = v;
        changed = true;
      }
      break;
    }
    case core::Type::Boolean: {
      bool v = value.is_boolean() && value.get<bool>();
      if (ImGui::Checkbox(label.c_str(), &v)) {
        value = v;
        changed = true;
      }
      break;
    }
    case core::Type::Text: {
      const std::string current = value.is_string() ? value.get<std::string>() : "";
      const std::vector<std::string> choices =
          key.choices ? key.choices() : std::vector<std::string>{};
      if (!choices.empty()) {
        if (ImGui::BeginCombo(label.c_str(), current.c_str())) {
          for (const std::string& c : choices) {
            if (ImGui::Selectable(c.c_str(), c == current)) {
              value = c;
              changed = true;
            }
          }
          ImGui::EndCombo();
        }
      } else {
        char buffer[512];
        std::snprintf(buffer, sizeof buffer, "%s", current.c_str());
        if (ImGui::InputText(label.c_str(), buffer, sizeof buffer)) {
          value = std::string(buffer);
          changed = true;
        }
      }
      break;
    }
    case core::Type::Numbers:
    case core::Type::Texts: {
      char buffer[1024];
      std::snprintf(buffer, sizeof buffer, "%s", listText(value).c_str());
      if (ImGui::InputText(label.c_str(), buffer, sizeof buffer,
                           ImGuiInputTextFlags_EnterReturnsTrue)) {
        value = parseList(buffer, key.type == core::Type::Numbers);
        changed = true;
      }
      break;
    }
    case core::Type::Section:
    case core::Type::List:
      break;  // drawn by editTable
  }
  keyTooltip(key);
  ImGui::PopID();
  recordField(path, width);  // a script finds the field by its dotted name
  return changed;
}

bool SettingsPanel::editTable(const core::Table& table, nlohmann::json& object,
                              const std::string& path) {
  bool changed = false;
  for (const core::Key& key : table.keys()) {
    const std::string here = path.empty() ? key.name : path + "." + key.name;
    nlohmann::json& value = object[key.name];
    if (key.type == core::Type::Section && key.table) {
      if (!value.is_object()) value = nlohmann::json::object();
      if (filter_[0]) {
        changed |= editTable(*key.table, value, here);
      } else if (ImGui::TreeNode(here.c_str(), "%s", key.name.c_str())) {
        keyTooltip(key);
        changed |= editTable(*key.table, value, here);
        ImGui::TreePop();
      }
      continue;
    }
    if (key.type == core::Type::List && key.table) {
      if (!value.is_array()) continue;
      for (size_t i = 0; i < value.size(); ++i) {
        const std::string item = here + "[" + std::to_string(i) + "]";
        if (filter_[0]) {
          changed |= editTable(*key.table, value[i], item);
        } else if (ImGui::TreeNode(item.c_str(), "%s", item.c_str())) {
          changed |= editTable(*key.table, value[i], item);
          ImGui::TreePop();
        }
      }
      continue;
    }
    if (filter_[0] && !containsIgnoringCase(here, filter_) &&
        !containsIgnoringCase(key.doc, filter_))
      continue;
    if (filter_[0]) ImGui::TextDisabled("%s", path.c_str());
    changed |= editKey(key, value, here);
  }
  return changed;
}

void SettingsPanel::draw(const PanelInput& in) {
  initialise(in);
  if (applied_) {
    // The session opened again: its settings as it reads them (defaults written out).
    applied_ = false;
    document_ = in.settings.toJson();
    check();
  }
  const core::Table& schema = session::sessionSchema();
  const session::CycleRecord& r = in.record;
  // Applicable until Start is pressed (the pre-flight running is a start under way).
  const bool before_start =
      r.paradigm.phase == bci::Phase::Setup && !r.preflight.running && !r.ended;
  const bool pending = document_ != in.settings.toJson();
  if (before_start) {
    ImGui::TextWrapped(
        "The settings of the run about to start. Edits are checked as a session file is; Apply "
        "to this run opens the session again with them (the window keeps the subject and run).");
  } else {
    ImGui::TextWrapped(
        "Read-only: this run keeps the settings it started with; changes apply to the next run "
        "(Save writes a session file to start it with: arbci run --session FILE).");
    if (pending)
      ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.2f, 1.0f),
                         "the edits below were not applied to this run; Save keeps them");
  }
  ImGui::SetNextItemWidth(-FLT_MIN);
  ImGui::InputTextWithHint("##find", "find a setting (name or description)", filter_,
                           sizeof filter_);
  recordField("find a setting", ImGui::GetItemRectSize().x);
  if (error_.empty()) {
    ImGui::TextColored(ImVec4(0.4f, 0.9f, 0.4f, 1.0f), "valid");
  } else {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.35f, 0.3f, 1.0f));
    ImGui::TextWrapped("%s", error_.c_str());
    ImGui::PopStyleColor();
  }
  pathInput("session file to save", save_path_, sizeof save_path_, ".json",
            "where Save writes these settings (a complete session file)");
  if (before_start) {
    // Refused while the document does not check, with the reason shown above.
    if (button("Apply to this run", !error_.empty() ? error_ : !pending ? kNothingToApply : "")) {
      applied_ = in.requests.post(session::ApplySettingsRequest{document_.dump()});
      message_ = applied_ ? "applied: the session opened again with these settings"
                          : "not applied: the run has started (these apply to the next run)";
    }
    ImGui::SameLine();
  }
  if (button("Save", error_)) {
    message_ = saveSettings(document_, save_path_);
  }
  ImGui::SameLine();
  if (button("Revert")) {
    document_ = in.settings.toJson();
    check();
    message_ = "back to the session's settings";
  }
  if (!message_.empty()) {
    ImGui::SameLine();
    ImGui::TextWrapped("%s", message_.c_str());
  }
  if (before_start && pending)
    ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.2f, 1.0f),
                       "edited: not this run's settings until applied");
  ImGui::Separator();
  ImGui::BeginChild("settings", ImVec2(0, 0), false);
  ImGui::BeginDisabled(!before_start);
  if (editTable(schema, document_, "")) check();
  ImGui::EndDisabled();
  ImGui::EndChild();
}

}  // namespace

PanelRegistry::Entry settingsPanel() {
  PanelParts parts{[] { return std::make_unique<SettingsPanel>(); }, false};
  parts.shots.push_back({"settings", "the session's settings",
                         [](const session::CycleRecord& r) { return r.frame >= 10; }});
  return {"settings", "the session's settings from the schema: edited, checked as a file is, saved",
          std::move(parts)};
}

}  // namespace arbci::ui
