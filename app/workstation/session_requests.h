// The window's request sink: the panels' requests to the running session (Session::request, which
// refuses with the reason and logs it); the start screen's settings kept for the window, which
// opens the session again with them. At Start, a named subject's run without a number and
// without a BIDS root is numbered among the session folders beside this one first.
#pragma once

#include <filesystem>
#include <optional>
#include <utility>

#include "arbci/session/session.h"
#include "arbci/ui/panel.h"
#include "arbci/ui/window_state.h"

namespace arbci::app {

class SessionRequests final : public ui::RequestSink {
 public:
  // `bids_root`: where the run is exported when it ends ("" for none).
  SessionRequests(session::Session& session, std::filesystem::path bids_root)
      : session_(&session), bids_root_(std::move(bids_root)) {}
  bool post(session::Request request) override;
  // The session the requests go to (the window opened it again with new settings).
  void retarget(session::Session& session) { session_ = &session; }
  // Settings the start screen asked to apply (ApplySettingsRequest), once.
  std::optional<nlohmann::json> takeSettings() { return std::exchange(settings_, std::nullopt); }

 private:
  session::Session* session_;
  std::filesystem::path bids_root_;
  std::optional<nlohmann::json> settings_;
};

// The start screen's account of a run's labels: what stops a start with them, and where the run
// will be written (in the BIDS dataset at `bids_root`, or recorded in `folder` to be filed later).
ui::RunTarget describeRun(const core::RunLabels& labels, const std::filesystem::path& folder,
                          const std::filesystem::path& bids_root);

}  // namespace arbci::app
