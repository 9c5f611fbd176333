// Where a recording's selections start, and what each was, from its annotations: a session marks
// each selection as it starts ("Selection 9: trial 1, objects"; the calibration run's "Selection
// 3: calibration"), so an analysis splits the flashes where the session did, never by the gaps
// between them (trial 1 may start less than a second after the calibration's last flash).
// Recordings from before the marks are read from their phase annotations ("Phase phase 1:
// objects flashing"), every object selection then counted as a trial of its own; a copy task's
// cued selections ("Selection 3 target 2") are calibration selections.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arbci/bci/paradigm_layout.h"
#include "arbci/bci/recording.h"

namespace arbci::bci {

enum class SelectionKind { Calibration, Objects, Cells };
const char* toString(SelectionKind kind);

struct MarkedSelection {
  int number = 0;  // the session's count of selections, from 1
  SelectionKind kind = SelectionKind::Calibration;
  int trial = 0;            // online: the trial it belongs to; calibration: 0
  std::int64_t sample = 0;  // where it starts
  std::optional<int> retake_of;
};

// The annotation a session writes as a selection starts.
std::string selectionMark(const MarkedSelection& selection);

// Every selection the recording marks, in order; empty when it marks none (a BCI2000 file, a
// copy task from before the marks: split those by gaps).
std::vector<MarkedSelection> markedSelections(const Recording& recording);

// A session's grid (row/column codes 100 + row, 100 + rows + column): its layout from the
// recording's StimulusCodeMap parameter, or nothing when it has no grid.
std::optional<ParadigmLayout> gridLayoutOf(const Recording& recording);
// The code a grid code has in its own layout (row/column: 1..rows+columns).
inline constexpr int kGridCodeBase = 100;

// The recording's flashes of the selections of `kinds` as a recording of their own layout (the
// objects' codes as they are; the grid's as 1..rows+columns with the layout "row/column RxC"),
// and where each of those selections starts (for DatasetOptions::selection_starts).
struct SelectionsOfKind {
  Recording recording;
  std::vector<MarkedSelection> selections;  // those with flashes, in order
};
SelectionsOfKind selectionsOfKind(const Recording& recording,
                                  const std::vector<MarkedSelection>& marks,
                                  const std::vector<SelectionKind>& kinds);

}  // namespace arbci::bci
