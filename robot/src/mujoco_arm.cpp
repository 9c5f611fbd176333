#include "arbci/robot/mujoco_arm.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <sstream>

#include "arbci/assets.h"
#include "arbci/robot/workspace_check.h"
#include "mujoco/arm_kinematics.h"
#include "mujoco/scene_model.h"

namespace arbci::robot {
namespace {

constexpr double kAcceleration = 1.0;  // m/s^2 of the tool's path, start and end
constexpr double kArrived = 0.002;     // m: a move ends within this of its goal ...
constexpr double kStill = 0.05;        // rad/s: ... with every joint this slow
constexpr double kSettleLimit = 2.0;   // s: a move or a release waits at most this long after
constexpr double kGraspDepth = 0.025;  // m: fingertips below the top face when grasping
constexpr double kResting = 0.005;     // m/s: a released object slower than this rests
constexpr double kRestingFor = 0.1;    // s
constexpr double kLiftedClear = 0.02;  // m: a held object's base this far above the table
constexpr double kForceBaselineSeconds = 0.2;
constexpr int kCheckIterations = 60;  // a reachable point converges in far fewer from either seed
// A path is checked every this far along it, each point's joints from the last's: a joint that
// would move further than kMaxJointJump between two such points flips the arm's posture, which
// the path cannot follow either.
constexpr double kCheckStep = 0.02;     // m
constexpr double kMaxJointJump = 0.35;  // rad

double distance(const Vec3& a, const Vec3& b) {
  return std::hypot(a.x - b.x, a.y - b.y, a.z - b.z);
}

struct Segment {
  enum class Kind { Move, Descend, Close, Open, Settle, Verify } kind;
  Vec3 to;  // Move: the goal; Descend: the lowest tool point
};

}  // namespace

std::string builtInArm(const std::string& name) {
  try {
    return std::string(assets::embedded("robot/" + name + ".xml"));
  } catch (const std::out_of_range&) {
    throw ConfigError("no built-in arm named " + name + " (arm6, arm7)");
  }
}

struct MujocoArm::Impl {
  RobotConfig config;
  mujoco::ModelPtr model;
  mujoco::DataPtr data;
  mujoco::Contract contract;
  std::unique_ptr<mujoco::ArmKinematics> kinematics;
  std::vector<double> q_des;     // the joints' set points
  std::vector<double> q_before;  // ... at the last step
  std::vector<double> q_home;    // the joints at home, the posture the arm starts in
  Vec3 path;                     // where the tool's path is now
  double speed = 0.0;            // along the path
  double grip = 0.0;             // the gripper's set point (ctrlrange low: open)
  double grip_open = 0.0, grip_closed = 0.0;
  double leftover = 0.0;  // robot time not yet stepped
  long steps = 0;

  RobotState state = RobotState::Idle;
  DriverCommand command;
  std::deque<Segment> plan;
  int plan_size = 0;
  double segment_time = 0.0;
  double force_baseline[3] = {0, 0, 0};  // the wrist's force, slowly followed
  int released = -1;                     // the object let go of, while it settles
  double resting_for = 0.0;
  std::string failure;
  std::string fault;

  Vec3 tool() const {
    const double* p = data->site_xpos + 3 * contract.tcp;
    return {p[0], p[1], p[2]};
  }

  std::vector<double> joints() const {
    std::vector<double> q;
    for (int a : contract.qpos) q.push_back(data->qpos[a]);
    return q;
  }

  // The object whose geom touches both fingers, or -1.
  int held() const {
    for (const auto& o : contract.objects) {
      bool left = false, right = false;
      for (int i = 0; i < data->ncon; ++i) {
        const mjContact& c = data->contact[i];
        int other = -1;
        if (c.geom1 == o.geom) other = c.geom2;
        if (c.geom2 == o.geom) other = c.geom1;
        if (other < 0) continue;
        const int body = model->geom_bodyid[other];
        left = left || body == contract.left_finger;
        right = right || body == contract.right_finger;
      }
      if (left && right) return o.id;
    }
    return -1;
  }

