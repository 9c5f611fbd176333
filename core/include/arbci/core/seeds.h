// Every random stream a run draws, each derived from the one seed (a session's eeg.seed, or
// `arbci eeg simulate --seed`) by a rule of its own, named here: no two streams share a sequence,
// a run is reproduced from its seed alone, and a new stream takes a new name rather than another
// offset written where it is used. (The rules are those the recordings and tables in docs/ were
// made with: changing one changes every run of every seed.)
#pragma once

#include <cstdint>

namespace arbci::core {

enum class RandomStream {
  FlashOrder,           // the session's paradigm: the order of each sequence's flashes
  TrialIntents,         // the simulated subject's intended object and cell of each trial
  LeftCamera,           // the simulated cameras' noise
  RightCamera,          //
  SubjectProfile,       // the simulated subject drawn (P300 amplitude, latency, noise)
  SubjectTrials,        // its trial-to-trial variation
  SubjectErrp,          // its error potentials
  RecordingFlashOrder,  // `arbci eeg simulate`: the objects' (or copy task's) flash order
  RecordingGridOrder,   // the grid's flash order
  RecordingChoices,     // the targets it chooses
};

constexpr std::uint64_t seedOf(std::uint64_t seed, RandomStream stream) {
  switch (stream) {
    case RandomStream::FlashOrder:
      return seed + 11;
    case RandomStream::TrialIntents:
      return seed * 31 + 7;
    case RandomStream::LeftCamera:
      return seed * 7 + 1;
    case RandomStream::RightCamera:
      return seed * 7 + 2;
    case RandomStream::SubjectProfile:
      return seed * 0x9E3779B97F4A7C15ULL + 17;
    case RandomStream::SubjectTrials:
      return seed ^ 0xA5A5A5A5ULL;
    case RandomStream::SubjectErrp:
      return seed ^ 0x5EEDE44ULL;
    case RandomStream::RecordingFlashOrder:
      return seed + 1;
    case RandomStream::RecordingGridOrder:
      return seed + 3;
    case RandomStream::RecordingChoices:
      return seed + 2;
  }
  return seed;
}

}  // namespace arbci::core
