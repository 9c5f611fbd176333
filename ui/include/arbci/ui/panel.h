// An experimenter panel: one ImGui window in the shell's panel area. A panel draws from what it is
// given each frame — the last cycle's record, the session's settings, the operator log and the
// window's own state, all read-only — and posts what the experimenter asks for as the session's
// requests. It never reaches into the session: a panel shows the same whether the record came from
// a live session or was built by hand in a test.
#pragma once

#include "arbci/session/cycle.h"
#include "arbci/session/operator_log.h"
#include "arbci/session/requests.h"
#include "arbci/session/session_config.h"
#include "arbci/ui/window_state.h"

namespace arbci::ui {

// Where a panel's requests go: the session's queue in the window, a list in a test.
class RequestSink {
 public:
  virtual ~RequestSink() = default;
  // Queued for the next cycle (true), or refused with the reason the record's why-not gives (the
  // session logs it and tells the experimenter).
  virtual bool post(session::Request request) = 0;
};

// What a panel draws from, each frame.
struct PanelInput {
  const session::CycleRecord& record;  // the last cycle's
  const session::SessionConfig& settings;
  const session::OperatorLog& log;
  const WindowState& window;
  RequestSink& requests;
};

class Panel {
 public:
  virtual ~Panel() = default;
  virtual const char* title() const = 0;
  // Draws the panel's contents (the shell has already begun its window).
  virtual void draw(const PanelInput& in) = 0;
};

}  // namespace arbci::ui
