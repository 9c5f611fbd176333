// The LSL tests look for streams on this machine only: the lab's other streams, and other test
// processes' on other machines, stay out of what they resolve.
#pragma once

#include "arbci/bci/lsl/config.h"

namespace arbci::test {

inline bci::lsl::LslConfig machineScope() {
  bci::lsl::LslConfig c;
  c.resolve_scope = "machine";
  return c;
}

}  // namespace arbci::test
