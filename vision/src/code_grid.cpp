#include "arbci/vision/id_codes.h"

namespace arbci::vision {

CodeGrid wordToGrid(CodeWord word) {
  CodeGrid grid{};
  for (int p = 0; p < 36; ++p) grid[p] = (word >> (35 - p)) & 1U;
  return grid;
}

CodeWord gridToWord(const CodeGrid& grid) {
  CodeWord word = 0;
  for (int p = 0; p < 36; ++p) {
    if (grid[p]) word |= CodeWord{1} << (35 - p);
  }
  return word;
}

CodeGrid rotateClockwise(const CodeGrid& grid, int turns) {
  CodeGrid current = grid;
  for (int t = 0; t < ((turns % 4) + 4) % 4; ++t) {
    CodeGrid turned{};
    // Clockwise: the cell at (r, c) moves to (c, 5 - r).
    for (int r = 0; r < kCodeCells; ++r) {
      for (int c = 0; c < kCodeCells; ++c) turned[c * 6 + (5 - r)] = current[r * 6 + c];
    }
    current = turned;
  }
  return current;
}

}  // namespace arbci::vision