  const mujoco::Contract::Object* object(int id) const {
    for (const auto& o : contract.objects) {
      if (o.id == id) return &o;
    }
    return nullptr;
  }

  // The lowest point of an object (its box's lowest corner).
  double bottom(const mujoco::Contract::Object& o) const {
    const double* half = model->geom_size + 3 * o.geom;
    const double* r = data->geom_xmat + 9 * o.geom;
    const double* p = data->geom_xpos + 3 * o.geom;
    // The box's extent along z: the sum of |R_zk| * half_k.
    return p[2] - (std::abs(r[6]) * half[0] + std::abs(r[7]) * half[1] + std::abs(r[8]) * half[2]);
  }

  double speedOf(int body) const {
    mjtNum v[6];
    mj_objectVelocity(model.get(), data.get(), mjOBJ_BODY, body, v, 0);
    return std::hypot(v[3], v[4], v[5]);
  }

  // How far the wrist's force departs from its recent level. Contact raises it within a few
  // steps; the slow baseline absorbs the path's own start and the arm's settling.
  double wristForceChange(double dt) {
    const double* f = data->sensordata + contract.wrist_force;
    const double change =
        std::hypot(f[0] - force_baseline[0], f[1] - force_baseline[1], f[2] - force_baseline[2]);
    const double follow = std::min(1.0, dt / kForceBaselineSeconds);
    for (int i = 0; i < 3; ++i) force_baseline[i] += follow * (f[i] - force_baseline[i]);
    return change;
  }

  void physicsStep() {
    mj_step1(model.get(), data.get());
    // Gravity and Coriolis compensation of the arm's own links, as an arm's controller does, and
    // the set point's velocity fed forward through the joint's damping: the damping then brakes
    // only the departure from the path (a servo's velocity term), and the path is not lagged.
    for (size_t k = 0; k < contract.dof.size(); ++k) {
      const int dof = contract.dof[k];
      const double velocity = (q_des[k] - q_before[k]) / model->opt.timestep;
      data->qfrc_applied[dof] = data->qfrc_bias[dof] + model->dof_damping[dof] * velocity;
    }
    q_before = q_des;
    for (size_t k = 0; k < contract.actuators.size(); ++k)
      data->ctrl[contract.actuators[k]] = q_des[k];
    data->ctrl[contract.gripper] = grip;
    mj_step2(model.get(), data.get());
    ++steps;
  }

  // Holds the arm where it is now: the set point becomes the tool-down posture nearest the
  // joints' actual angles (they sag and yield a little under load), so paths start from it.
  void holdHere() {
    path = tool();
    const auto q = kinematics->solve(path, joints());
    q_des = q ? *q : joints();
    speed = 0.0;
  }

  // Moves the path towards `goal` for one step at up to `top` speed, within the joint speed
  // limit; false when no joint solution reaches the next point.
  bool advancePath(const Vec3& goal, double top, double dt) {
    const double remaining = distance(path, goal);
    if (remaining < 1e-9) return true;
    speed = std::min({top, speed + kAcceleration * dt, std::sqrt(2 * kAcceleration * remaining)});
    double advance = std::min(remaining, std::max(speed, 1e-4) * dt);
    for (int attempt = 0; attempt < 6; ++attempt, advance *= 0.5) {
      const double f = advance / remaining;
      const Vec3 next{path.x + (goal.x - path.x) * f, path.y + (goal.y - path.y) * f,
                      path.z + (goal.z - path.z) * f};
      const auto q = kinematics->solve(next, q_des, 20);
      if (!q) continue;
      double fastest = 0.0;
      for (size_t k = 0; k < q->size(); ++k)
        fastest = std::max(fastest, std::abs((*q)[k] - q_des[k]) / dt);
      if (fastest > config.max_joint_speed * 1.0001) {
        speed *= 0.5;
        continue;
      }
      q_des = *q;
      path = next;
      return true;
    }
    return false;
  }

  bool settled() const {
    for (int dof : contract.dof) {
      if (std::abs(data->qvel[dof]) > kStill) return false;
    }
    return true;
  }

