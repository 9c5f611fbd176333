// The System panel: what this workstation runs on (GL context, library versions, build).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "arbci/ui/panel.h"

namespace arbci::ui {

class SystemPanel final : public Panel {
 public:
  explicit SystemPanel(std::vector<std::pair<std::string, std::string>> facts)
      : facts_(std::move(facts)) {}
  const char* title() const override { return "System"; }
  void draw(const PanelInput& in) override;

 private:
  std::vector<std::pair<std::string, std::string>> facts_;
};

}  // namespace arbci::ui
