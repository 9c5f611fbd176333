// What the experimenter is told, in one place: every end, abort, fault, pre-flight failure,
// refusal, pause and warning, with its session time, in the same words as log.jsonl and
// summary.json. The window's Operator log panel lists it (filterable); a terminal run gets each
// message on its progress stream as it is said. The session's stages say things through it
// (StageServices), never by writing to a stream of their own.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

namespace arbci::session {

enum class Severity { Info, Warning, Error };
const char* toString(Severity severity);  // "info", "warning", "error"

struct OperatorMessage {
  double t = 0.0;  // session time, seconds
  Severity severity = Severity::Info;
  std::string text;
};

class OperatorLog {
 public:
  // `terminal`: where each message is also printed (null: nowhere).
  explicit OperatorLog(std::ostream* terminal = nullptr) : terminal_(terminal) {}
  void say(double t, Severity severity, const std::string& text);
  // Kept for the window only: what the terminal already prints in its own words (the end).
  void add(double t, Severity severity, const std::string& text);
  const std::vector<OperatorMessage>& messages() const { return messages_; }

 private:
  std::ostream* terminal_;
  std::vector<OperatorMessage> messages_;
};

}  // namespace arbci::session
