// Small text helpers every reader of names and headers needs (XDF, LSL, BioSig, BIDS, camera
// files), in one place.
#pragma once

#include <string>

namespace arbci::core {

// `text` in lower case (ASCII; other bytes as they are).
std::string lowerCase(std::string text);
// `text` without the white space at either end.
std::string trimmed(const std::string& text);

}  // namespace arbci::core
