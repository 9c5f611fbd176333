#include "arbci/robot/robot_config.h"

#include <fstream>
#include <nlohmann/json.hpp>

namespace arbci::robot {
namespace {

Vec3 vec(const nlohmann::json& j, const std::string& field, const std::string& file) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() ||
      !j[2].is_number()) {
    throw ConfigError(file + ": " + field + " must be [x, y, z] in metres");
  }
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

double positive(const nlohmann::json& j, const std::string& field, double fallback,
                const std::string& file) {
  if (!j.contains(field)) return fallback;
  if (!j[field].is_number() || !(j[field].get<double>() > 0.0))
    throw ConfigError(file + ": " + field + " must be a positive number");
  return j[field].get<double>();
}

}  // namespace

RobotConfig RobotConfig::load(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw ConfigError(file + ": cannot open");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& error) {
    throw ConfigError(file + ": not JSON (" + error.what() + ")");
  }
  if (!j.is_object()) throw ConfigError(file + ": must be a JSON object");
  RobotConfig c;
  c.speed_factor = positive(j, "speed_factor", c.speed_factor, file);
  if (j.contains("table_z")) {
    if (!j["table_z"].is_number()) throw ConfigError(file + ": table_z must be a number");
    c.table_z = j["table_z"].get<double>();
  }
  if (j.contains("workspace")) {
    c.workspace_min = vec(j["workspace"].value("min", nlohmann::json()), "workspace.min", file);
    c.workspace_max = vec(j["workspace"].value("max", nlohmann::json()), "workspace.max", file);
    if (!(c.workspace_min.x < c.workspace_max.x && c.workspace_min.y < c.workspace_max.y &&
          c.workspace_min.z < c.workspace_max.z)) {
      throw ConfigError(file + ": workspace.min must lie below workspace.max on every axis");
    }
  }
  c.approach_height = positive(j, "approach_height", c.approach_height, file);
  c.lift_height = positive(j, "lift_height", c.lift_height, file);
  c.cartesian_speed = positive(j, "cartesian_speed", c.cartesian_speed, file);
  c.descend_speed = positive(j, "descend_speed", c.descend_speed, file);
  c.max_joint_speed = positive(j, "max_joint_speed", c.max_joint_speed, file);
  c.gripper_seconds = positive(j, "gripper_seconds", c.gripper_seconds, file);
  if (j.contains("home")) c.home = vec(j["home"], "home", file);
  if (j.contains("objects")) {
    if (!j["objects"].is_array()) throw ConfigError(file + ": objects must be a list");
    for (size_t i = 0; i < j["objects"].size(); ++i) {
      const auto& o = j["objects"][i];
      const std::string at = "objects[" + std::to_string(i) + "]";
      if (!o.is_object() || !o.contains("id") || !o["id"].is_number_integer())
        throw ConfigError(file + ": " + at + ".id must be an integer");
      SimulatedObject object;
      object.id = o["id"].get<int>();
      object.position = vec(o.value("position", nlohmann::json()), at + ".position", file);
      object.height = positive(o, "height", object.height, file);
      object.radius = positive(o, "radius", object.radius, file);
      c.objects.push_back(object);
    }
  }
  return c;
}

std::string RobotConfig::toJson() const {
  auto v = [](const Vec3& p) { return nlohmann::json::array({p.x, p.y, p.z}); };
  nlohmann::json j = {{"speed_factor", speed_factor},
                      {"table_z", table_z},
                      {"workspace", {{"min", v(workspace_min)}, {"max", v(workspace_max)}}},
                      {"approach_height", approach_height},
                      {"lift_height", lift_height},
                      {"cartesian_speed", cartesian_speed},
                      {"descend_speed", descend_speed},
                      {"max_joint_speed", max_joint_speed},
                      {"gripper_seconds", gripper_seconds},
                      {"home", v(home)},
                      {"objects", nlohmann::json::array()}};
  for (const SimulatedObject& o : objects) {
    j["objects"].push_back(
        {{"id", o.id}, {"position", v(o.position)}, {"height", o.height}, {"radius", o.radius}});
  }
  return j.dump(2);
}

}  // namespace arbci::robot