  void planFor(const DriverCommand& c) {
    plan.clear();
    failure.clear();
    fault.clear();
    holdHere();
    const Vec3 t = tool();
    const double travel_z = std::max(t.z, config.table_z + config.lift_height);
    switch (c.type) {
      case MessageType::Grasp: {
        // To the travel height where the tool is (down from home), across, then down: crossing at
        // home's height would stretch an arm of this reach at the far cells.
        const Vec3 above{c.target.x, c.target.y, c.target.z + config.approach_height};
        const double high = std::max(config.table_z + config.lift_height, above.z);
        plan.push_back({Segment::Kind::Open, {}});
        plan.push_back({Segment::Kind::Move, {t.x, t.y, high}});
        plan.push_back({Segment::Kind::Move, {above.x, above.y, high}});
        plan.push_back({Segment::Kind::Move, above});
        plan.push_back(
            {Segment::Kind::Descend,
             {c.target.x, c.target.y, std::max(c.target.z - kGraspDepth, config.table_z)}});
        plan.push_back({Segment::Kind::Close, {}});
        plan.push_back(
            {Segment::Kind::Move, {c.target.x, c.target.y, config.table_z + config.lift_height}});
        plan.push_back({Segment::Kind::Verify, {}});
        break;
      }
      case MessageType::Drop: {
        plan.push_back({Segment::Kind::Move, {t.x, t.y, travel_z}});
        plan.push_back({Segment::Kind::Move, {c.target.x, c.target.y, travel_z}});
        plan.push_back({Segment::Kind::Descend, c.target});  // to.z: the object's base
        plan.push_back({Segment::Kind::Open, {}});
        plan.push_back({Segment::Kind::Settle, {}});
        plan.push_back({Segment::Kind::Move, {c.target.x, c.target.y, travel_z}});
        break;
      }
      default:  // Home
        // Across at the height it is at, then to home: rising first would stretch an arm of
        // this reach at the far cells.
        plan.push_back({Segment::Kind::Move, {t.x, t.y, travel_z}});
        plan.push_back({Segment::Kind::Move, {config.home.x, config.home.y, travel_z}});
        plan.push_back({Segment::Kind::Move, config.home});
        break;
    }
    plan_size = static_cast<int>(plan.size());
    segment_time = 0.0;
  }

  void beginSegment(Segment& s) {
    segment_time = 0.0;
    speed = 0.0;
    if (s.kind == Segment::Kind::Descend) {
      std::copy_n(data->sensordata + contract.wrist_force, 3, force_baseline);
      if (command.type == MessageType::Drop) {
        // The goal is the held object's base at to.z: the tool stops that far above it.
        const int id = held();
        const auto* o = object(id);
        const double tool_above_base = o ? tool().z - bottom(*o) : 0.0;
        s.to.z = s.to.z + tool_above_base;
      }
    }
    if (s.kind == Segment::Kind::Open) released = held();
    if (s.kind == Segment::Kind::Settle) resting_for = 0.0;
  }

