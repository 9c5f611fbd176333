#include "arbci/session/trust_report.h"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "arbci/bci/intervals.h"

namespace arbci::session {
namespace {

using Json = nlohmann::json;

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0) {
  char text[200];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}

const Json& at(const Json& j, const char* key) {
  static const Json none;
  return j.is_object() && j.contains(key) ? j.at(key) : none;
}

double number(const Json& j, double otherwise = 0.0) {
  return j.is_number() ? j.get<double>() : otherwise;
}

int integer(const Json& j) {
  return j.is_number() ? j.get<int>() : 0;
}

// "2 of 3 right (0.667, 95 % 0.21-0.94)".
std::string rightOf(int right, int of) {
  const bci::Interval ci = bci::wilsonInterval(right, of);
  return std::to_string(right) + " of " + std::to_string(of) + " right" +
         format(" (%.3f, 95 %% %.2f-%.2f)", of ? static_cast<double>(right) / of : 0.0, ci.low,
                ci.high);
}

void calibration(const Json& s, std::vector<TrustRow>& rows) {
  const Json& c = at(s, "calibration");
  if (!at(c, "auc").is_number()) {
    if (!c.is_null()) rows.push_back({"calibration", "no model was trained", true});
    return;
  }
  const double auc = number(c["auc"]);
  const Json& ci = at(c, "auc_95");
  const Json& flashes = at(c, "flashes");
  std::string text =
      aucReference(auc, ci.is_array() ? number(ci[0]) : auc, ci.is_array() ? number(ci[1]) : auc,
                   integer(at(flashes, "targets")), integer(at(flashes, "others")));
  text += "; " + std::to_string(integer(at(c, "selections"))) + " selections";
  if (integer(at(c, "retakes")) > 0)
    text += ", " + std::to_string(integer(c["retakes"])) + " retaken";
  if (integer(at(c, "reflashed_sequences")) > 0)
    text += ", " + std::to_string(integer(c["reflashed_sequences"])) +
            " sequences shown again after an interruption";
  rows.push_back({"calibration", text, auc < kSimulatedSubjectAuc.low});
  for (const Json& review : at(c, "reviews")) {
    const std::string decision = review.value("decision", "");
    rows.push_back({"review",
                    decision + format(" at AUC %.3f (at %.0f s)", number(at(review, "auc")),
                                      number(at(review, "at_s"))),
                    decision.find("anyway") != std::string::npos ||
                        decision.find("ended") != std::string::npos});
  }
}

void online(const Json& s, std::vector<TrustRow>& rows) {
  for (const char* kind : {"objects", "cells"}) {
    const Json& r = at(s, kind);
    if (!at(r, "of").is_number()) continue;
    const int right = integer(r["right"]), of = integer(r["of"]);
    rows.push_back({std::string("online ") + kind,
                    rightOf(right, of) + " (as the session recorded what the subject intended)",
                    of > 0 && 2 * right < of});
  }
  const Json& post_hoc = at(s, "post_hoc");
  if (at(at(post_hoc, "objects"), "of").is_number() && integer(post_hoc["objects"]["of"]) > 0) {
    rows.push_back(
        {"post hoc objects",
         rightOf(integer(post_hoc["objects"]["right"]), integer(post_hoc["objects"]["of"])) +
             ", decided by " + post_hoc.value("scored_by", "") +
             " (the calibration run's figures are in-sample)",
         false});
  }
  const int wrong_arm = integer(at(s, "wrong_robot_actions"));
  if (wrong_arm > 0)
    rows.push_back(
        {"robot",
         std::to_string(wrong_arm) + " robot actions on a choice the subject did not intend",
         true});
}

void timing(const Json& s, std::vector<TrustRow>& rows) {
  const Json& g = at(s, "timing_gate");
  if (g.is_null()) return;
  const int off =
      integer(at(g, "long_flashes")) + integer(at(g, "short_gaps")) + integer(at(g, "short_soas"));
  std::string text = g.value("verdict", "");
  if (off > 0)
    text += ": " + std::to_string(off) + " flashes off limits, each annotated in the recording (" +
            std::to_string(integer(at(g, "long_flashes"))) + " too long, " +
            std::to_string(integer(at(g, "short_gaps"))) + " with too short a dark gap, " +
            std::to_string(integer(at(g, "short_soas"))) + " too soon)";
  const Json& soa = at(at(s, "timing"), "soa_ms");
  if (at(soa, "median").is_number())
    text += format("; SOA median %.0f ms (configured %.0f)", number(soa["median"]),
                   number(at(soa, "configured")));
  if (integer(at(g, "pauses")) > 0)
    text += "; paused " + std::to_string(integer(g["pauses"])) + " time(s) for timing";
  if (g.value("policy_at_end", g.value("policy", "")) != g.value("policy", ""))
    text += "; went on annotated after the experimenter's answer";
  rows.push_back({"timing", text, off > 0});
}

// eeg.trigger_out: whether the amplifier's own file holds every flash's trigger.
void triggers(const Json& s, std::vector<TrustRow>& rows) {
  const Json& t = at(s, "trigger");
  if (t.is_null()) return;
  const int failed = integer(at(t, "failed"));
  std::string text = std::to_string(integer(at(t, "written"))) + " bytes to " +
                     t.value("device", "") +
                     format(", at most %.2f ms after their swap", number(at(t, "latency_max_ms")));
  if (failed > 0)
    text += "; " + std::to_string(failed) +
            " not sent: the amplifier's file lacks them (ARBCI's recording keeps every onset)";
  rows.push_back({"triggers", text, failed > 0});
}

void eeg(const Json& s, std::vector<TrustRow>& rows) {
  const Json& q = at(s, "signal_quality");
  if (!q.is_null()) {
    const std::string verdict = q.value("verdict", "");
    const int bad = integer(at(q, "bad_channels"));
    std::string text = "quality at Start: " + verdict;
    if (bad > 0) {
      text += ", " + std::to_string(bad) + " channel(s) bad:";
      for (const Json& ch : at(q, "channels")) {
        if (ch.value("grade", "") != "bad") continue;
        text.append(" ").append(ch.value("channel", ""));
        text.append(" (").append(ch.value("finding", "")).append(")");
      }
    }
    rows.push_back({"EEG channels", text, bad > 0});
  }
  const Json& e = at(s, "eeg");
  const Json& t = at(s, "timing");
  const int lost = integer(at(t, "lost_samples"));
  const int discarded = integer(at(e, "discarded_epochs"));
  const Json& stalls = at(t, "eeg_stalls");
  std::string text = std::to_string(lost) + " samples lost, " + std::to_string(discarded) +
                     " epochs discarded for it; " + std::to_string(integer(at(stalls, "count"))) +
                     " delivery stalls";
  if (integer(at(stalls, "uncertain_flashes")) > 0)
    text +=
        " (" + std::to_string(integer(stalls["uncertain_flashes"])) + " flash stamps uncertain)";
  bool fault = false;
  for (const Json& f : at(e, "faults")) {
    text += "; fault at " + format("%.1f s: ", number(at(f, "t"))) + f.value("fault", "");
    fault = true;
  }
  rows.push_back({"EEG stream", text, lost > 0 || fault || integer(at(stalls, "count")) > 0});
}

void interruptions(const Json& s, std::vector<TrustRow>& rows) {
  for (const Json& t : at(s, "trials")) {
    const Json& list = at(t, "interruptions");
    if (!list.is_array() || list.empty()) continue;
    std::string text;
    for (const Json& i : list) {
      if (!text.empty()) text += "; ";
      text += i.value("kind", "") + format(" at %.1f s", number(at(i, "at_s")));
      const double resumed = number(at(i, "resumed_s"), -1.0);
      text += resumed >= 0.0 ? format(", went on at %.1f s", resumed) : ", not resumed";
    }
    rows.push_back({"trial " + std::to_string(integer(at(t, "trial"))), text, true});
  }
  const Json& stalls = at(s, "stalls");
  if (integer(at(stalls, "count")) > 0)
    rows.push_back({"stalls",
                    std::to_string(integer(stalls["count"])) +
                        format(" stalls of the machine (the longest %.2f s), each held "
                               "and annotated",
                               number(at(stalls, "longest_s"))),
                    true});
}

}  // namespace

