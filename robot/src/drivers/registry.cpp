// The arms arbci-robotd can drive, by name. A new driver is a file in this folder that defines
// its Entry, and its line here.
#include "arbci/robot/settings.h"

namespace arbci::robot {

DriverRegistry::Entry simulatedArmDriver();
DriverRegistry::Entry mujocoArmDriver();

const DriverRegistry& robotDrivers() {
  static const DriverRegistry registry = [] {
    DriverRegistry r("robot driver", "arbci-robotd --driver");
    r.add(simulatedArmDriver());
    r.add(mujocoArmDriver());
    return r;
  }();
  return registry;
}

}  // namespace arbci::robot
