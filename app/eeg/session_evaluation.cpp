#include "eeg/session_evaluation.h"

#include <algorithm>
#include <cstdio>

#include "arbci/bci/intervals.h"
#include "arbci/bci/p300_dataset.h"

namespace arbci::app {
namespace {

// The flashes of the selections of `kinds`, epoched and grouped where the session marked them.
bci::P300Dataset datasetOf(const bci::P300Model& model, const bci::SelectionsOfKind& part) {
  bci::DatasetOptions options;
  options.keep_unknown = true;
  for (const bci::MarkedSelection& m : part.selections)
    options.selection_starts.push_back(m.sample);
  return bci::buildDataset({part.recording}, model.pipeline, {}, options);
}

// One selection's flashes in order, decided as the session decides.
OnlineDecision decideSelection(const bci::P300Model& model, const bci::P300Dataset& data,
                               const bci::SelectionEpochs& selection, const bci::StoppingRule& rule,
                               int max_sequences) {
  bci::SelectionAccumulator accumulator(data.layout, model.score_model);
  OnlineDecision out;
  const auto& rows = selection.epochs;
  for (size_t k = 0; k < rows.size(); ++k) {
    const int row = rows[k];
    if (max_sequences > 0 && data.sequence[static_cast<size_t>(row)] >= max_sequences) break;
    accumulator.add(data.code[static_cast<size_t>(row)],
                    model.classifier->score(data.features.row(row).transpose()));
    const bool sequence_ends =
        k + 1 == rows.size() ||
        data.sequence[static_cast<size_t>(rows[k + 1])] != data.sequence[static_cast<size_t>(row)];
    if (sequence_ends && rule.certainty > 0.0 &&
        accumulator.completeSequences() >= rule.min_sequences &&
        accumulator.decide().certainty >= rule.certainty)
      break;
  }
  out.decision = accumulator.decide();
  out.sequences = accumulator.completeSequences();
  out.truth = selection.target_codes;
  return out;
}

// "2" or "101+105".
std::string codesText(const std::set<int>& codes) {
  std::string text;
  for (int code : codes) {
    if (!text.empty()) text.push_back('+');
    text.append(std::to_string(code));
  }
  return text;
}

}  // namespace

bool isSessionRecording(const bci::Recording& recording) {
  for (const bci::MarkedSelection& m : bci::markedSelections(recording))
    if (m.kind != bci::SelectionKind::Calibration) return true;
  return false;
}

SessionEvaluation evaluateSession(const bci::P300Model& model, const bci::Recording& recording,
                                  const bci::StoppingRule& rule, int max_sequences) {
  SessionEvaluation out;
  out.source = recording.source;
  const std::vector<bci::MarkedSelection> marks = bci::markedSelections(recording);
  const bci::SelectionsOfKind calibration =
      bci::selectionsOfKind(recording, marks, {bci::SelectionKind::Calibration});
  if (!calibration.selections.empty()) {
    const bci::P300Dataset data = datasetOf(model, calibration);
    for (const bci::SelectionEpochs& s : data.selections) {
      if (s.target_codes.empty()) continue;
      ++out.calibration_selections;
      const bci::StoppingRule all{1000000, 1000000, 0.0};  // every sequence: a cued selection's
      out.calibration_right += decideSelection(model, data, s, all, 0).right();
    }
  }
  for (const bci::SelectionKind kind : {bci::SelectionKind::Objects, bci::SelectionKind::Cells}) {
    const bci::SelectionsOfKind part = bci::selectionsOfKind(recording, marks, {kind});
    if (part.selections.empty()) continue;
    const bci::P300Dataset data = datasetOf(model, part);
    for (size_t i = 0; i < data.selections.size() && i < part.selections.size(); ++i) {
      OnlineDecision d = decideSelection(model, data, data.selections[i], rule, max_sequences);
      d.kind = kind;
      d.trial = part.selections[i].trial;
      d.number = part.selections[i].number;
      out.online.push_back(std::move(d));
    }
  }
  std::stable_sort(
      out.online.begin(), out.online.end(),
      [](const OnlineDecision& a, const OnlineDecision& b) { return a.number < b.number; });
  return out;
}

void printSessionEvaluation(std::ostream& out, const SessionEvaluation& e,
                            const bci::StoppingRule& rule) {
  out << e.source << ": a session's recording, " << e.calibration_selections
      << " calibration selections and " << e.online.size() << " online selections\n";
  if (e.calibration_selections > 0) {
    out << "  calibration run: " << e.calibration_right << " of " << e.calibration_selections
        << " right after every sequence"
        << (e.in_sample ? " (IN-SAMPLE: the model was trained on these selections; its "
                          "cross-validation is the figure for new data)"
                        : " (the model was not trained on them)")
        << "\n";
  }
  char line[240];
  if (rule.certainty > 0.0) {
    std::snprintf(line, sizeof line,
                  "  online selections, decided with dynamic stopping replayed: stopped once "
                  "%.4g certain after at least %d sequences, else after every sequence recorded\n",
                  rule.certainty, rule.min_sequences);
  } else {
    std::snprintf(line, sizeof line,
                  "  online selections, decided on every flash the session showed (as it "
                  "decided them)\n");
  }
  out << line;
  std::vector<bci::ClaimedDecision> claims[2];
  int right[2] = {0, 0}, known[2] = {0, 0};
  for (const OnlineDecision& d : e.online) {
    const int k = d.kind == bci::SelectionKind::Objects ? 0 : 1;
    std::string truth = "not known";
    if (!d.truth.empty()) {
      ++known[k];
      right[k] += d.right();
      claims[k].push_back({d.decision.certainty, d.right()});
    }
    std::snprintf(line, sizeof line,
                  "  trial %3d %-7s codes %-5s certainty %.4f after %2d sequences  ", d.trial,
                  bci::toString(d.kind), codesText(d.decision.codes).c_str(), d.decision.certainty,
                  d.sequences);
    out << line;
    if (d.truth.empty())
      out << "(attended not recorded)\n";
    else if (d.right())
      out << "right\n";
    else
      out << "WRONG (attended " << codesText(d.truth) << ")\n";
  }
  const char* names[2] = {"objects", "cells"};
  for (int k = 0; k < 2; ++k) {
    if (known[k] == 0) continue;
    const bci::Interval ci = bci::wilsonInterval(right[k], known[k]);
    std::snprintf(line, sizeof line, "  online %s: %d of %d right, %.3f [%.3f, %.3f]\n", names[k],
                  right[k], known[k], static_cast<double>(right[k]) / known[k], ci.low, ci.high);
    out << line;
    for (const bci::ReliabilityBand& b : bci::reliabilityBands(claims[k])) {
      std::snprintf(line, sizeof line,
                    "    certainty [%.3f, %.3f%c: %d decisions, %d wrong, %.2f expected (95 %% of "
                    "the claims: %d-%d wrong) %s\n",
                    b.low, b.high, b.high >= 1.0 ? ']' : ')', b.decisions, b.wrong,
                    b.expected_wrong, b.wrong_low, b.wrong_high, b.verdict());
      out << line;
    }
  }
}

}  // namespace arbci::app
