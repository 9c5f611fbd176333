// The experimenter panels by name: the workstation opens them in this order, and `arbci
// screenshot --panel` names their pictures. Adding a panel is its file in ui/src/ (NAME_panel.cpp,
// globbed by CMake) defining its Entry, and its line in panel_registry.cpp.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "arbci/core/registry.h"
#include "arbci/ui/panel.h"

namespace arbci::ui {

// What a screenshot's recipe may do with the simulated session it is taken on (the screenshot
// command's): step it, and give the panel its input as it stands.
struct ShotSteps {
  std::function<void(int frames)> step;  // steps the session, feeding the window's state
  std::function<PanelInput()> input;
  std::filesystem::path folder;  // the session's folder (its recording, its model)
};

// How `arbci screenshot --panel NAME` shows a panel on a simulated session: the session is stepped
// until `ready` holds, then `act` (when given) does what a person would first (capture views,
// train), then the picture is drawn.
struct PanelShot {
  PanelShot(std::string name_, std::string doc_,
            std::function<bool(const session::CycleRecord&)> ready_,
            std::function<void(Panel&, const ShotSteps&)> act_ = {}, bool live_ = false,
            bool hmd_framebuffer_ = false)
      : name(std::move(name_)),
        doc(std::move(doc_)),
        ready(std::move(ready_)),
        act(std::move(act_)),
        live(live_),
        hmd_framebuffer(hmd_framebuffer_) {}
  std::string name;
  std::string doc;
  std::function<bool(const session::CycleRecord&)> ready;
  std::function<void(Panel&, const ShotSteps&)> act;
  bool live = false;             // the session steps while the picture's frames are drawn
  bool hmd_framebuffer = false;  // the picture is the HMD's framebuffer itself, not the window
};

struct PanelParts {
  explicit PanelParts(std::function<std::unique_ptr<Panel>()> make_, bool open_at_start_ = true)
      : make(std::move(make_)), open_at_start(open_at_start_) {}
  std::function<std::unique_ptr<Panel>()> make;
  bool open_at_start = true;  // the others are opened from the menu
  // The panel's pictures for `arbci screenshot` (none: it has no picture of its own).
  std::vector<PanelShot> shots;
};
using PanelRegistry = core::Registry<PanelParts>;
const PanelRegistry& panels();

// Every panel's shots, in the registry's order.
std::vector<std::pair<std::string, const PanelShot*>> panelShots();

}  // namespace arbci::ui
