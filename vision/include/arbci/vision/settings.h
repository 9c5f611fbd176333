// The vision module's settings and its registry of marker families. The session's tracker
// section and `arbci detect` take the detector's defaults (kind, border, search_decimate, passes)
// from detectorSchema(); markerFamilies() names every kind of marker the tracker reads, with what
// each is for (docs/settings.md lists them).
#pragma once

#include "arbci/core/registry.h"
#include "arbci/core/schema.h"
#include "arbci/vision/marker.h"
#include "arbci/vision/marker_detector.h"
#include "arbci/vision/marker_family.h"
#include "arbci/vision/search_passes.h"

namespace arbci::vision {

// kind, border, search_decimate, apriltag_refine_edges and passes (the DetectorConfig's settings).
const core::Schema<DetectorConfig>& detectorSchema();
// The search's passes (DetectorConfig::passes).
const core::Schema<SearchPasses>& searchPassesSchema();

}  // namespace arbci::vision
