// The order of flashes: each sequence presents every stimulus code once in random order, and no
// code flashes twice in a row across a sequence boundary.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

namespace arbci::bci {

class StimulusSequencer {
 public:
  // Codes 1..count. Throws std::invalid_argument when count < 1.
  StimulusSequencer(int count, std::uint64_t seed);
  std::vector<int> next();

 private:
  int count_;
  std::mt19937_64 random_;
  int last_ = 0;
};

}  // namespace arbci::bci
