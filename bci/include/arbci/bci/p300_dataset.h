// Labelled P300 epochs from recordings (BCI2000 .dat or ARBCI's BDF+), grouped into selections
// and sequences, ready for training and evaluation.
#pragma once

#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "arbci/bci/classifier.h"
#include "arbci/bci/erp.h"
#include "arbci/bci/paradigm_layout.h"
#include "arbci/bci/recording.h"

namespace arbci::bci {

struct SelectionEpochs {
  std::vector<int> epochs;     // rows of the dataset, in presentation order
  std::set<int> target_codes;  // what the subject attended (copy task); empty when unknown
  int file = 0;
};

struct P300Dataset {
  SignalInfo info;  // of the recordings
  FeatureShape shape;
  std::vector<std::string> feature_channels;
  ParadigmLayout layout;
  Eigen::MatrixXd features;  // one row per epoch
  std::vector<bool> target;
  std::vector<int> code;
  std::vector<int> sequence;  // 0-based, within the selection
  std::vector<int> selection;
  std::vector<int> file;             // index into `sources`
  std::vector<std::int64_t> sample;  // the stimulus onset in its file
  std::vector<SelectionEpochs> selections;
  std::vector<std::string> sources;
  int dropped_epochs = 0;      // flashes too close to the end of a file for a whole window
  int rejected_epochs = 0;     // over the amplitude limit (buildDataset's reject_uv)
  int unknown_flashes = 0;     // recorded as "U" (not known whether attended): left out
  int other_code_flashes = 0;  // codes beyond the paradigm's (a session's grid flashes): left out
  // Flashes of calibration selections a session interrupted and retook (its annotation
  // "Calibration selection N interrupted ..." follows them): no whole selection, left out.
  int interrupted_flashes = 0;
  double reject_uv = 0.0;
  // Every stimulus code is always a target or never one (an oddball, or a recording coded by
  // class): the codes are the classes, not choices, so there are no selections to score.
  bool codes_are_classes = false;
  // The ERPs at the full rate, all channels, from 100 ms before each stimulus (the baseline) to
  // the end of the analysis window, for the figures; filtered as DatasetOptions::erp_filter says.
  ErpCurves erp;

  int epochs() const { return static_cast<int>(features.rows()); }
};

// The layout a recording declares: BCI2000 NumMatrixRows/NumMatrixColumns (with the symbols of
// TargetDefinitions), ARBCI's "Paradigm" parameter, or single stimuli numbered by the codes.
ParadigmLayout layoutOf(const Recording& recording);
// The recording's parameters that layoutOf() reads (and the photodiode's name), to carry the
// layout where a file format has no parameters of its own (an LSL marker stream's description,
// hence XDF).
std::vector<std::pair<std::string, std::string>> layoutParameters(const Recording& recording);

struct DatasetOptions {
  // > 0: epochs whose filtered peak-to-peak amplitude exceeds it on any feature channel are left
  // out (counted in rejected_epochs).
  double reject_uv = 0.0;
  // The ERP figures' filter: the pipeline's band run forward and backward (ZeroPhase: the
  // response's true latency and shape; a causal band-pass delays a slow P300 and rings after it,
  // turning a parietal positivity into a late trough) or exactly as the features (AsFeatures:
  // what the online classifier sees).
  enum class ErpFilter { ZeroPhase, AsFeatures } erp_filter = ErpFilter::ZeroPhase;
  // Flashes recorded as "U" (whether attended not known: a free choice online) are kept as epochs
  // with no target, for learning without labels (bci/unsupervised.h); left out otherwise. They
  // never enter the ERP averages.
  bool keep_unknown = false;
  // Where selections start (samples, ascending; bci/selection_marks.h): a flash after a start
  // that the flash before it had not reached begins a new selection. Empty: selections are the
  // runs of flashes apart by more than four stimulus onsets (a recording without marks).
  std::vector<std::int64_t> selection_starts;
};

// Filters each recording as the online cycle does, cuts the response windows and computes the
// features. Throws std::invalid_argument naming the file for recordings without stimuli, with
// other channels or rates than the first, or another paradigm, and when every epoch is rejected.
P300Dataset buildDataset(const std::vector<Recording>& recordings, const PipelineSettings& settings,
                         const Progress& progress = {}, const DatasetOptions& options = {});

}  // namespace arbci::bci