  // One physics step of the current segment; true when it has ended.
  bool advance(Segment& s, double dt) {
    if (segment_time == 0.0) beginSegment(s);
    segment_time += dt;
    switch (s.kind) {
      case Segment::Kind::Move: {
        if (!advancePath(s.to, config.cartesian_speed, dt)) {
          fault = "no joint motion reaches " + pointText(path) + " (joint limit or singularity)";
          return true;
        }
        physicsStep();
        if (distance(path, s.to) > 1e-9) {
          path_done_at = -1.0;
          return false;
        }
        if (path_done_at < 0) path_done_at = segment_time;
        const bool arrived = distance(tool(), s.to) < kArrived && settled();
        if (arrived || segment_time - path_done_at > kSettleLimit) {
          path_done_at = -1.0;
          return true;
        }
        return false;
      }
      case Segment::Kind::Descend: {
        const double change = wristForceChange(dt);
        if (change > config.contact_force || path.z <= s.to.z + 1e-9) {
          holdHere();
          return true;
        }
        if (!advancePath({s.to.x, s.to.y, s.to.z}, config.descend_speed, dt)) {
          fault = "no joint motion reaches " + pointText(path) + " (joint limit or singularity)";
          return true;
        }
        physicsStep();
        return false;
      }
      case Segment::Kind::Close: {
        const double* sensors = data->sensordata;
        const bool gripping = sensors[contract.left_force] >= config.grip_force &&
                              sensors[contract.right_force] >= config.grip_force;
        if (gripping || grip >= grip_closed) {
          if (!gripping && held() < 0) {
            failure = "the gripper closed on nothing at " + pointText(tool());
          }
          return true;
        }
        grip =
            std::min(grip_closed, grip + (grip_closed - grip_open) * dt / config.gripper_seconds);
        physicsStep();
        return false;
      }
      case Segment::Kind::Open: {
        if (grip <= grip_open) return true;
        grip = std::max(grip_open, grip - (grip_closed - grip_open) * dt / config.gripper_seconds);
        physicsStep();
        return false;
      }
      case Segment::Kind::Settle: {
        physicsStep();
        const auto* o = object(released);
        if (!o) return true;
        resting_for = speedOf(o->body) < kResting ? resting_for + dt : 0.0;
        return resting_for >= kRestingFor || segment_time >= kSettleLimit;
      }
      case Segment::Kind::Verify: {
        // Held is what physics holds: between both fingers and clear of the table.
        const auto* o = object(held());
        if (failure.empty() && (!o || bottom(*o) < config.table_z + kLiftedClear)) {
          failure = grasped >= 0
                        ? "object " + std::to_string(grasped) +
                              " slipped out of the gripper during the lift"
                        : "nothing between the fingers after the lift at " + pointText(tool());
        }
        return true;
      }
    }
    return true;
  }

  double path_done_at = -1.0;
  int grasped = -1;  // what the fingers closed on

  // The corners of the tool's path for a command from `from` (the plan's moves, as planFor
  // makes them), and the way home after it.
  std::vector<Vec3> pathOf(MessageType type, const Vec3& from, const Vec3& target,
                           double tool_above_base) const {
    const double travel_z = std::max(from.z, config.table_z + config.lift_height);
    std::vector<Vec3> path{from, {from.x, from.y, travel_z}};
    Vec3 end = path.back();
    if (type == MessageType::Grasp) {
      const Vec3 above{target.x, target.y, target.z + config.approach_height};
      const double high = std::max(config.table_z + config.lift_height, above.z);
      path = {from,
              {from.x, from.y, high},
              {above.x, above.y, high},
              above,
              {target.x, target.y, std::max(target.z - kGraspDepth, config.table_z)},
              {target.x, target.y, config.table_z + config.lift_height}};
      end = path.back();
    } else if (type == MessageType::Drop) {
      path.push_back({target.x, target.y, travel_z});
      path.push_back({target.x, target.y, target.z + tool_above_base});
      path.push_back({target.x, target.y, travel_z});
      end = path.back();
    }
    // Home: across at the height it is at (at least the travel height), then down to home.
    const double home_z = std::max(end.z, config.table_z + config.lift_height);
    path.push_back({end.x, end.y, home_z});
    path.push_back({config.home.x, config.home.y, home_z});
    path.push_back(config.home);
    return path;
  }

