#include "mujoco/scene_model.h"

#include <pugixml.hpp>

#include <cstdio>
#include <sstream>

namespace arbci::robot::mujoco {
namespace {

std::string numbers(std::initializer_list<double> values) {
  std::string out;
  char one[32];
  for (double v : values) {
    std::snprintf(one, sizeof one, "%s%.9g", out.empty() ? "" : " ", v);
    out += one;
  }
  return out;
}

// Every attribute the scene's bodies need is set here, so the arm file's defaults do not reach
// them.
void addTable(pugi::xml_node world, const RobotConfig& c) {
  pugi::xml_node table = world.append_child("geom");
  table.append_attribute("name") = "table";
  table.append_attribute("type") = "box";
  table.append_attribute("size") = numbers({1.5, 1.5, 0.02}).c_str();
  table.append_attribute("pos") = numbers({0.0, 0.5, c.table_z - 0.02}).c_str();
  table.append_attribute("contype") = 1;
  table.append_attribute("conaffinity") = 1;
  table.append_attribute("condim") = 4;
  table.append_attribute("friction") = numbers({0.8, 0.02, 0.001}).c_str();
  table.append_attribute("rgba") = "0.55 0.45 0.35 1";
}

void addObject(pugi::xml_node world, const SimulatedObject& o) {
  const std::string name = "object_" + std::to_string(o.id);
  pugi::xml_node body = world.append_child("body");
  body.append_attribute("name") = name.c_str();
  body.append_attribute("pos") =
      numbers({o.position.x, o.position.y, o.position.z - o.height / 2}).c_str();
  pugi::xml_node joint = body.append_child("joint");
  joint.append_attribute("name") = name.c_str();
  joint.append_attribute("type") = "free";
  joint.append_attribute("damping") = 0;
  joint.append_attribute("armature") = 0;
  pugi::xml_node geom = body.append_child("geom");
  geom.append_attribute("name") = name.c_str();
  geom.append_attribute("type") = "box";
  geom.append_attribute("size") = numbers({o.radius, o.radius, o.height / 2}).c_str();
  geom.append_attribute("mass") = o.mass;
  geom.append_attribute("contype") = 1;
  geom.append_attribute("conaffinity") = 1;
  geom.append_attribute("condim") = 4;
  geom.append_attribute("friction") = numbers({o.friction, 0.02, 0.001}).c_str();
  geom.append_attribute("rgba") = "0.3 0.5 0.8 1";
}

int named(const mjModel& m, mjtObj type, const std::string& name) {
  return mj_name2id(&m, type, name.c_str());
}

}  // namespace

std::string composeScene(const std::string& arm_xml, const std::filesystem::path& folder,
                         const RobotConfig& config, const std::string& what) {
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_string(arm_xml.c_str());
  if (!parsed)
    throw ConfigError(what + " is not XML: " + parsed.description() + " at byte " +
                      std::to_string(parsed.offset));
  pugi::xml_node root = doc.child("mujoco");
  if (!root) throw ConfigError(what + " has no <mujoco> element (is it MJCF?)");
  if (!folder.empty()) {
    pugi::xml_node compiler = root.child("compiler");
    if (!compiler) compiler = root.prepend_child("compiler");
    for (const char* key : {"meshdir", "texturedir"}) {
      pugi::xml_attribute dir = compiler.attribute(key);
      if (!dir) dir = compiler.append_attribute(key);
      const std::filesystem::path given = dir.value();
      if (given.is_relative()) dir = (folder / given).lexically_normal().string().c_str();
    }
  }
  pugi::xml_node world = root.child("worldbody");
  if (!world) world = root.append_child("worldbody");
  addTable(world, config);
  for (const SimulatedObject& o : config.objects) addObject(world, o);
  std::ostringstream out;
  doc.save(out, "  ");
  return out.str();
}

ModelPtr compile(const std::string& xml, const std::string& what) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "arbci_scene.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0)
    throw ConfigError(what + ": cannot hold the model in memory");
  const int file = mj_findFileVFS(vfs.get(), name);
  std::copy(xml.begin(), xml.end(), static_cast<char*>(vfs->filedata[file]));
  char error[1000] = "";
  ModelPtr model(mj_loadXML(name, vfs.get(), error, sizeof error));
  mj_deleteVFS(vfs.get());
  if (!model) throw ConfigError(what + ": MuJoCo cannot load it: " + error);
  return model;
}

Contract findContract(const mjModel& m, const RobotConfig& config, const std::string& what) {
  auto lacks = [&](const std::string& thing) {
    return ConfigError(what + " has no " + thing + " (docs/robot.md lists what a model provides)");
  };
  Contract c;
  for (int k = 1;; ++k) {
    const int joint = named(m, mjOBJ_JOINT, "arm_joint_" + std::to_string(k));
    if (joint < 0) break;
    if (m.jnt_type[joint] != mjJNT_HINGE)
      throw ConfigError(what + ": arm_joint_" + std::to_string(k) + " is not a hinge joint");
    int actuator = -1;
    for (int a = 0; a < m.nu; ++a) {
      if (m.actuator_trntype[a] == mjTRN_JOINT && m.actuator_trnid[2 * a] == joint) actuator = a;
    }
    if (actuator < 0) throw lacks("position actuator on arm_joint_" + std::to_string(k));
    c.joints.push_back(joint);
    c.qpos.push_back(m.jnt_qposadr[joint]);
    c.dof.push_back(m.jnt_dofadr[joint]);
    c.actuators.push_back(actuator);
  }
  if (c.joints.size() < 6) throw lacks("six hinge joints arm_joint_1 .. arm_joint_6");
  c.gripper = named(m, mjOBJ_ACTUATOR, "gripper");
  if (c.gripper < 0) throw lacks("actuator named gripper");
  c.tcp = named(m, mjOBJ_SITE, "tcp");
  if (c.tcp < 0) throw lacks("site named tcp (the tool point between the fingertips)");
  auto sensor = [&](const char* name, mjtSensor type, int& address, int& body) {
    const int s = named(m, mjOBJ_SENSOR, name);
    if (s < 0 || m.sensor_type[s] != type)
      throw lacks(std::string(type == mjSENS_TOUCH ? "touch" : "force") + " sensor named " + name);
    address = m.sensor_adr[s];
    body = m.site_bodyid[m.sensor_objid[s]];
  };
  int wrist_body = -1;
  sensor("left_finger_force", mjSENS_TOUCH, c.left_force, c.left_finger);
  sensor("right_finger_force", mjSENS_TOUCH, c.right_force, c.right_finger);
  sensor("wrist_force", mjSENS_FORCE, c.wrist_force, wrist_body);
  for (const SimulatedObject& o : config.objects) {
    Contract::Object object;
    object.id = o.id;
    const std::string name = "object_" + std::to_string(o.id);
    object.body = named(m, mjOBJ_BODY, name);
    object.geom = named(m, mjOBJ_GEOM, name);
    object.qpos = m.jnt_qposadr[named(m, mjOBJ_JOINT, name)];
    object.half_height = o.height / 2;
    c.objects.push_back(object);
  }
  return c;
}

}  // namespace arbci::robot::mujoco
