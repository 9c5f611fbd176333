// From flash scores to a selection. Scores accumulate per stimulus code over sequences; the
// choice is the object (single stimulus) or the row and the column (row/column) with the most
// evidence. The certainty is the posterior probability of the choice under a Gaussian model of
// target and non-target scores (fitted on cross-validated training scores), each code's evidence
// discounted for the correlation of its scores within the selection: it drives dynamic stopping.
#pragma once

#include <algorithm>
#include <limits>
#include <map>
#include <set>
#include <vector>

#include "arbci/bci/paradigm_layout.h"

namespace arbci::bci {

struct ScoreModel {
  double target_mean = 1.0;
  double other_mean = -1.0;
  double sd = 1.0;  // pooled within-class standard deviation
  // The median of all training scores (mostly non-targets in any P300 paradigm): another run's
  // scores are shifted so their median lands here (scores drift between sessions; see
  // alignScoresPerFile in evaluation.h). NaN: unknown (a model from before it was kept).
  double median = std::numeric_limits<double>::quiet_NaN();
  // The correlation of one code's scores within a selection (0: independent flashes). Flashes
  // of a selection share stretches of background EEG, the subject's state and overlapping
  // epochs, so a code's n scores carry the evidence of n / (1 + (n - 1) rho) independent ones.
  double rho = 0.0;
  // Fitted to scores and labels; throws std::invalid_argument without both classes.
  static ScoreModel fit(const std::vector<double>& scores, const std::vector<bool>& target);
  // Target minus non-target mean in standard deviations: how far apart the classes are, which is
  // what a decision's certainty grows with.
  double separation() const { return (target_mean - other_mean) / sd; }
  // How much more a code's summed evidence varies over `flashes` flashes than independent
  // flashes would make it: 1 + (flashes - 1) rho.
  double overdispersion(int flashes) const { return 1.0 + std::max(flashes - 1, 0) * rho; }
};

// rho (ScoreModel::rho) from scores whose selection and code are known, under `model`'s class
// means: the scatter of each selection's code means about their own mean against the scatter of
// its single flashes (what all codes of a selection share cancels in both, as in a decision),
// solved for rho. Within [0, 0.5]; 0 when no selection has two codes.
double fitWithinSelectionCorrelation(const ScoreModel& model, const std::vector<double>& scores,
                                     const std::vector<bool>& target,
                                     const std::vector<int>& selection,
                                     const std::vector<int>& code);

struct Decision {
  std::set<int> codes;     // {object} or {row, rows + column}
  int choice = -1;         // 0-based object or cell (row-major)
  double certainty = 0.0;  // posterior probability of `codes`
  // The next most probable choice (for a cell: the best row with the second column, or the
  // second row with the best column), for a correction when the choice is rejected.
  std::set<int> runner_up_codes;
  int runner_up_choice = -1;
  double runner_up_certainty = 0.0;
  // The evidence behind it, per stimulus code: the log-likelihood ratio (target against
  // non-target) summed over its flashes (before the discount for their correlation), and how
  // many flashes that is.
  std::map<int, double> evidence;
  std::map<int, int> flashes;
};

// The posterior probability that a selection was wrong, from its ErrP classifier score under the
// Gaussian score model (target: error feedback) and the prior probability of an error (1 minus
// the selection's certainty, kept within 0.01-0.99 so neither source alone is final).
double errorPosterior(const ScoreModel& errp, double score, double prior_error);

struct StoppingRule {
  int max_sequences = 15;
  int min_sequences = 1;
  double certainty = 0.0;  // stop once the decision is this sure; 0: always max_sequences
};

class SelectionAccumulator {
 public:
  SelectionAccumulator(const ParadigmLayout& layout, const ScoreModel& model);
  void add(int code, double score);
  // Sequences in which every code has flashed.
  int completeSequences() const;
  int flashes() const { return flashes_; }
  Decision decide() const;
  // After a complete sequence: stop with this rule?
  bool shouldStop(const StoppingRule& rule) const;
  const ScoreModel& scoreModel() const { return model_; }

 private:
  // Posterior over the candidates `codes` from the log-likelihood ratios.
  std::map<int, double> posterior(int first_code, int count) const;
  // A code's evidence as independent flashes' worth (ScoreModel::overdispersion of its count).
  double discounted(int code) const;

  ParadigmLayout layout_;
  ScoreModel model_;
  std::map<int, double> evidence_;  // log-likelihood ratio target vs non-target, per code
  std::map<int, int> counts_;
  int flashes_ = 0;
};

}  // namespace arbci::bci
