// The timing check's figure: a histogram of the photodiode offsets (one bar per EEG sample
// period), with the mean, SD and count in the title and labelled axes.
#pragma once

#include <filesystem>

#include "arbci/bci/photodiode_check.h"

namespace arbci::app {

void writeTimingHistogram(const std::filesystem::path& path, const bci::PhotodiodeReport& report);

}  // namespace arbci::app
