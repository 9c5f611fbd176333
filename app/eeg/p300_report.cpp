#include "eeg/p300_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>

#include "support/cli_error.h"
#include "support/status_line.h"

namespace arbci::app {

namespace {

std::string interval(const bci::Interval& i) {
  char text[48];
  std::snprintf(text, sizeof text, "[%.3f, %.3f]", i.low, i.high);
  return text;
}

nlohmann::json toJson(const bci::Interval& i) {
  return {i.low, i.high};
}

}  // namespace

void printReport(std::ostream& out, const bci::EvaluationReport& r, const ReportWords& words) {
  out << std::fixed;
  if (words.paradigm) {
    out << "paradigm: " << r.layout.describeShape();
    if (r.selection_metrics) {
      out << ", " << r.selections.size() << " selections (" << r.selections_with_truth
          << " with known targets)";
    }
    out << ", stimulus onset asynchrony " << std::setprecision(3) << r.layout.soa_s << " s\n";
  }
  out << "single-" << words.event << " AUC: " << std::setprecision(3) << r.auc << " (95 % interval "
      << interval(r.auc_interval) << ", " << r.target_flashes << " " << words.target << " and "
      << r.other_flashes << " " << words.other << " " << words.events << ")\n";
  if (!r.selection_metrics) {
    if (words.paradigm)
      out << "no selection metrics: every stimulus code is always or never the target (an "
             "oddball, or codes that are classes), so codes are not choices\n";
    out.unsetf(std::ios::fixed);
    return;
  }
  out << "selected with " << r.max_sequences << " sequences: " << r.selected(r.max_sequences)
      << "\n";
  out << "chance: " << std::setprecision(3) << r.chance << "; over " << r.selections_with_truth
      << " selections an accuracy of " << r.chance_95 << " or more beats guessing (p < 0.05)\n\n";
  const bool speller = !r.layout.symbols.empty();
  out << "sequences  accuracy  95 % interval   s/selection  bits/selection  bits/min"
      << (speller ? "  selected" : "") << "\n";
  for (int n = 1; n <= r.max_sequences; ++n) {
    const size_t i = static_cast<size_t>(n - 1);
    out << std::setw(9) << n << std::setw(10) << std::setprecision(3) << r.accuracy[i] << "  "
        << interval(r.accuracy_interval[i]) << std::setw(12) << std::setprecision(2)
        << r.seconds_per_selection[i] << std::setw(16) << std::setprecision(3)
        << r.bits_per_minute[i] * r.seconds_per_selection[i] / 60.0 << std::setw(10)
        << std::setprecision(2) << r.bits_per_minute[i];
    if (speller) out << "  " << r.selected(n);
    out << "\n";
  }
  // Selections cut short count with the sequences they have: say over how many each row is.
  if (r.fragments > 0 || r.selections_by_sequences.back() < r.selections_with_truth) {
    out << "(selections cut short: " << r.fragments
        << " without a whole sequence left out; the others count with what they have, so "
           "accuracy after n sequences is over:";
    for (int n = 1; n <= r.max_sequences; ++n)
      out << " " << r.selections_by_sequences[static_cast<size_t>(n - 1)];
    out << ")\n";
  }
  out << "\ndynamic stopping (certainty >= " << std::setprecision(3) << r.dynamic_rule.certainty
      << ", " << r.dynamic_rule.min_sequences << "-" << r.dynamic_rule.max_sequences
      << " sequences): accuracy " << r.dynamic_accuracy << " "
      << interval(r.dynamic_accuracy_interval) << ", " << std::setprecision(1)
      << r.dynamic_mean_flashes << " flashes (" << std::setprecision(2) << r.dynamic_seconds
      << " s) per selection, " << r.dynamic_bits_per_minute << " bits/min";
  if (speller) out << "; selected: " << r.selectedDynamic();
  out << "\n";
  const size_t last = static_cast<size_t>(r.max_sequences - 1);
  out << "fixed " << r.max_sequences << " sequences: accuracy " << std::setprecision(3)
      << r.accuracy[last] << ", " << std::setprecision(1) << r.max_sequences * r.layout.codes()
      << " flashes (" << std::setprecision(2) << r.seconds_per_selection[last]
      << " s) per selection, " << r.bits_per_minute[last] << " bits/min\n";
  out << "(selection time counts the flashes only";
  if (r.recorded_seconds_per_selection > 0.0) {
    out << "; as recorded, with cues and pauses, " << r.recorded_seconds_per_selection
        << " s per selection: " << r.recorded_bits_per_minute << " bits/min";
  }
  out << ")\n";
  out.unsetf(std::ios::fixed);
}

nlohmann::json reportJson(const bci::EvaluationReport& r) {
  nlohmann::json out = {
      {"paradigm", r.layout.describeShape()},
      {"soa_s", r.layout.soa_s},
      {"auc", r.auc},
      {"auc_interval_95", toJson(r.auc_interval)},
      {"target_flashes", r.target_flashes},
      {"non_target_flashes", r.other_flashes},
      {"selection_metrics", r.selection_metrics},
  };
  if (!r.selection_metrics) return out;
  nlohmann::json by_sequences = nlohmann::json::array();
  for (int n = 1; n <= r.max_sequences; ++n) {
    const size_t i = static_cast<size_t>(n - 1);
    by_sequences.push_back(
        {{"sequences", n},
         {"selections", r.selections_by_sequences[i]},
         {"accuracy", r.accuracy[i]},
         {"accuracy_interval_95", toJson(r.accuracy_interval[i])},
         {"seconds_per_selection", r.seconds_per_selection[i]},
         {"bits_per_minute", r.bits_per_minute[i]},
         {"bits_per_minute_with_pauses", i < r.bits_per_minute_with_pauses.size()
                                             ? nlohmann::json(r.bits_per_minute_with_pauses[i])
                                             : nlohmann::json(nullptr)},
         {"selected", r.selected(n)}});
  }
  nlohmann::json selections = nlohmann::json::array();
  for (const bci::SelectionResult& s : r.selections) {
    selections.push_back({{"truth", s.truth.empty() ? nlohmann::json(nullptr)
                                                    : nlohmann::json(r.layout.describe(s.truth))},
                          {"selected", r.layout.describe(s.by_sequences.back().codes)},
                          {"certainty", s.by_sequences.back().certainty},
                          {"dynamic_selected", r.layout.describe(s.dynamic.codes)},
                          {"dynamic_sequences", s.dynamic_sequences},
                          {"dynamic_flashes", s.dynamic_flashes}});
  }
  out["selections"] = r.selections.size();
  out["selections_with_truth"] = r.selections_with_truth;
  out["choices"] = r.layout.choices();
  out["chance"] = r.chance;
  out["chance_95"] = r.chance_95;
  out["max_sequences"] = r.max_sequences;
  out["fragments"] = r.fragments;
  out["by_sequences"] = by_sequences;
  out["dynamic"] = {{"certainty", r.dynamic_rule.certainty},
                    {"min_sequences", r.dynamic_rule.min_sequences},
                    {"max_sequences", r.dynamic_rule.max_sequences},
                    {"accuracy", r.dynamic_accuracy},
                    {"accuracy_interval_95", toJson(r.dynamic_accuracy_interval)},
                    {"mean_flashes", r.dynamic_mean_flashes},
                    {"seconds_per_selection", r.dynamic_seconds},
                    {"bits_per_minute", r.dynamic_bits_per_minute}};
  out["all_inclusive"] = {
      {"seconds_per_selection", r.recorded_seconds_per_selection > 0.0
                                    ? nlohmann::json(r.recorded_seconds_per_selection)
                                    : nlohmann::json(nullptr)},
      {"bits_per_minute", r.recorded_seconds_per_selection > 0.0
                              ? nlohmann::json(r.recorded_bits_per_minute)
                              : nlohmann::json(nullptr)},
      {"pause_seconds_per_selection", r.recorded_seconds_per_selection > 0.0
                                          ? nlohmann::json(r.pause_seconds_per_selection)
                                          : nlohmann::json(nullptr)}};
  out["per_selection"] = selections;
  return out;
}

void writeScoresCsv(const std::filesystem::path& path, const bci::P300Dataset& data,
                    const std::vector<double>& scores, const std::vector<int>& fold) {
  std::ofstream out(path);
  out << "file,sample,code,label,score,fold\n";
  out << std::setprecision(9);
  for (int i = 0; i < data.epochs(); ++i) {
    const size_t k = static_cast<size_t>(i);
    std::string file = data.sources[static_cast<size_t>(data.file[k])];
    // A file name with a comma or a quote is quoted, as CSV readers expect.
    if (file.find_first_of(",\"") != std::string::npos) {
      std::string quoted = "\"";
      for (char c : file) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
      file = quoted + "\"";
    }
    out << file << "," << data.sample[k] << "," << data.code[k] << "," << (data.target[k] ? 1 : 0)
        << "," << scores[k] << "," << (fold.empty() ? -1 : fold[k]) << "\n";
  }
  if (!out) throw CliError("cannot write " + path.string());
}

bci::Progress progressLine(std::ostream& err) {
  return [&err, last = -1](double fraction, const std::string& stage) mutable {
    const int percent = static_cast<int>(std::lround(100.0 * std::clamp(fraction, 0.0, 1.0)));
    if (percent == last) return;
    last = percent;
    std::string line = stage.substr(0, 70);
    line.resize(70, ' ');
    err << "\r" << std::setw(3) << percent << "% " << line << std::flush;
    setStatusLineOpen(percent < 100);
    if (percent == 100) err << "\n";
  };
}

}  // namespace arbci::app
