#include "arbci/ui/widget_registry.h"

namespace arbci::ui {
namespace {
// Filled while a frame is drawn; the last complete frame's lists are what readers see.
std::vector<DrawnWidget> drawing_widgets, drawn_widgets;
std::vector<std::string> drawing_windows, drawn_windows;
}  // namespace

const std::vector<DrawnWidget>& drawnWidgets() {
  return drawn_widgets;
}

const std::vector<std::string>& drawnWindows() {
  return drawn_windows;
}

namespace detail {

void endWidgetFrame() {
  drawn_widgets = std::move(drawing_widgets);
  drawn_windows = std::move(drawing_windows);
  drawing_widgets.clear();
  drawing_windows.clear();
}

void recordWidget(DrawnWidget widget) {
  drawing_widgets.push_back(std::move(widget));
}

void recordWindow(const std::string& title) {
  drawing_windows.push_back(title);
}

}  // namespace detail
}  // namespace arbci::ui
