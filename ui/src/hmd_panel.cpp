// The HMD view as the subject sees it (both eyes), mirrored for the experimenter from the HMD
// framebuffer's texture (the window's state).
#include <imgui.h>

#include "arbci/ui/image_view.h"
#include "arbci/ui/panel_registry.h"

namespace arbci::ui {
namespace {

class HmdPanel final : public Panel {
 public:
  const char* title() const override { return "HMD view"; }
  void draw(const PanelInput& in) override {
    const float width = ImGui::GetContentRegionAvail().x;
    ImageView::drawTexture(in.window.hmd_texture, width, width / in.window.hmd_aspect, true);
  }
};

}  // namespace

PanelRegistry::Entry hmdPanel() {
  PanelParts parts{[] { return std::make_unique<HmdPanel>(); }};
  // The HMD framebuffer itself, as the subject sees it, on a frame that shows a flash.
  parts.shots.push_back({"hmd",
                         "the HMD framebuffer during the grid's flashing",
                         [](const session::CycleRecord& r) {
                           return r.paradigm.phase == bci::Phase::CellFlashing &&
                                  r.paradigm.sequence >= 2 && r.frame % 11 == 0;
                         },
                         {},
                         false,
                         true});
  return {"hmd", "the HMD view as the subject sees it (both eyes)", std::move(parts)};
}

}  // namespace arbci::ui
