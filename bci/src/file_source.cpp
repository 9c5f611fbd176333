#include "arbci/bci/file_source.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace arbci::bci {

FileSource::FileSource(Recording recording, std::shared_ptr<const SampleClock> clock,
                       int block_size)
    : recording_(std::move(recording)), clock_(std::move(clock)) {
  if (!clock_) throw std::invalid_argument("file source: no clock");
  if (block_size > 0) recording_.info.block_size = block_size;
  if (recording_.info.block_size <= 0) recording_.info.block_size = kBlockSize;
  std::stable_sort(
      recording_.stimuli.begin(), recording_.stimuli.end(),
      [](const StimulusEvent& a, const StimulusEvent& b) { return a.sample < b.sample; });
}

std::vector<Block> FileSource::poll(int max_blocks) {
  std::vector<Block> blocks;
  const int size = recording_.info.block_size;
  const std::int64_t available =
      std::min(clock_->available(recording_.info.rate_hz), recording_.samples);
  while (static_cast<int>(blocks.size()) < max_blocks && delivered_ < recording_.samples) {
    // The last block of a file may be short.
    const std::int64_t end = std::min<std::int64_t>(delivered_ + size, recording_.samples);
    if (end > available) break;
    Block block(delivered_, recording_.info.channelCount(), static_cast<int>(end - delivered_));
    for (int c = 0; c < block.channels; ++c) {
      std::copy_n(recording_.data.begin() +
                      static_cast<std::ptrdiff_t>(c * recording_.samples + delivered_),
                  block.samples,
                  block.data.begin() + static_cast<std::ptrdiff_t>(c) * block.samples);
    }
    delivered_ = end;
    blocks.push_back(std::move(block));
  }
  return blocks;
}

std::vector<StimulusEvent> FileSource::takeRecordedStimuli() {
  std::vector<StimulusEvent> out;
  while (next_stimulus_ < recording_.stimuli.size() &&
         recording_.stimuli[next_stimulus_].sample < delivered_) {
    out.push_back(recording_.stimuli[next_stimulus_++]);
  }
  return out;
}

std::string FileSource::describe() const {
  char text[96];
  std::snprintf(text, sizeof text, " (%d channels at %g Hz, %.1f s)",
                recording_.info.channelCount(), recording_.info.rate_hz, recording_.seconds());
  return "the file " + recording_.source + text;
}

}  // namespace arbci::bci
