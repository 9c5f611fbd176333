#include "arbci/bci/epocher.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace arbci::bci {

Epocher::Epocher(int channels, double rate_hz, const EpochWindow& window, double history_s)
    : channels_(channels),
      offset_(static_cast<int>(std::lround(window.start_s * rate_hz))),
      length_(static_cast<int>(std::lround((window.end_s - window.start_s) * rate_hz))) {
  if (channels <= 0) throw std::invalid_argument("epocher: no channels");
  if (length_ <= 0) throw std::invalid_argument("epoch window must end after it starts");
  history_ =
      std::max(length_ + std::abs(offset_) + 1, static_cast<int>(std::lround(history_s * rate_hz)));
  buffer_.assign(static_cast<size_t>(channels) * history_, 0.0f);
}

void Epocher::addEvent(const StimulusEvent& event) {
  const std::int64_t first = event.sample + offset_;
  const std::int64_t oldest = end_ < 0 ? 0 : std::max(start_, end_ - history_);
  if (end_ >= 0 && first < oldest) {
    ++missed_;
    return;
  }
  events_.push_back(event);
}

std::vector<Epoch> Epocher::push(const Block& block) {
  if (block.channels != channels_) {
    throw std::invalid_argument("epocher: block has " + std::to_string(block.channels) +
                                " channels, expected " + std::to_string(channels_));
  }
  if (end_ < 0) {
    start_ = end_ = block.first_sample;
  } else if (block.first_sample != end_) {
    throw std::invalid_argument("epocher: block starts at sample " +
                                std::to_string(block.first_sample) + ", expected " +
                                std::to_string(end_));
  }
  for (int s = 0; s < block.samples; ++s) {
    const size_t slot = static_cast<size_t>((end_ + s) % history_);
    for (int c = 0; c < channels_; ++c)
      buffer_[static_cast<size_t>(c) * history_ + slot] = block.at(c, s);
  }
  end_ += block.samples;
  return completed();
}

std::vector<Epoch> Epocher::completed() {
  std::vector<Epoch> epochs;
  if (end_ < 0) return epochs;
  const std::int64_t oldest = std::max(start_, end_ - history_);
  std::stable_sort(
      events_.begin(), events_.end(),
      [](const StimulusEvent& a, const StimulusEvent& b) { return a.sample < b.sample; });
  std::vector<StimulusEvent> waiting;
  for (const StimulusEvent& event : events_) {
    const std::int64_t first = event.sample + offset_;
    if (first < oldest) {
      ++missed_;
      continue;
    }
    if (first + length_ > end_) {
      waiting.push_back(event);
      continue;
    }
    Epoch epoch;
    epoch.event = event;
    epoch.channels = channels_;
    epoch.samples = length_;
    epoch.data.resize(static_cast<size_t>(channels_) * length_);
    for (int c = 0; c < channels_; ++c) {
      for (int s = 0; s < length_; ++s) {
        epoch.data[static_cast<size_t>(c) * length_ + s] =
            buffer_[static_cast<size_t>(c) * history_ +
                    static_cast<size_t>((first + s) % history_)];
      }
    }
    epochs.push_back(std::move(epoch));
  }
  events_ = std::move(waiting);
  return epochs;
}

}  // namespace arbci::bci
