// How strongly each simulated component appears at an electrode, from its 10-20 name: the P3 is
// parietal, the N2 central, the visual response and alpha occipital, blinks frontal, the
// error-related potential fronto-central (FCz, Cz).
#pragma once

#include <string>

namespace arbci::bci {

struct ScalpWeights {
  double p3 = 0.3, n2 = 0.3, vep = 0.2, alpha = 0.3, blink = 0.05, errp = 0.3;
};

ScalpWeights scalpWeights(const std::string& electrode);

}  // namespace arbci::bci
