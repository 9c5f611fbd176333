// Learning the P300 classifier from a session's own selections, without a calibration run (or
// adapting a calibrated one): after each selection the whole of what was flashed so far is fitted
// again by EM over each selection's one attended choice (bci/unsupervised.h), and the session's
// classifier is trained on the labels found. Whether the arm may act on the model is a separate
// judgement (judgeTrust), made from how the fit went, never from the labels.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "arbci/bci/p300_model.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/unsupervised.h"

namespace arbci::bci {

// One fit over the selections so far.
struct LearnedSelections {
  P300Model model;           // the session's method trained on the labels found
  std::vector<int> numbers;  // the caller's number of each selection fitted, in order
  std::vector<int> choice;   // per selection: the choice decoded post hoc (0-based)
  std::vector<double> posterior;
  int agreeing = 0, restarts = 0;  // EM starts reaching the decoding kept (UnsupervisedFit)
  double consistency = 0.0;        // UnsupervisedFit::consistency
  // UnsupervisedFit's: the variance explained, the most explained with shuffled codes, how many
  // of `shuffles` such fits it beats.
  double explained = 0.0, shuffled_explained = 0.0;
  int beats_shuffled = 0, shuffles = 0;
  // By the labels found, target minus non-target projected on the textbook P300 as the pipeline's
  // features show it (bci::p300Template), in uV of that response: positive for the P300, negative
  // for its mirror; none without parietal or central sites in the features.
  std::optional<double> p3_uv;
};

// `recording`: the session's signal and flashes; `number_of_stimulus`: each stimulus's selection
// (the caller's numbering), which groups them; `known`: selections whose choice is given (a
// calibration run's cued targets, by number), held at it; `previous`: the last fit's decodings
// (number -> choice), one more start. The other stimuli's labels are never read. Throws
// std::invalid_argument when there is nothing to learn from (no selection flashing two whole
// choices) or training fails.
LearnedSelections learnFromUse(const Recording& recording,
                               const std::vector<int>& number_of_stimulus,
                               const std::map<int, int>& known, const std::map<int, int>& previous,
                               const PipelineSettings& pipeline, const TrainingSettings& training,
                               const UnsupervisedOptions& options = {});

// Each selection of `recording` (grouped as for learnFromUse) decoded by `model`: its number ->
// the code of the choice with the most summed score. The model's pipeline must be `pipeline`.
std::map<int, int> decodeSelections(const P300Model& model, const Recording& recording,
                                    const std::vector<int>& number_of_stimulus,
                                    const PipelineSettings& pipeline);

struct TrustRule {
  int min_selections = 5;
  double min_consistency = 0.8;
};

// Whether the arm may act on the model: enough selections learnt from; a response that repeats
// with the attended stimulus (the fit explains more variance than every fit with the codes
// shuffled); that response positive at the parietal sites (the P300, not its mirror: each
// selection's least P300-like stimulus taken as its target, a solution EM can settle on that
// beats the shuffles too); a leave-one-out consistency of at least the minimum (the response
// generalises from selection to selection); and its decoding of the selections the last fit knew
// unchanged but for a tenth of them, or one (a weakly attended selection may flip between fits of
// a settled model). A fit that changed its mind about more has not settled: the arm waits, and
// `changed` names them.
struct Trust {
  bool trusted = false;
  std::string waiting_for;  // empty once trusted: what is missing, in words
  std::vector<int> changed;
};
Trust judgeTrust(const LearnedSelections& fit, const std::map<int, int>& previous_choices,
                 const TrustRule& rule);

}  // namespace arbci::bci