std::string aucReference(double auc, double low, double high, int targets, int others) {
  std::string text = format("cross-validated AUC %.3f (95 %% %.3f-%.3f)", auc, low, high);
  if (targets > 0 && others > 0) {
    // An AUC with no response at all: 0.5, spread by the finite counts (Hanley & McNeil's
    // variance at 0.5).
    const double chance = bci::aucInterval(0.5, targets, others).high - 0.5;
    text += format("; chance with these %.0f target and %.0f other flashes: 0.50 +/- %.3f", targets,
                   others, chance);
  }
  text += format("; the simulated default subject reaches %.2f (%.2f-%.2f)",
                 kSimulatedSubjectAuc.median, kSimulatedSubjectAuc.low, kSimulatedSubjectAuc.high);
  return text;
}

std::vector<TrustRow> trustRows(const Json& summary) {
  std::vector<TrustRow> rows;
  if (!summary.is_object()) return rows;
  calibration(summary, rows);
  online(summary, rows);
  timing(summary, rows);
  triggers(summary, rows);
  eeg(summary, rows);
  interruptions(summary, rows);
  for (const Json& note : at(summary, "notes"))
    rows.push_back(
        {format("note at %.1f s", number(at(note, "t"))), note.value("text", ""), false});
  return rows;
}

}  // namespace arbci::session
