// The experimenter panels by name (the workstation opens them in this order; `arbci screenshot
// --panel` names them). Adding a panel is its file in ui/src/ defining its Entry, and its line
// in panel_registry.cpp.
#pragma once

#include <functional>
#include <memory>

#include "arbci/core/registry.h"
#include "arbci/ui/panel.h"
#include "arbci/ui/workstation_model.h"

namespace arbci::ui {

// What a panel is made with.
struct PanelContext {
  WorkstationModel& model;
  unsigned int hmd_texture = 0;  // the HMD framebuffer's colour texture
  float hmd_aspect = 1.0f;       // its width over its height
};

struct PanelParts {
  std::function<std::unique_ptr<Panel>(const PanelContext&)> make;
  bool open_at_start = true;  // the others are opened from the menu
};
using PanelRegistry = core::Registry<PanelParts>;
const PanelRegistry& panels();

}  // namespace arbci::ui
