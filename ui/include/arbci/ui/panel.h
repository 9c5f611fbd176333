// An experimenter panel: one ImGui window in the shell's panel area.
#pragma once

namespace arbci::ui {

class Panel {
 public:
  virtual ~Panel() = default;
  virtual const char* title() const = 0;
  // Draws the panel's contents (the shell has already begun its window).
  virtual void draw() = 0;
};

}  // namespace arbci::ui