  // The path followed as advancePath follows it: every kCheckStep along each straight stretch,
  // each point's joints found from the last point's. The first point no joint motion reaches
  // (a joint limit, a singularity, or a flip of the posture), or nothing.
  std::optional<Vec3> unreachableOn(const std::vector<Vec3>& corners) const {
    std::optional<std::vector<double>> q =
        kinematics->solve(corners.front(), q_des, kCheckIterations);
    if (!q) q = kinematics->solve(corners.front(), q_home, kCheckIterations);
    if (!q) return corners.front();
    for (size_t k = 1; k < corners.size(); ++k) {
      const Vec3& a = corners[k - 1];
      const Vec3& b = corners[k];
      const int steps = std::max(1, static_cast<int>(std::ceil(distance(a, b) / kCheckStep)));
      for (int i = 1; i <= steps; ++i) {
        const double f = static_cast<double>(i) / steps;
        const Vec3 p{a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f, a.z + (b.z - a.z) * f};
        const auto next = kinematics->solve(p, *q, kCheckIterations);
        if (!next) return p;
        for (size_t j = 0; j < next->size(); ++j)
          if (std::abs((*next)[j] - (*q)[j]) > kMaxJointJump) return p;
        q = next;
      }
    }
    return std::nullopt;
  }
};

MujocoArm::MujocoArm(const RobotConfig& config) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.config = config;
  std::string arm_xml, what;
  std::filesystem::path folder;
  if (config.model.empty() || config.model == "arm6" || config.model == "arm7") {
    const std::string name = config.model.empty() ? "arm6" : config.model;
    arm_xml = builtInArm(name);
    what = "the built-in arm " + name;
  } else {
    std::ifstream in(config.model);
    if (!in) throw ConfigError(config.model + ": cannot read the arm's model");
    std::stringstream text;
    text << in.rdbuf();
    arm_xml = text.str();
    what = config.model;
    folder = std::filesystem::absolute(config.model).parent_path();
  }
  m.model = mujoco::compile(mujoco::composeScene(arm_xml, folder, config, what), what);
  m.data.reset(mj_makeData(m.model.get()));
  m.contract = mujoco::findContract(*m.model, config, what);
  m.kinematics = std::make_unique<mujoco::ArmKinematics>(*m.model, m.contract);
  const mjModel& model = *m.model;
  m.grip_open = model.actuator_ctrlrange[2 * m.contract.gripper];
  m.grip_closed = model.actuator_ctrlrange[2 * m.contract.gripper + 1];
  m.grip = m.grip_open;
  const auto home = m.kinematics->solveAnywhere(config.home);
  if (!home)
    throw ConfigError(what + ": the home position " + pointText(config.home) +
                      " is not reachable pointing down");
  for (size_t k = 0; k < home->size(); ++k) m.data->qpos[m.contract.qpos[k]] = (*home)[k];
  m.q_des = *home;
  m.q_home = *home;
  m.q_before = *home;
  mj_forward(m.model.get(), m.data.get());
  m.path = m.tool();
  // Let the objects settle on the table before the first command.
  for (int i = 0; i < 250; ++i) m.physicsStep();
  m.steps = 0;
}

MujocoArm::~MujocoArm() = default;

double MujocoArm::timestep() const {
  return impl_->model->opt.timestep;
}

long MujocoArm::steps() const {
  return impl_->steps;
}

int MujocoArm::armJoints() const {
  return static_cast<int>(impl_->contract.joints.size());
}

std::optional<Rejection> MujocoArm::check(const DriverCommand& c) const {
  const Impl& m = *impl_;
  const RobotConfig& cfg = m.config;
  const int holding = m.held();
  if (c.type == MessageType::Grasp || c.type == MessageType::Drop) {
    if (auto outside = outsideWorkspace(cfg, c.target)) return outside;
    if (c.type == MessageType::Grasp && holding >= 0)
      return Rejection{RejectReason::InvalidState,
                       "already holding object " + std::to_string(holding)};
    if (c.type == MessageType::Drop && holding < 0)
      return Rejection{RejectReason::InvalidState, "holding nothing to drop"};
  }
  // The whole path, not its ends: the travel height, the approach, the descent, the lift and the
  // way home, as the plan will follow them from where the arm is.
  const auto* held = holding >= 0 ? m.object(holding) : nullptr;
  const double tool_above_base = held ? m.tool().z - m.bottom(*held) : 0.0;
  if (const auto point = m.unreachableOn(m.pathOf(c.type, m.path, c.target, tool_above_base)))
    return Rejection{RejectReason::Unreachable,
                     std::string(toString(c.type)) + " " + pointText(c.target) +
                         ": its path passes " + pointText(*point) +
                         ", which no joint motion of the arm reaches (joint limit or singularity)"};
  if (c.type == MessageType::Drop && held) {
    // Put down, the object must be graspable there again (the next trial may choose it): from
    // home, its top where the drop leaves it.
    // The tool holds it kGraspDepth below its top face: its top lies that far above the tool.
    const double height = tool_above_base + kGraspDepth;
    const Vec3 top{c.target.x, c.target.y, c.target.z + std::max(height, 0.0)};
    if (const auto point = m.unreachableOn(m.pathOf(MessageType::Grasp, cfg.home, top, 0.0)))
      return Rejection{RejectReason::Unreachable,
                       "DROP " + pointText(c.target) +
                           ": the arm could put the object there but not grasp it again (the path "
                           "passes " +
                           pointText(*point) + ", which no joint motion reaches)"};
  }
  return std::nullopt;
}

