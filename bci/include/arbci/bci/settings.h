// The bci module's settings tables (arbci/core/schema.h): every key of the structs a session file
// (or `arbci train`) fills, with its type, range, one-line doc and its one default. The structs
// take their defaults from here (their constructors), and the session's tables adopt these keys,
// so no default is written twice. docs/settings.md shows them where the session file puts them.
#pragma once

#include "arbci/bci/eegdev_source.h"
#include "arbci/bci/evaluation.h"
#include "arbci/bci/features.h"
#include "arbci/bci/filters.h"
#include "arbci/bci/lsl_source.h"
#include "arbci/bci/paradigm.h"
#include "arbci/bci/simulated_subject.h"
#include "arbci/core/schema.h"

namespace arbci::bci {

// The paradigm: flash timing, sequences, dynamic stopping, the calibration run, trials, and
// (keys errp_*) how selections are corrected with error-related potentials.
const core::Schema<ParadigmSettings>& paradigmSchema();
// The online and offline filters: common average, Butterworth band-pass, notch.
const core::Schema<FilterSettings>& filterSchema();
// Between the signal and the classifier: the filters, the epoch window, decimation, channels.
const core::Schema<PipelineSettings>& pipelineSchema();
// How a classifier is trained and cross-validated: the method (classifiers()), its parameters,
// the folds.
const core::Schema<TrainingSettings>& trainingSchema();
// The simulated subject's signal: its seed, montage, rate, block size, line noise, photodiode.
const core::Schema<SimulatedSubjectConfig>& subjectSchema();
// A Lab Streaming Layer stream: which one, and how long to look for it.
const core::Schema<LslSourceSettings>& lslSourceSchema();
// An amplifier through eegdev: the device string.
const core::Schema<EegdevSourceSettings>& eegdevSourceSchema();

}  // namespace arbci::bci
