// The contract every part of the session's cycle keeps, in the spirit of BCI2000's filters:
//   configure  the constructor takes the stage's own settings (its part of the session file, and
//              nothing else), checked before the run (an error names the key, the value and why),
//              and opens its devices and files;
//   start      before the first cycle;
//   step       each displayed frame: reads what earlier stages wrote on the cycle's record this
//              cycle (and what later ones wrote last cycle), writes only its own part;
//   stop       once, at the end of the run (its reason), on a closing cycle: saves what it holds;
//   report     its part of summary.json.
// A stage never holds another stage; what one asks of another travels as a request on the record
// (requests.h). The session times each step under the stage's name (summary.json's "cycle").
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "arbci/session/cycle.h"
#include "arbci/session/operator_log.h"
#include "arbci/session/session_log.h"

namespace arbci::session {

// What every stage may use: the session's clock, its log (log.jsonl), and what the experimenter
// is told (the window's operator log and the terminal).
struct StageServices {
  const Clock& clock;
  SessionLog& log;
  OperatorLog& tell;
};

class Stage {
 public:
  virtual ~Stage() = default;
  virtual const char* name() const = 0;
  virtual void start(Cycle& /*cycle*/) {}
  virtual void step(Cycle& cycle) = 0;
  virtual void stop(Cycle& /*cycle*/, const std::string& /*reason*/) {}
  virtual void report(nlohmann::json& /*summary*/) const {}
};

}  // namespace arbci::session
