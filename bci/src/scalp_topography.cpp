#include "scalp_topography.h"

#include <algorithm>

#include "arbci/bci/electrode_positions.h"

namespace arbci::bci {

ScalpWeights scalpWeights(const std::string& electrode) {
  const std::string name = electrodeKey(electrode);
  const bool midline = !name.empty() && name.back() == 'Z';
  auto starts = [&](const char* prefix) { return name.rfind(prefix, 0) == 0; };
  ScalpWeights w;
  if (starts("FP") || starts("AF")) {
    w = {0.3, 0.5, 0.05, 0.15, 1.0, 0.55};
  } else if (starts("FC")) {
    w = {0.55, 0.9, 0.1, 0.25, 0.35, 1.0};
  } else if (starts("F")) {
    w = {0.45, 0.8, 0.08, 0.2, 0.5, 0.8};
  } else if (starts("CP")) {
    w = {0.9, 0.8, 0.3, 0.5, 0.12, 0.6};
  } else if (starts("C")) {
    w = {0.8, 1.0, 0.2, 0.4, 0.2, 0.9};
  } else if (starts("T")) {
    w = {0.35, 0.4, 0.3, 0.4, 0.15, 0.25};
  } else if (starts("PO")) {
    w = {0.65, 0.4, 0.9, 0.95, 0.03, 0.25};
  } else if (starts("P")) {
    w = {1.0, 0.6, 0.5, 0.75, 0.06, 0.4};
  } else if (starts("O") || starts("I")) {
    w = {0.5, 0.3, 1.0, 1.0, 0.02, 0.15};
  }
  if (!midline) {
    w.p3 *= 0.85;  // the P3 and the ErrP peak on the midline
    w.errp *= 0.8;
  }
  return w;
}

}  // namespace arbci::bci
