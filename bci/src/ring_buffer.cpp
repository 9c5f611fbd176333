#include "arbci/bci/ring_buffer.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace arbci::bci {

RingBuffer::RingBuffer(int channels, int capacity_samples)
    : channels_(channels),
      capacity_(capacity_samples),
      data_(static_cast<size_t>(channels) * capacity_samples, 0.0f) {
  if (channels <= 0 || capacity_samples <= 0)
    throw std::invalid_argument("ring buffer needs channels and capacity");
}

void RingBuffer::write(const Block& block) {
  std::lock_guard lock(mutex_);
  if (block.channels != channels_) {
    throw std::invalid_argument("ring buffer: block has " + std::to_string(block.channels) +
                                " channels, not " + std::to_string(channels_));
  }
  if (end_ < 0) {
    end_ = start_ = block.first_sample;
  } else if (block.first_sample != end_) {
    throw std::invalid_argument("ring buffer: block starts at sample " +
                                std::to_string(block.first_sample) + ", expected " +
                                std::to_string(end_));
  }
  for (int s = 0; s < block.samples; ++s) {
    const size_t slot = static_cast<size_t>((end_ + s) % capacity_);
    for (int c = 0; c < channels_; ++c)
      data_[static_cast<size_t>(c) * capacity_ + slot] = block.at(c, s);
  }
  end_ += block.samples;
}

std::int64_t RingBuffer::end() const {
  std::lock_guard lock(mutex_);
  return std::max<std::int64_t>(end_, 0);
}

RingBuffer::Reader RingBuffer::reader(std::int64_t from) {
  std::lock_guard lock(mutex_);
  return Reader(*this, from >= 0 ? from : std::max<std::int64_t>(end_, 0));
}

RingBuffer::Read RingBuffer::Reader::read(int max_samples) {
  RingBuffer& b = *buffer_;
  std::lock_guard lock(b.mutex_);
  Read result;
  if (b.end_ < 0) return result;
  const std::int64_t oldest = std::max(b.start_, b.end_ - b.capacity_);
  if (position_ < oldest) {
    result.lost = oldest - position_;
    position_ = oldest;
  }
  const int count = static_cast<int>(std::clamp<std::int64_t>(b.end_ - position_, 0, max_samples));
  result.block = Block(position_, b.channels_, count);
  for (int s = 0; s < count; ++s) {
    const size_t slot = static_cast<size_t>((position_ + s) % b.capacity_);
    for (int c = 0; c < b.channels_; ++c)
      result.block.at(c, s) = b.data_[static_cast<size_t>(c) * b.capacity_ + slot];
  }
  position_ += count;
  return result;
}

}  // namespace arbci::bci
