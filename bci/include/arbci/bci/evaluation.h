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
#include "arbci/bci/intervals.h"
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
  // False when the stimulus codes are classes, not choices (P300Dataset::codes_are_classes):
  // then only the single-flash figures mean anything.
  bool selection_metrics = true;
  // The run's number of sequences: the whole sequences at least half of its selections have (a
  // longer selection is scored up to it). A selection cut short (a retake, the end of a run)
  // counts with the whole sequences it has and limits no other; one without a whole sequence is
  // a fragment, left out of the selection figures (its flashes still count in the AUC).
  int max_sequences = 0;
  int fragments = 0;
  std::vector<int> selections_by_sequences;  // [n - 1]: with truth and at least n sequences
  double auc = 0.0;
  Interval auc_interval;  // 95 %
  int target_flashes = 0, other_flashes = 0;
  std::vector<double> accuracy;             // [n - 1], over selections_by_sequences[n - 1]
  std::vector<Interval> accuracy_interval;  // 95 % (Wilson), [n - 1]
  double chance = 0.0;                      // 1 / choices
  double chance_95 = 0.0;  // an accuracy at or above this beats guessing (p < 0.05)
  std::vector<double> seconds_per_selection;
  std::vector<double> bits_per_minute;
  std::vector<SelectionResult> selections;
  int selections_with_truth = 0;
  StoppingRule dynamic_rule;
  double dynamic_accuracy = 0.0, dynamic_mean_flashes = 0.0, dynamic_seconds = 0.0,
         dynamic_bits_per_minute = 0.0;
  Interval dynamic_accuracy_interval;
  // All inclusive: the recording's time per selection (first flash to the next selection's first,
  // pauses and cues included) and the bit rate at the full number of sequences over it; 0 when
  // the recording has one selection.
  double recorded_seconds_per_selection = 0.0, recorded_bits_per_minute = 0.0;
  // The recording's time per selection outside the flashes (cues, feedback, pauses), and the bit
  // rate by sequences with it added to each selection: what a user gets, not the flashes alone.
  // Empty, and 0, when the recording has one selection.
  double pause_seconds_per_selection = 0.0;
  std::vector<double> bits_per_minute_with_pauses;  // [n - 1]

  // The selections after n sequences as text: the speller's symbols, or "object 2, object 4".
  std::string selected(int sequences) const;
  std::string selectedDynamic() const;
};

// Scores drift between sessions (electrode impedances, the subject's state) by an offset that
// sums into every code's evidence in proportion to its flash count: a whole run's scores are
// shifted so their median equals the training scores' median (`model.median`), per file. Returns
// the shift applied to each file (none when the model has no median).
std::vector<double> alignScoresPerFile(const P300Dataset& data, std::vector<double>& scores,
                                       const ScoreModel& model);

EvaluationReport evaluateScores(const P300Dataset& data, const std::vector<double>& scores,
                                const ScoreModel& model, const StoppingRule& dynamic);

// Each setting's default, range and meaning: bci::trainingSchema() (bci/settings.h).
// Offline evaluation's dynamic stopping (the bit rate `arbci train` and `arbci evaluate` report
// with it), not the online paradigm's: up to the recordings' 15 sequences, never before 2, at a
// posterior of 0.99.
inline constexpr StoppingRule kOfflineStopping{15, 2, 0.99};

struct TrainingSettings {
  TrainingSettings();  // the schema's defaults
  std::string method;  // a name of bci::classifiers()
  SwldaSettings swlda;
  XdawnSettings xdawn;
  double shift_ms;  // shift-lda: the largest latency shift tried, each way
  int folds;        // at most one per selection (or file)
  // "selection" (no selection's flashes both trained on and tested), "block" (k contiguous blocks
  // of flashes in time), "file", or "" for the default: by selection, or by block where the data
  // have fewer than 2 selections or their codes are classes.
  std::string folds_by;
  StoppingRule dynamic = kOfflineStopping;
};

struct CrossValidation {
  EvaluationReport report;
  std::vector<double> scores;  // out-of-fold, one per epoch
  std::vector<int> fold;       // each epoch's test fold (0-based), -1: not tested
  ScoreModel score_model;
  int folds = 0;
  std::string folds_by;  // the scheme used
};

// The scheme `requested` ("" for the default) resolves to for `data`; throws
// std::invalid_argument when it cannot make 2 folds.
std::string foldScheme(const P300Dataset& data, const std::string& requested);

// Throws std::invalid_argument when fewer than two selections have known targets.
CrossValidation crossValidate(const P300Dataset& data, const TrainingSettings& settings,
                              const Progress& progress = {});

}  // namespace arbci::bci
