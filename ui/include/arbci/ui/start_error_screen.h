// What the window shows when the session cannot start (a session file refused, an EEG source, a
// camera or a model that cannot be opened): the message, word for word as the terminal has it,
// what to do about it, and Quit. The experimenter who started the run from a desktop icon sees
// why, instead of a window that never opened.
#pragma once

#include <string>

namespace arbci::ui {

// Draws the screen over the whole window (`width` x `height` pixels) in the frame begun; true
// once Quit is pressed.
bool drawStartError(float width, float height, const std::string& message);

}  // namespace arbci::ui
