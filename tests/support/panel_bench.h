// A panel's world built by hand: a cycle record, the session's settings (the schema's defaults),
// an operator log and the window's state, and the requests the panel posts, kept in order.
#pragma once

#include <vector>

#include "arbci/session/cycle.h"
#include "arbci/session/operator_log.h"
#include "arbci/session/session_config.h"
#include "arbci/ui/panel.h"
#include "arbci/ui/window_state.h"

namespace arbci::test {

class RecordedRequests final : public ui::RequestSink {
 public:
  bool post(session::Request request) override {
    posted.push_back(std::move(request));
    return true;
  }
  template <class T>
  int count() const {
    int n = 0;
    for (const session::Request& r : posted) n += std::holds_alternative<T>(r);
    return n;
  }
  std::vector<session::Request> posted;
};

struct PanelBench {
  session::CycleRecord record;
  session::SessionConfig settings;
  session::OperatorLog log;
  ui::WindowState window;
  RecordedRequests requests;
  ui::PanelInput input() { return {record, settings, log, window, requests}; }
};

}  // namespace arbci::test
