// The ERP figures of the Training panel, drawn as `arbci train --plots` draws its PNGs: per
// channel the target and non-target averages overlaid on one scale with their 95 % bands, the
// difference wave and the analysis window; the signed r^2 per channel and time; the scalp map.
#pragma once

#include "arbci/bci/erp.h"

namespace arbci::ui {

// `target` and `other` name the two classes in the legend (an ErrP figure: error, correct).
void drawErpPlots(const bci::ErpCurves& erp, const char* target = "target",
                  const char* other = "non-target");
void drawSignedR2(const bci::ErpCurves& erp);
// The difference at its peak on a head map, where 3 or more channels have 10-20 names.
void drawScalpMap(const bci::ErpCurves& erp);

}  // namespace arbci::ui
