// The experimenter panels, in the order the workstation opens them. A new panel is its file in
// this folder defining its Entry, and its line here.
#include "arbci/ui/panel_registry.h"

namespace arbci::ui {

PanelRegistry::Entry sessionPanel();
PanelRegistry::Entry hmdPanel();
PanelRegistry::Entry robotPanel();
PanelRegistry::Entry thresholdPanel();
PanelRegistry::Entry calibrationPanel();
PanelRegistry::Entry trainingPanel();
PanelRegistry::Entry summaryPanel();
PanelRegistry::Entry operatorLogPanel();
PanelRegistry::Entry eegPanel();
PanelRegistry::Entry settingsPanel();

const PanelRegistry& panels() {
  static const PanelRegistry registry = [] {
    PanelRegistry r("panel", "the workstation's panels");
    r.add(sessionPanel());
    r.add(hmdPanel());
    r.add(robotPanel());
    r.add(eegPanel());
    r.add(thresholdPanel());
    r.add(calibrationPanel());
    r.add(trainingPanel());
    r.add(settingsPanel());
    r.add(summaryPanel());
    r.add(operatorLogPanel());
    return r;
  }();
  return registry;
}

std::vector<std::pair<std::string, const PanelShot*>> panelShots() {
  std::vector<std::pair<std::string, const PanelShot*>> out;
  for (const auto& entry : panels().entries()) {
    for (const PanelShot& shot : entry.make.shots) out.emplace_back(entry.name, &shot);
  }
  return out;
}

}  // namespace arbci::ui
