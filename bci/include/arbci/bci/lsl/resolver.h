// Finds LSL streams: sends liblsl's discovery query ("LSL:shortinfo") to the configuration's
// discovery addresses and known peers, in waves, and collects the outlets' replies.
#pragma once

#include <string>
#include <vector>

#include "arbci/bci/lsl/config.h"
#include "arbci/bci/lsl/stream_info.h"

namespace arbci::bci::lsl {

// The streams matching `query` (XPath, e.g. buildQuery(...)) that answer within `timeout_s`.
// Returns early, once `minimum` (> 0) streams have answered and a short grace has passed for
// others; `minimum` 0 waits the whole timeout. Each stream once (by uid), with its v4address
// taken from where the reply came from. Throws LslError for an invalid query or no socket.
std::vector<StreamInfo> resolveStreams(const LslConfig& config, const std::string& query,
                                       double timeout_s, int minimum = 1);

// Asks an outlet for its full description (with <desc>: channel labels) over TCP.
StreamInfo fetchFullInfo(const StreamInfo& stream, double timeout_s);

}  // namespace arbci::bci::lsl
