#include "arbci/bci/stimulus_sequence.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace arbci::bci {

StimulusSequencer::StimulusSequencer(int count, std::uint64_t seed) : count_(count), random_(seed) {
  if (count < 1) throw std::invalid_argument("a stimulus sequence needs at least one stimulus");
}

std::vector<int> StimulusSequencer::next() {
  std::vector<int> order(static_cast<size_t>(count_));
  std::iota(order.begin(), order.end(), 1);
  std::shuffle(order.begin(), order.end(), random_);
  // A repeat across the boundary is moved to a random later place in this sequence.
  if (count_ > 1 && order.front() == last_) {
    std::uniform_int_distribution<int> place(1, count_ - 1);
    std::swap(order[0], order[static_cast<size_t>(place(random_))]);
  }
  last_ = order.back();
  return order;
}

}  // namespace arbci::bci
