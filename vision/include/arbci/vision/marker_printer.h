// Printable ID markers, drawn exactly as ARToolKitPlus's own marker images: 6x6 code cells inside
// a black border (1 cell of 8 for the thin border 0.125, 3 of 12 for the standard 0.25). For
// printing, a white quiet zone surrounds the black square and sizes are in millimetres.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/vision/marker.h"

namespace arbci::vision {

// One pixel per cell, black square only (as ARToolKitPlus's id-markers/*.png): 0 black, 255
// white. Throws std::invalid_argument for an id out of range, a border other than 0.125 or 0.25,
// or a kind that is not bch or simple.
cv::Mat markerCells(MarkerKind kind, int id, double border);

struct PrintLayout {
  double size_mm = 80.0;  // side of the black square
  int dpi = 300;          // PNG resolution
  // White margin around the black square: one cell, at least this many millimetres.
  double min_quiet_zone_mm = 5.0;
};

// The marker with its quiet zone at print resolution (8-bit grey).
cv::Mat renderMarkerImage(MarkerKind kind, int id, double border, const PrintLayout& layout);
// The same as an SVG document with millimetre units (one path for the black cells).
std::string renderMarkerSvg(MarkerKind kind, int id, double border, const PrintLayout& layout);

// Several markers on A4 pages' worth of one sheet, each labelled with its kind, id and size,
// with a thin grey cutting frame around its quiet zone. Throws std::invalid_argument when a
// marker does not fit on A4 with its label.
cv::Mat renderSheetImage(MarkerKind kind, const std::vector<int>& ids, double border,
                         const PrintLayout& layout);
std::string renderSheetSvg(MarkerKind kind, const std::vector<int>& ids, double border,
                           const PrintLayout& layout);

}  // namespace arbci::vision
