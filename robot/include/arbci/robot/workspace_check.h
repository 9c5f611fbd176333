// What every driver checks before its own reach: the target inside the configured workspace box
// and not below the table, and the point above it the arm passes through.
#pragma once

#include <optional>
#include <string>

#include "arbci/robot/robot_config.h"
#include "arbci/robot/robot_driver.h"

namespace arbci::robot {

// "(0.100, 0.600, 0.060)", for messages.
std::string pointText(const Vec3& p);
// Why `p` is outside the workspace or below the table, or nothing.
std::optional<Rejection> outsideWorkspace(const RobotConfig& config, const Vec3& p);
// Where a grasp or put-down at `p` comes down from.
Vec3 approachPoint(const RobotConfig& config, const Vec3& p);

}  // namespace arbci::robot
