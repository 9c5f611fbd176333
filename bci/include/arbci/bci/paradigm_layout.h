// What the stimulus codes of a P300 paradigm mean: single stimuli (each object flashes alone,
// codes 1..stimuli) or the rows and columns of a matrix (codes 1..rows are rows, rows+1..
// rows+columns columns, as BCI2000's P3Speller), with the symbol of each cell when known.
#pragma once

#include <random>
#include <set>
#include <string>
#include <vector>

namespace arbci::bci {

struct ParadigmLayout {
  enum class Kind { SingleStimulus, RowColumn };
  Kind kind = Kind::SingleStimulus;
  int stimuli = 0;                   // single stimulus
  int rows = 0, columns = 0;         // row/column
  std::vector<std::string> symbols;  // row-major, rows * columns, may be empty
  double soa_s = 0.18;               // stimulus onset asynchrony (flash + inter-stimulus interval)

  static ParadigmLayout single(int stimuli, double soa_s = 0.18);
  static ParadigmLayout matrix(int rows, int columns, double soa_s = 0.18);

  int codes() const { return kind == Kind::RowColumn ? rows + columns : stimuli; }
  bool isRow(int code) const { return kind == Kind::RowColumn && code >= 1 && code <= rows; }
  // Number of possible selections (objects or cells).
  int choices() const { return kind == Kind::RowColumn ? rows * columns : stimuli; }
  // Codes selecting one choice: {object} or {row, rows + column}.
  std::set<int> codesOf(int choice) const;  // choice 0-based
  // A copy task's next target, drawn uniformly: an object, or a row and then a column. The one
  // target draw of the session's calibration run and of `arbci eeg simulate`.
  std::set<int> drawTarget(std::mt19937_64& random) const;
  // "object 3", "row 2 column 5", or the cell's symbol.
  std::string describe(const std::set<int>& codes) const;
  std::string describeShape() const;  // "single stimulus, 4 stimuli" / "row/column 6x6"
};

}  // namespace arbci::bci
