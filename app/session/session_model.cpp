#include "session/session_model.h"

namespace arbci::app {

void SessionModel::setThreshold(const vision::ThresholdSettings& settings) {
  threshold_ = settings;
  session_.setThreshold(settings);
}

std::vector<ui::TrackedObject> SessionModel::trackedObjects() {
  std::vector<ui::TrackedObject> out;
  for (const vision::ObjectState& o : session_.vision().world().objects()) {
    out.push_back(
        {o.id, o.T_robot_object.translation, o.age(session_.time()), o.reprojection_rms_px});
  }
  return out;
}

std::string SessionModel::phase() {
  std::string text = bci::toString(session_.paradigm().phase());
  if (session_.ended()) text += " (" + session_.endReason() + ")";
  return text;
}

std::vector<ui::StageTiming> SessionModel::timing() {
  std::vector<ui::StageTiming> out;
  const auto& last = session_.timing().lastCycle();
  for (const auto& [stage, p] : session_.timing().stagePercentiles()) {
    const auto found = last.find(stage);
    out.push_back({stage, p.p50, p.p90, p.p99, p.max, found == last.end() ? 0.0 : found->second});
  }
  const Percentiles total = session_.timing().totalPercentiles();
  out.push_back(
      {"total", total.p50, total.p90, total.p99, total.max, session_.timing().lastTotalMs()});
  return out;
}

}  // namespace arbci::app
