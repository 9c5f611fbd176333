// The marker families the tracker reads, each a registry entry that says how: squares whose
// cells are a code (IdCode), squares matched to trained patterns, or markers a library of their
// own finds in the whole image. The detector, the reader and the printer ask the family's entry;
// a new family is one file (vision/src/families/) and its line in markerFamilies().
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "arbci/core/registry.h"
#include "arbci/vision/id_codes.h"
#include "arbci/vision/marker.h"
#include "arbci/vision/marker_detector.h"

namespace arbci::vision {

// A square's 6x6 cells read as an id (ARToolKitPlus's simple and BCH codes).
struct IdCode {
  int max_id = 0;  // ids 0..max_id
  std::optional<DecodedId> (*decode)(CodeWord word) = nullptr;
  CodeWord (*encode)(int id) = nullptr;
  // Bits by which `id` turned a quarter, half or three-quarters differs from any codeword
  // (`arbci marker make` warns under 5); nullptr when the code does not say.
  int (*rotation_margin)(int id) = nullptr;
  // It corrects errors: a word hard decoding misses is read again (sharpened cells, Chase).
  bool corrects_errors = false;
  // Every id has at least this many light cells, so an outline enclosing none, or a flat code
  // area, is no marker (0: an id may be all dark).
  int min_light_cells = 0;
};

// Markers found in the whole frame by a library of their own (its own threshold and quads).
struct WholeImageSearch {
  // Corners as every detection: the printed marker's TL, TR, BR, BL in OpenCV pixels.
  std::function<std::vector<MarkerDetection>(const cv::Mat& gray)> detect;
  std::string threshold_mode;  // how it thresholds, for the result
};

struct MarkerFamily {
  double border = 0.25;      // its usual border, as a fraction of the side
  bool in_sessions = false;  // a session can track objects by it (ids alone: no extra files)
  // How its markers are read: one of the three.
  const IdCode* code = nullptr;  // squares whose cells are this code
  bool templates = false;        // squares matched to DetectorConfig::templates
  // The whole frame searched by another library; throws std::invalid_argument for a
  // configuration it cannot take (an unknown dictionary).
  std::function<WholeImageSearch(const DetectorConfig&)> whole_image;

  bool squares() const { return !whole_image; }       // found by our quad search
  bool printable() const { return code != nullptr; }  // `arbci marker make` draws it
};
using MarkerFamilyRegistry = core::Registry<MarkerFamily>;
const MarkerFamilyRegistry& markerFamilies();

// The family `kind` names; throws std::invalid_argument naming those there are.
const MarkerFamily& familyOf(MarkerKind kind);

}  // namespace arbci::vision
