// How well a classifier finds what the subject attends: single-flash AUC, selection accuracy
// against the number of sequences, selection time and bit rate (Wolpaw), for fixed sequences and
// for dynamic stopping. Cross-validation splits by selection, never by flash, so no selection's
// flashes are both trained on and tested.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "arbci/bci/classifier.h"
#include "arbci/bci/decision.h"
#include "arbci/bci/p300_dataset.h"

namespace arbci::bci {

// Mann-Whitney estimate; ties count half.
double areaUnderCurve(const std::vector<double>& scores, const std::vector<bool>& target);
// Bits per selection among `choices` at `accuracy` (Wolpaw et al. 2002).
double wolpawBits(int choices, double accuracy);

struct SelectionResult {
  std::set<int> truth;                 // empty when unknown
  std::vector<Decision> by_sequences;  // [n - 1]: after n sequences
  Decision dynamic;
  int dynamic_sequences = 0;
  int dynamic_flashes = 0;
};

struct EvaluationReport {
  ParadigmLayout layout;
  int max_sequences = 0;
  double auc = 0.0;
  std::vector<double> accuracy;  // [n - 1]
  std::vector<double> seconds_per_selection;
  std::vector<double> bits_per_minute;
  std::vector<SelectionResult> selections;
  int selections_with_truth = 0;
  StoppingRule dynamic_rule;
  double dynamic_accuracy = 0.0, dynamic_mean_flashes = 0.0, dynamic_seconds = 0.0,
         dynamic_bits_per_minute = 0.0;

  // The selections after n sequences as text: the speller's symbols, or "object 2, object 4".
  std::string selected(int sequences) const;
  std::string selectedDynamic() const;
};

EvaluationReport evaluateScores(const P300Dataset& data, const std::vector<double>& scores,
                                const ScoreModel& model, const StoppingRule& dynamic);

struct TrainingSettings {
  std::string method = "swlda";
  SwldaSettings swlda;
  XdawnSettings xdawn;
  int folds = 10;  // at most one per selection
  StoppingRule dynamic{15, 2, 0.99};
};

struct CrossValidation {
  EvaluationReport report;
  std::vector<double> scores;  // out-of-fold, one per epoch
  ScoreModel score_model;
  int folds = 0;
};

// Throws std::invalid_argument when fewer than two selections have known targets.
CrossValidation crossValidate(const P300Dataset& data, const TrainingSettings& settings,
                              const Progress& progress = {});

}  // namespace arbci::bci
