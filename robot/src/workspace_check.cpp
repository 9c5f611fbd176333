#include "arbci/robot/workspace_check.h"

#include <algorithm>
#include <cstdio>

namespace arbci::robot {

std::string pointText(const Vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f)", p.x, p.y, p.z);
  return text;
}

std::optional<Rejection> outsideWorkspace(const RobotConfig& c, const Vec3& p) {
  const bool inside = p.x >= c.workspace_min.x && p.x <= c.workspace_max.x &&
                      p.y >= c.workspace_min.y && p.y <= c.workspace_max.y &&
                      p.z >= c.workspace_min.z && p.z <= c.workspace_max.z;
  if (!inside)
    return Rejection{RejectReason::OutsideWorkspace, pointText(p) + " lies outside the workspace"};
  if (p.z < c.table_z - 0.001)
    return Rejection{RejectReason::OutsideWorkspace, pointText(p) + " lies below the table"};
  return std::nullopt;
}

Vec3 approachPoint(const RobotConfig& c, const Vec3& p) {
  return {p.x, p.y, std::max(p.z + c.approach_height, c.table_z + c.lift_height)};
}

}  // namespace arbci::robot
