// A P300 classifier learnt without labels (Kindermans et al., PLoS ONE 2012): every selection has
// exactly one attended choice (an object, or a cell: its row and its column), unknown.
// Expectation-maximisation over that latent choice: given a projection w, each epoch's log-odds of
// being a target (a one-dimensional Gaussian model of w.x per class) summed over the epochs of
// each choice give the posterior of each choice; given the posteriors, each epoch's probability of
// being a target weights the class means, and w = S^-1 (mean_target - mean_other) with S the
// covariance of all epochs, which needs no label (shrunk by the Ledoit-Wolf intensity).
// Starts: several random projections; the textbook P300 as a matched filter, when
// UnsupervisedOptions::p300_direction is given (with few selections most random starts settle on
// noise); an earlier decoding, when given. Every fit the decoding is compared with (a selection
// left out, the flashes shuffled) starts the same ways: the comparison then measures the data.
// Whether a decoding is the P300 or a labelling of noise: fitted again without each selection in
// turn, does the fit decode that selection as before (UnsupervisedFit::consistency)? Of the most
// likely decodings (most variance explained) the most consistent is kept, one with a positive P300
// along UnsupervisedOptions::p300_direction before any mirror. Labels are never read.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "arbci/bci/p300_dataset.h"

namespace arbci::bci {

struct UnsupervisedOptions {
  int restarts = 12;
  int max_iterations = 100;
  std::uint64_t seed = 1;
  // Selections whose choice is known (a calibration run's cued targets), by their index in the
  // dataset's selections: held at it, the rest found (semi-supervised; a session's adaptation).
  std::map<int, int> known;
  // Fits with each selection's codes shuffled among its epochs (UnsupervisedFit::beats_shuffled);
  // 0: none.
  int shuffles = 9;
  // A decoding to start from as well (an earlier fit's: selection index -> choice).
  std::map<int, int> initial;
  // Measure the fit's leave-one-out consistency (UnsupervisedFit::consistency): a fit again
  // without each selection in turn, so as many fits as selections more.
  bool held_out = true;
  // What is known of the P300 before any data (empty: nothing): a direction in feature space
  // along which target minus non-target is positive (bci::p300Template: the textbook P300 as
  // the pipeline's features show it). A fit again without a selection keeps the most likely of
  // its starts whose labels find the response positive along it: a start settled on the mirror
  // solution (each selection's least P300-like stimulus as its target) would decode the left-out
  // selection as its mirror, and a right fit would look inconsistent. UnsupervisedFit::p300_uv
  // measures the decoding kept along it.
  Eigen::VectorXd p300_direction;
};

struct UnsupervisedFit {
  std::vector<int> selections;    // the dataset's selections fitted (indices into selections)
  std::vector<int> choice;        // per fitted selection: the choice decoded (0-based)
  std::vector<double> posterior;  // its posterior
  Eigen::VectorXd weights;        // the kept start's projection (target scores higher)
  // Starts, and those that reached the kept decoding (differing on at most a tenth of the
  // selections, rounded down: on fewer than ten, on none).
  int restarts = 0, agreeing = 0;
  int iterations = 0;  // the kept start's
  // Its leave-one-out consistency: the share of the selections that the same fit without them
  // (from new starts) decodes as this fit does; chance is about one over the choices. The measure
  // of trust (0 unless UnsupervisedOptions::held_out). The starts agreeing count the warm one.
  double consistency = 0.0;
  // By the decoding kept, target minus non-target projected on UnsupervisedOptions::p300_direction,
  // in units of it (uV of the textbook P300): positive for the P300, negative for its mirror; none
  // without a direction.
  std::optional<double> p300_uv;
  // The share of the data's variance the decoding explains, and the most that a fit explains with
  // each selection's codes shuffled among its epochs (no response repeats with a stimulus there:
  // noise alone), over UnsupervisedOptions::shuffles such fits; how many of them it beats. A
  // decoding that beats every one of 9 found a response at p < 0.1.
  double explained = 0.0, shuffled_explained = 0.0;
  int beats_shuffled = 0;
};

// Fits `selections` of `data` (every one if empty). Throws std::invalid_argument when a selection
// has no choice of the layout among its codes (no single attended stimulus to find).
UnsupervisedFit fitWithoutLabels(const P300Dataset& data, std::vector<int> selections = {},
                                 const UnsupervisedOptions& options = {});

// `data` with each epoch's label replaced by what the fit decoded (a target: its code belongs to
// its selection's decoded choice), for a supervised classifier to be trained on.
P300Dataset withLabelsFound(const P300Dataset& data, const UnsupervisedFit& fit);

// How the fit does, measured against the recordings' own labels where they carry them (the fit
// never reads them).
struct UnsupervisedReport {
  UnsupervisedFit fit;
  bool labelled = false;  // every selection's target is known
  int right = 0;          // post hoc: selections decoded right by the fit on all of them
  // The learning curve: selection k decoded by the fit on selections 1..k, as online.
  struct Point {
    int selection = 0;  // 1-based
    bool right = false;
    int agreeing = 0;          // starts that reached that fit's decoding
    double consistency = 0.0;  // that fit's held-out self-consistency
  };
  std::vector<Point> curve;
  // Each selection's epochs scored by the fit on the others: the AUC against the true labels.
  double cross_validated_auc = 0.0;
};
UnsupervisedReport evaluateWithoutLabels(const P300Dataset& data,
                                         const UnsupervisedOptions& options = {});

}  // namespace arbci::bci
