#include "workstation/session_requests.h"

#include "bids/bids_export.h"
#include "support/session_runs.h"

namespace arbci::app {
namespace {
BidsEntities entitiesOf(const core::RunLabels& l) {
  return {l.subject, l.session, l.task.empty() ? "arbci" : l.task, l.run};
}

std::string labelsProblem(const core::RunLabels& l, const std::filesystem::path& bids_root) {
  if (!bids_root.empty() && l.subject.empty())
    return "give the subject: the run is exported to the BIDS dataset " + bids_root.string();
  // Without a BIDS root the subject may stay empty; a label BIDS refuses is refused anyway, so
  // that the folder can be exported later as it is.
  BidsEntities entities = entitiesOf(l);
  if (entities.subject.empty()) entities.subject = "unnamed";
  try {
    checkBidsEntities(entities);
    checkBidsParticipant({l.age, l.sex, l.handedness});
  } catch (const BidsError& error) {
    return error.what();
  }
  return "";
}
}  // namespace

bool SessionRequests::post(session::Request request) {
  if (auto* apply = std::get_if<session::ApplySettingsRequest>(&request)) {
    // Only before Start: a running session keeps the settings it started with.
    const session::CycleRecord& last = session_->last();
    if (last.paradigm.phase != bci::Phase::Setup || last.preflight.running || session_->ended())
      return false;
    settings_ = nlohmann::json::parse(apply->settings_json);
    return true;
  }
  if (std::holds_alternative<session::StartRequest>(request)) {
    // Without a BIDS dataset, a named subject's runs are numbered among the session folders.
    core::RunLabels labels = session_->labels();
    if (bids_root_.empty() && !labels.subject.empty() && labels.run.empty()) {
      labels.run = std::to_string(nextFolderRun(session_->folder(), labels));
      session_->setLabels(labels);
    }
  }
  return session_->request(std::move(request));
}

ui::RunTarget describeRun(const core::RunLabels& l, const std::filesystem::path& folder,
                          const std::filesystem::path& bids_root) {
  ui::RunTarget out;
  out.problem = labelsProblem(l, bids_root);
  if (!out.problem.empty()) return out;
  if (bids_root.empty()) {
    const std::string where =
        "recorded in " + folder.string() + "/summary.json (arbci bids export can file it later)";
    out.target = l.subject.empty() || !l.run.empty()
                     ? where
                     : "run " + std::to_string(nextFolderRun(folder, l)) +
                           " (the next free among the session folders beside this one), " + where;
    return out;
  }
  try {
    out.target = "BIDS: " + (bids_root / bidsTarget(bids_root, entitiesOf(l))).string();
  } catch (const BidsError& error) {
    out.target = error.what();
  }
  return out;
}

}  // namespace arbci::app
