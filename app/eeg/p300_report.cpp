#include "eeg/p300_report.h"

#include <algorithm>
#include <cmath>
#include <iomanip>

namespace arbci::app {

void printReport(std::ostream& out, const bci::EvaluationReport& r) {
  out << std::fixed;
  out << "paradigm: " << r.layout.describeShape() << ", " << r.selections.size() << " selections ("
      << r.selections_with_truth << " with known targets), stimulus onset asynchrony "
      << std::setprecision(3) << r.layout.soa_s << " s\n";
  out << "single-flash AUC: " << std::setprecision(3) << r.auc << "\n";
  out << "selected with " << r.max_sequences << " sequences: " << r.selected(r.max_sequences)
      << "\n\n";
  const bool speller = !r.layout.symbols.empty();
  out << "sequences  accuracy  s/selection  bits/selection  bits/min"
      << (speller ? "  selected" : "") << "\n";
  for (int n = 1; n <= r.max_sequences; ++n) {
    const size_t i = static_cast<size_t>(n - 1);
    out << std::setw(9) << n << std::setw(10) << std::setprecision(3) << r.accuracy[i]
        << std::setw(13) << std::setprecision(2) << r.seconds_per_selection[i] << std::setw(16)
        << std::setprecision(3) << r.bits_per_minute[i] * r.seconds_per_selection[i] / 60.0
        << std::setw(10) << std::setprecision(2) << r.bits_per_minute[i];
    if (speller) out << "  " << r.selected(n);
    out << "\n";
  }
  out << "\ndynamic stopping (certainty >= " << std::setprecision(3) << r.dynamic_rule.certainty
      << ", " << r.dynamic_rule.min_sequences << "-" << r.dynamic_rule.max_sequences
      << " sequences): accuracy " << r.dynamic_accuracy << ", " << std::setprecision(1)
      << r.dynamic_mean_flashes << " flashes (" << std::setprecision(2) << r.dynamic_seconds
      << " s) per selection, " << r.dynamic_bits_per_minute << " bits/min";
  if (speller) out << "; selected: " << r.selectedDynamic();
  out << "\n";
  const size_t last = static_cast<size_t>(r.max_sequences - 1);
  out << "fixed " << r.max_sequences << " sequences: accuracy " << std::setprecision(3)
      << r.accuracy[last] << ", " << std::setprecision(1) << r.max_sequences * r.layout.codes()
      << " flashes (" << std::setprecision(2) << r.seconds_per_selection[last]
      << " s) per selection, " << r.bits_per_minute[last] << " bits/min\n";
  out << "(selection time counts the flashes only, not the pauses between selections)\n";
  out.unsetf(std::ios::fixed);
}

bci::Progress progressLine(std::ostream& err) {
  return [&err, last = -1](double fraction, const std::string& stage) mutable {
    const int percent = static_cast<int>(std::lround(100.0 * std::clamp(fraction, 0.0, 1.0)));
    if (percent == last) return;
    last = percent;
    std::string line = stage.substr(0, 70);
    line.resize(70, ' ');
    err << "\r" << std::setw(3) << percent << "% " << line << std::flush;
    if (percent == 100) err << "\n";
  };
}

}  // namespace arbci::app
