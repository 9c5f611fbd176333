#include "arbci/robot/settings.h"

#include "arbci/robot/udp_socket.h"

namespace arbci::robot {

// Apart from linkSchema() (robot_config.cpp), which names the drivers: a client that reads only
// these keys (`arbci robot`) links no driver, so loads neither MuJoCo nor KDL.
const core::Schema<LinkSettings>& clientLinkSchema() {
  static const core::Schema<LinkSettings> table = [] {
    core::Schema<LinkSettings> t("link", "How a client finds and authenticates to the backend");
    t.text("host", &LinkSettings::host, kLoopback,
           "the backend's host (arbci-robotd: the address it listens on)")
        .integer("port", &LinkSettings::port, 47800, 1, 65535, "its UDP port")
        // 100 ms: the client sends 20 heartbeats in it (every 5 ms), so only 19 or more lost in
        // a row halt the arm. The deadline counts from each heartbeat's send time, so a delayed
        // link halts as a dead one does; a busy PC only delays the heartbeat thread (the highest
        // priority the process may take), which sleeps between beats and is woken promptly even
        // at normal priority (docs/robot.md has the loss model and the false-halt counts).
        .integer("watchdog_ms", &LinkSettings::watchdog_ms, 100, 0, 60000,
                 "the backend halts a running motion (and latches the stop) this long after the "
                 "send time of the commanding client's newest heartbeat (a heartbeat the link "
                 "delayed counts as missing); 0: off (not for a real arm); raise it on a lossy "
                 "link",
                 "ms")
        .text("key_file", &LinkSettings::key_file, "",
              "the shared key (arbci robot keygen); a remote robot needs one, a simulated one "
              "is given a fresh key for each run");
    return t;
  }();
  return table;
}

}  // namespace arbci::robot
