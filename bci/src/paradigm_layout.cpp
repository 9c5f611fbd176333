#include "arbci/bci/paradigm_layout.h"

#include <stdexcept>

namespace arbci::bci {

ParadigmLayout ParadigmLayout::single(int stimuli, double soa_s) {
  if (stimuli < 2)
    throw std::invalid_argument("a single-stimulus paradigm needs at least 2 stimuli");
  ParadigmLayout layout;
  layout.stimuli = stimuli;
  layout.soa_s = soa_s;
  return layout;
}

ParadigmLayout ParadigmLayout::matrix(int rows, int columns, double soa_s) {
  if (rows < 1 || columns < 1 || rows * columns < 2)
    throw std::invalid_argument("a matrix needs at least 2 cells");
  ParadigmLayout layout;
  layout.kind = Kind::RowColumn;
  layout.rows = rows;
  layout.columns = columns;
  layout.soa_s = soa_s;
  return layout;
}

std::set<int> ParadigmLayout::codesOf(int choice) const {
  if (kind == Kind::RowColumn) return {choice / columns + 1, rows + choice % columns + 1};
  return {choice + 1};
}

std::set<int> ParadigmLayout::drawTarget(std::mt19937_64& random) const {
  if (kind == Kind::SingleStimulus) return {std::uniform_int_distribution<int>(1, stimuli)(random)};
  const int row = std::uniform_int_distribution<int>(1, rows)(random);
  const int column = std::uniform_int_distribution<int>(1, columns)(random);
  return {row, rows + column};
}

std::string ParadigmLayout::describe(const std::set<int>& codes) const {
  if (kind == Kind::SingleStimulus)
    return codes.size() == 1 ? "object " + std::to_string(*codes.begin()) : "?";
  int row = 0, column = 0;
  for (int code : codes) {
    if (isRow(code))
      row = code;
    else
      column = code - rows;
  }
  if (row < 1 || column < 1 || column > columns) return "?";
  const size_t cell = static_cast<size_t>((row - 1) * columns + column - 1);
  if (cell < symbols.size()) return symbols[cell];
  return "row " + std::to_string(row) + " column " + std::to_string(column);
}

std::string ParadigmLayout::describeShape() const {
  if (kind == Kind::RowColumn)
    return "row/column " + std::to_string(rows) + "x" + std::to_string(columns);
  return "single stimulus, " + std::to_string(stimuli) + " stimuli";
}

}  // namespace arbci::bci