void MujocoArm::start(const DriverCommand& c) {
  Impl& m = *impl_;
  m.command = c;
  m.grasped = -1;
  m.planFor(c);
  m.state = RobotState::Moving;
}

void MujocoArm::stop() {
  Impl& m = *impl_;
  m.plan.clear();
  m.holdHere();
  m.state = RobotState::Stopped;
}

std::optional<DriverResult> MujocoArm::step(double seconds) {
  Impl& m = *impl_;
  if (m.state != RobotState::Moving) return std::nullopt;
  const double dt = m.model->opt.timestep;
  m.leftover += seconds;
  while (m.leftover >= dt - 1e-12 && !m.plan.empty()) {
    m.leftover -= dt;
    Segment& s = m.plan.front();
    const bool close = s.kind == Segment::Kind::Close;
    if (m.advance(s, dt)) {
      if (close) m.grasped = m.held();
      if (close && !m.failure.empty()) {
        // Lift back out empty-handed: only the lift remains (then the verdict).
        while (m.plan.size() > 1 && m.plan[1].kind != Segment::Kind::Move)
          m.plan.erase(m.plan.begin() + 1);
      }
      m.plan.pop_front();
      m.segment_time = 0.0;
    }
    if (!m.fault.empty()) {
      m.plan.clear();
      m.holdHere();
      m.state = RobotState::Fault;
      return DriverResult{Outcome::Failed, m.fault};
    }
  }
  if (!m.plan.empty()) return std::nullopt;
  m.leftover = 0.0;
  m.state = RobotState::Idle;
  if (!m.failure.empty()) return DriverResult{Outcome::Failed, m.failure};
  switch (m.command.type) {
    case MessageType::Grasp:
      return DriverResult{Outcome::Success, "holding object " + std::to_string(m.held())};
    case MessageType::Drop:
      return DriverResult{Outcome::Success, "released at " + pointText(m.tool())};
    default:
      return DriverResult{Outcome::Success, "at home " + pointText(m.tool())};
  }
}

DriverStatus MujocoArm::status() const {
  const Impl& m = *impl_;
  DriverStatus s;
  s.state = m.state;
  s.tool = m.tool();
  const double span = m.grip_closed - m.grip_open;
  const double finger =
      m.data->qpos[m.model->jnt_qposadr[m.model->actuator_trnid[2 * m.contract.gripper]]];
  s.gripper_opening = std::clamp(1.0 - (finger - m.grip_open) / span, 0.0, 1.0);
  s.holding = m.held();
  s.progress = m.state == RobotState::Moving && m.plan_size > 0
                   ? 1.0 - static_cast<double>(m.plan.size()) / m.plan_size
                   : 0.0;
  return s;
}

std::vector<WorldObject> MujocoArm::world() const {
  const Impl& m = *impl_;
  const int holding = m.held();
  std::vector<WorldObject> out;
  for (const auto& o : m.contract.objects) {
    const double* p = m.data->xpos + 3 * o.body;
    const double* r = m.data->xmat + 9 * o.body;
    const double* q = m.data->xquat + 4 * o.body;
    WorldObject w;
    w.id = o.id;
    // The centre of its top face: half its height along its own z.
    w.position = {p[0] + r[2] * o.half_height, p[1] + r[5] * o.half_height,
                  p[2] + r[8] * o.half_height};
    w.held = o.id == holding;
    w.orientation = {q[0], q[1], q[2], q[3]};
    out.push_back(w);
  }
  return out;
}

}  // namespace arbci::robot
