#include "arbci/session/session_log.h"

#include <stdexcept>

namespace arbci::session {

SessionLog::SessionLog(const std::filesystem::path& path) : out_(path, std::ios::trunc) {
  if (!out_) throw std::runtime_error(path.string() + ": cannot write the session log");
}

void SessionLog::write(const std::string& event, double t, nlohmann::json fields) {
  fields["event"] = event;
  fields["t"] = t;
  out_ << fields.dump() << '\n';
  out_.flush();
}

}  // namespace arbci::session
