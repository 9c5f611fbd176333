#include "arbci/session/cycle.h"

#include <cstdio>

namespace arbci::session {

std::string FeedbackShown::text() const {
  std::string out = "Feedback ";
  for (int code : codes) {
    if (out.back() != ' ') out += '+';
    out += std::to_string(objects ? code : code + 100);  // as the recording codes the grid
  }
  out += error ? (*error ? " error" : " correct") : " unknown";
  return out;
}

bool TrackingPart::fresh(int id, double now_s) const {
  if (!world) return false;
  const auto state = world->object(id);
  return state && state->age(now_s) <= max_pose_age_s;
}

std::string TrackingPart::alarm(const std::vector<int>& ids, double now_s) const {
  if (!world) return "";
  std::string lost;
  auto add = [&lost](const std::string& what, std::optional<double> age) {
    char text[64];
    if (age) {
      std::snprintf(text, sizeof text, " (%.1f s)", *age);
    } else {
      std::snprintf(text, sizeof text, " (never seen)");
    }
    lost.append(lost.empty() ? "" : ", ").append(what).append(text);
  };
  const auto reference = world->referenceAge(now_s);
  if (!reference || *reference > max_pose_age_s)
    add("reference " + std::to_string(world->reference().id), reference);
  for (int id : ids) {
    const auto state = world->object(id);
    if (!state || state->age(now_s) > max_pose_age_s)
      add("object " + std::to_string(id),
          state ? std::optional<double>(state->age(now_s)) : std::nullopt);
  }
  return lost.empty() ? "" : "tracking lost: " + lost;
}

}  // namespace arbci::session

namespace arbci::session {

std::vector<std::string> QualityPart::bad() const {
  std::vector<std::string> out;
  for (size_t c = 0; c < quality.size() && c < channels.size(); ++c)
    if (quality[c].grade == bci::Grade::Bad) out.push_back(channels[c] + ": " + quality[c].finding);
  return out;
}

nlohmann::json QualityPart::toJson() const {
  nlohmann::json out = nlohmann::json::array();
  for (size_t c = 0; c < quality.size() && c < channels.size(); ++c) {
    const bci::SignalQuality& q = quality[c];
    out.push_back({{"channel", channels[c]},
                   {"grade", bci::toString(q.grade)},
                   {"finding", q.finding},
                   {"rms_uv", q.rms_uv},
                   {"sd_uv", q.sd_uv},
                   {"line50_uv", q.line50_uv},
                   {"line60_uv", q.line60_uv},
                   {"drift_uv_s", q.drift_uv_s}});
  }
  return out;
}

}  // namespace arbci::session

namespace arbci::session {

std::string LearningState::line() const {
  if (adapting)
    return "adapting: " + std::to_string(fits) + " fit(s) over " + std::to_string(selections) +
           " selections";
  std::string out =
      "learning: " + std::to_string(selections) + " selection" + (selections == 1 ? "" : "s");
  if (trusted) return out + ", the model trusted: the arm moves";
  out += ", not yet moving the arm";
  if (fits == 0) out += "; waiting for the first fit";
  if (!waiting_for.empty()) out += "; waiting for " + waiting_for;
  if (!error.empty()) out += " (last fit: " + error + ")";
  return out;
}

}  // namespace arbci::session
