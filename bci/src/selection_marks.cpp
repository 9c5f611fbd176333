#include "arbci/bci/selection_marks.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "arbci/bci/paradigm.h"

namespace arbci::bci {
namespace {

bool startsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

// "Selection 9: trial 1, objects", "Selection 3: calibration, retake of 2", or a copy task's
// "Selection 3 target 2".
std::optional<MarkedSelection> parseMark(const Annotation& a) {
  MarkedSelection m;
  m.sample = a.sample;
  int number = 0, trial = 0, retake = 0, used = 0;
  char kind[16] = "";
  const char* text = a.text.c_str();
  if (std::sscanf(text, "Selection %d: trial %d, %15s%n", &number, &trial, kind, &used) == 3 &&
      text[used] == '\0' && number > 0) {
    const std::string k = kind;
    if (k != "objects" && k != "cells") return std::nullopt;
    m.number = number;
    m.trial = trial;
    m.kind = k == "objects" ? SelectionKind::Objects : SelectionKind::Cells;
    return m;
  }
  if (std::sscanf(text, "Selection %d: calibration, retake of %d%n", &number, &retake, &used) ==
          2 &&
      text[used] == '\0' && number > 0) {
    m.number = number;
    m.retake_of = retake;
    return m;
  }
  used = 0;
  if (std::sscanf(text, "Selection %d: calibration%n", &number, &used) == 1 && used > 0 &&
      text[used] == '\0' && number > 0) {
    m.number = number;
    return m;
  }
  used = 0;
  if (std::sscanf(text, "Selection %d target %n", &number, &used) == 1 && used > 0 && number > 0) {
    m.number = number;
    return m;
  }
  return std::nullopt;
}

// Recordings from before the marks: each flashing phase starts a selection, unless it resumes
// one that a pause interrupted.
std::vector<MarkedSelection> fromPhases(const Recording& r) {
  const std::string phase = kPhaseAnnotation;
  const std::string calibration = phase + toString(Phase::CalibrationFlashing);
  const std::string objects = phase + toString(Phase::ObjectFlashing);
  const std::string cells = phase + toString(Phase::CellFlashing);
  const std::string paused = phase + toString(Phase::Paused);
  std::vector<MarkedSelection> out;
  bool after_pause = false;
  int trial = 0;
  for (const Annotation& a : r.annotations) {
    if (!startsWith(a.text, phase)) continue;
    std::optional<SelectionKind> kind;
    if (a.text == calibration) kind = SelectionKind::Calibration;
    if (a.text == objects) kind = SelectionKind::Objects;
    if (a.text == cells) kind = SelectionKind::Cells;
    if (kind && !after_pause) {
      MarkedSelection m;
      m.number = static_cast<int>(out.size()) + 1;
      m.kind = *kind;
      if (*kind == SelectionKind::Objects) ++trial;
      m.trial = *kind == SelectionKind::Calibration ? 0 : trial;
      m.sample = a.sample;
      out.push_back(m);
    }
    after_pause = startsWith(a.text, paused);
  }
  return out;
}

bool wanted(const std::vector<SelectionKind>& kinds, SelectionKind kind) {
  return std::find(kinds.begin(), kinds.end(), kind) != kinds.end();
}

}  // namespace

const char* toString(SelectionKind kind) {
  switch (kind) {
    case SelectionKind::Calibration:
      return "calibration";
    case SelectionKind::Objects:
      return "objects";
    case SelectionKind::Cells:
      return "cells";
  }
  return "unknown";
}

std::string selectionMark(const MarkedSelection& s) {
  std::string text = "Selection " + std::to_string(s.number) + ": ";
  if (s.kind == SelectionKind::Calibration) {
    text += "calibration";
    if (s.retake_of) text += ", retake of " + std::to_string(*s.retake_of);
    return text;
  }
  return text + "trial " + std::to_string(s.trial) + ", " + toString(s.kind);
}

std::vector<MarkedSelection> markedSelections(const Recording& r) {
  std::vector<MarkedSelection> marks;
  for (const Annotation& a : r.annotations) {
    if (!startsWith(a.text, "Selection ")) continue;
    if (auto m = parseMark(a)) marks.push_back(*m);
  }
  if (marks.empty()) marks = fromPhases(r);
  std::stable_sort(
      marks.begin(), marks.end(),
      [](const MarkedSelection& a, const MarkedSelection& b) { return a.sample < b.sample; });
  return marks;
}

std::optional<ParadigmLayout> gridLayoutOf(const Recording& r) {
  const auto map = r.parameters.find("StimulusCodeMap");
  if (map == r.parameters.end()) return std::nullopt;
  // "1=object 10;...;101=row 1;...;104=column 1;..."
  int rows = 0, columns = 0;
  std::stringstream entries(map->second);
  std::string entry;
  while (std::getline(entries, entry, ';')) {
    int code = 0, index = 0;
    char what[16] = "";
    if (std::sscanf(entry.c_str(), "%d=%15s %d", &code, what, &index) != 3) continue;
    if (code <= kGridCodeBase) continue;
    if (std::string(what) == "row") rows = std::max(rows, index);
    if (std::string(what) == "column") columns = std::max(columns, index);
  }
  if (rows < 1 || columns < 1) return std::nullopt;
  return ParadigmLayout::matrix(rows, columns);
}

SelectionsOfKind selectionsOfKind(const Recording& r, const std::vector<MarkedSelection>& marks,
                                  const std::vector<SelectionKind>& kinds) {
  SelectionsOfKind out;
  out.recording = r;
  out.recording.stimuli.clear();
  const bool cells = wanted(kinds, SelectionKind::Cells);
  if (cells) {
    const auto grid = gridLayoutOf(r);
    if (!grid) return out;
    out.recording.parameters["Paradigm"] =
        "row/column " + std::to_string(grid->rows) + "x" + std::to_string(grid->columns);
  }
  size_t next = 0;  // marks[next - 1] is the selection of the flashes now
  int last_taken = -1;
  for (const StimulusEvent& e : r.stimuli) {
    while (next < marks.size() && marks[next].sample <= e.sample) ++next;
    if (next == 0) continue;  // before the first selection
    const MarkedSelection& m = marks[next - 1];
    if (!wanted(kinds, m.kind)) continue;
    const bool grid_code = e.code > kGridCodeBase;
    if (grid_code != (m.kind == SelectionKind::Cells)) continue;  // another paradigm's flash
    StimulusEvent kept = e;
    if (grid_code) kept.code -= kGridCodeBase;
    out.recording.stimuli.push_back(kept);
    if (static_cast<int>(next) - 1 != last_taken) {
      out.selections.push_back(m);
      last_taken = static_cast<int>(next) - 1;
    }
  }
  return out;
}

}  // namespace arbci::bci
