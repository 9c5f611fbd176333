// The events log.jsonl carries, declared once. Each line is {"event": NAME, "t": session
// seconds, FIELDS...}; docs/log.md is printed from this table (`arbci log-events`), and a test
// holds the sources to it: every event written is declared here, every one declared is written.
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace arbci::session {

struct LogEvent {
  std::string_view name;
  std::string_view fields;  // "frame, compute_ms, stages": the keys beside "event" and "t"
  std::string_view meaning;
};

// Every event, by name.
std::span<const LogEvent> logEvents();
// The event named `name`, or null.
const LogEvent* findLogEvent(std::string_view name);
// docs/log.md's table.
std::string logEventsMarkdown();

}  // namespace arbci::session
