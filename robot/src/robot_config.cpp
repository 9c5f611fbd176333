#include "arbci/robot/robot_config.h"

#include <fstream>
#include <nlohmann/json.hpp>

#include "arbci/robot/settings.h"
#include "arbci/robot/udp_socket.h"

namespace arbci::robot {
namespace {

using Json = nlohmann::json;
using core::Key;
using core::Type;

constexpr double kTiny = 1e-6;  // "positive": above it

const core::Schema<RobotConfig>& workspaceSchema() {
  static const core::Schema<RobotConfig> table = [] {
    core::Schema<RobotConfig> t("workspace", "The box the tool may reach (robot frame)");
    t.vector3("min", &RobotConfig::workspace_min, {-0.7, 0.2, 0.0}, "its lower corner", "m");
    t.vector3("max", &RobotConfig::workspace_max, {0.7, 1.1, 0.6}, "its upper corner", "m");
    t.rule([](const Json& w) -> std::optional<std::pair<std::string, std::string>> {
      for (int i = 0; i < 3; ++i) {
        if (!(w["min"][i].get<double>() < w["max"][i].get<double>()))
          return std::pair{"min", "must lie below workspace.max on every axis"};
      }
      return std::nullopt;
    });
    return t;
  }();
  return table;
}

}  // namespace

const core::Schema<SimulatedObject>& objectSchema() {
  static const core::Schema<SimulatedObject> table = [] {
    core::Schema<SimulatedObject> t("object", "An object of the simulated world");
    t.required(core::Key{"id", Type::Integer, nullptr, "its marker id", "", 0, 1 << 30},
               &SimulatedObject::id);
    t.vector3("position", &SimulatedObject::position, nullptr, "the centre of its top face", "m",
              true);
    t.number("height", &SimulatedObject::height, 0.06, kTiny, 10.0, "its height", "m")
        .number("radius", &SimulatedObject::radius, 0.03, kTiny, 10.0,
                "its footprint's radius, for contact and grasping (the mujoco driver: half the "
                "side of its square footprint)",
                "m")
        .number("mass", &SimulatedObject::mass, 0.15, 0.001, 20.0, "mujoco driver: its mass", "kg")
        .number("friction", &SimulatedObject::friction, 0.8, 0.05, 3.0,
                "mujoco driver: its sliding friction coefficient");
    return t;
  }();
  return table;
}

const core::Schema<RobotConfig>& configSchema() {
  static const core::Schema<RobotConfig> table = [] {
    using R = RobotConfig;
    core::Schema<R> t("robot backend", "The backend's configuration (arbci-robotd --config)");
    t.number("speed_factor", &R::speed_factor, 1.0, 0.01, 100.0,
             "simulated seconds per real second")
        .number("table_z", &R::table_z, 0.0, -2.0, 2.0, "the table's height", "m")
        .sectionOf("workspace", workspaceSchema())
        .number("approach_height", &R::approach_height, 0.10, kTiny, 2.0,
                "above the target before descending", "m")
        .number("lift_height", &R::lift_height, 0.25, kTiny, 2.0, "above the table after grasping",
                "m")
        .number("cartesian_speed", &R::cartesian_speed, 0.30, kTiny, 5.0, "the tool's speed", "m/s")
        .number("descend_speed", &R::descend_speed, 0.06, kTiny, 5.0,
                "the tool's speed down to contact", "m/s")
        .number("max_joint_speed", &R::max_joint_speed, 1.2, kTiny, 20.0, "any joint's limit",
                "rad/s")
        .number("gripper_seconds", &R::gripper_seconds, 0.5, kTiny, 60.0,
                "how long the gripper takes to open or close", "s");
    t.vector3("home", &R::home, {0.0, 0.45, 0.45}, "where HOME parks the tool", "m");
    t.text("model", &R::model, "",
           "mujoco driver: the arm's MJCF file, or arm6 or arm7, the project's 6- and 7-axis "
           "arms (\"\": arm6); docs/robot.md names what a model must provide")
        .number("grip_force", &R::grip_force, 15.0, 0.5, 500.0,
                "mujoco driver: the gripper closes until each finger presses this hard", "N")
        .number("contact_force", &R::contact_force, 3.0, 0.1, 500.0,
                "mujoco driver: a descent ends when the wrist's force changes this much", "N");
    t.list("objects", &R::objects, objectSchema(), Json::array(), 0,
           "the simulated world's objects (none: a real arm's world is its own)");
    return t;
  }();
  return table;
}

const core::Schema<LinkSettings>& linkSchema() {
  static const core::Schema<LinkSettings> table = [] {
    core::Schema<LinkSettings> t("link", "The robot backend: its UDP address and its arm");
    for (const char* key : {"host", "port", "watchdog_ms", "key_file"})
      t.adopt(clientLinkSchema(), key);
    // The kinematic arm by default: it puts an object exactly where it was sent, so the
    // default session measures the tracker and the classifier, not the grasp.
    t.text("driver", &LinkSettings::driver, "simulated",
           "the arm arbci-robotd drives: " + robotDrivers().list(", "),
           [] { return robotDrivers().names(); });
    return t;
  }();
  return table;
}

LinkSettings::LinkSettings() {
  linkSchema().applyDefaults(*this);
}

SimulatedObject::SimulatedObject() : id(0), position{} {
  objectSchema().applyDefaults(*this);
}

RobotConfig::RobotConfig() {
  configSchema().applyDefaults(*this);
}

RobotConfig RobotConfig::load(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw ConfigError(file + ": cannot open");
  Json j;
  try {
    in >> j;
  } catch (const Json::exception& error) {
    throw ConfigError(file + ": not JSON (" + error.what() + ")");
  }
  RobotConfig c;
  try {
    configSchema().read(configSchema().resolve(j, core::Place{file, ""}), c);
  } catch (const core::SettingsError& error) {
    throw ConfigError(error.what());
  }
  return c;
}

std::string RobotConfig::toJson() const {
  return configSchema().write(*this).dump(2);
}

}  // namespace arbci::robot
