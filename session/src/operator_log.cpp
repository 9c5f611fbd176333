#include "arbci/session/operator_log.h"

namespace arbci::session {

const char* toString(Severity severity) {
  switch (severity) {
    case Severity::Info:
      return "info";
    case Severity::Warning:
      return "warning";
    case Severity::Error:
      return "error";
  }
  return "info";
}

void OperatorLog::add(double t, Severity severity, const std::string& text) {
  messages_.push_back({t, severity, text});
}

void OperatorLog::say(double t, Severity severity, const std::string& text) {
  add(t, severity, text);
  if (!terminal_) return;
  // On its own line: the terminal's status line is redrawn in place with \r.
  *terminal_ << "\n" << (severity == Severity::Warning ? "warning: " : "") << text << "\n";
}

}  // namespace arbci::session
