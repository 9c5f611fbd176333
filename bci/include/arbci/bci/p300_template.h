// What is known of the P300 before any data, in a pipeline's features: the prior that learning
// without labels reads the P300's sign by (bci/unsupervised.h, bci/learning_from_use.h).
#pragma once

#include <Eigen/Core>

#include "arbci/bci/features.h"
#include "arbci/bci/signal.h"

namespace arbci::bci {

// A textbook response (a positive deflection peaking 350 ms after the flash, 75 ms wide, 1 uV,
// at the parietal and central midline sites Pz, P3, P4, CPz, Cz, POz, P1, P2; nothing elsewhere)
// put through the same filters, window and feature extraction as a recording's epochs. The
// filters reshape it (a causal high-pass leaves a negative rebound after it), so its sign in
// feature space is read here, not assumed. Empty when the features have none of those sites.
Eigen::VectorXd p300Template(const PipelineSettings& settings, const SignalInfo& info);

}  // namespace arbci::bci
