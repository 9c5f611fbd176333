#include "arbci/robot/simulated_arm.h"
#include "arbci/robot/workspace_check.h"

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <numbers>
#include <stdexcept>

namespace arbci::robot {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kStep = 0.005;          // seconds of robot time per integration step
constexpr double kGripperLength = 0.15;  // flange to fingertips

// UR10 (standard DH) with the gripper's length added to the last link.
KDL::Chain ur10() {
  KDL::Chain chain;
  const double a[6] = {0.0, -0.612, -0.5723, 0.0, 0.0, 0.0};
  const double alpha[6] = {kPi / 2, 0.0, 0.0, kPi / 2, -kPi / 2, 0.0};
  const double d[6] = {0.1273, 0.0, 0.0, 0.163941, 0.1157, 0.0922 + kGripperLength};
  for (int i = 0; i < 6; ++i)
    chain.addSegment(
        KDL::Segment(KDL::Joint(KDL::Joint::RotZ), KDL::Frame::DH(a[i], alpha[i], d[i], 0.0)));
  return chain;
}

const double kLowerLimit[6] = {-2 * kPi, -2 * kPi, -kPi, -2 * kPi, -2 * kPi, -2 * kPi};
const double kUpperLimit[6] = {2 * kPi, 2 * kPi, kPi, 2 * kPi, 2 * kPi, 2 * kPi};

// The tool pointing straight down, its x axis along the robot's x.
KDL::Frame toolDown(const Vec3& p) {
  return KDL::Frame(KDL::Rotation::RotX(kPi), KDL::Vector(p.x, p.y, p.z));
}

double distance(const Vec3& a, const Vec3& b) {
  return std::hypot(a.x - b.x, a.y - b.y, a.z - b.z);
}

// One part of a command: a straight move, a descent until contact, or the gripper.
struct Segment {
  enum class Kind { Move, Descend, Close, Open } kind;
  Vec3 to;  // Move: the goal; Descend: the lowest point allowed
};

}  // namespace

struct SimulatedArm::Impl {
  RobotConfig config;
  KDL::Chain chain = ur10();
  mutable KDL::ChainFkSolverPos_recursive fk{chain};
  mutable KDL::ChainIkSolverPos_LMA ik{chain, 1e-6, 500, 1e-10};
  KDL::JntArray q{6};
  std::vector<SimulatedObject> objects;
  int holding = -1;
  Vec3 grasp_offset;  // the held object's top centre relative to the fingertips (it does not centre
                      // itself)
  double gripper = 1.0;
  RobotState state = RobotState::Idle;
  DriverCommand command;
  std::deque<Segment> plan;
  int plan_size = 0;
  double gripper_time = 0.0;
  std::string failure;  // why the command failed, once it has

  Vec3 tool() const {
    KDL::Frame frame;
    fk.JntToCart(q, frame);
    return {frame.p.x(), frame.p.y(), frame.p.z()};
  }

  // Joint angles that put the tool at `p` pointing down, starting the search from `seed`.
  bool solve(const Vec3& p, const KDL::JntArray& seed, KDL::JntArray& out) const {
    const KDL::Frame goal = toolDown(p);
    if (ik.CartToJnt(seed, goal, out) < 0) return false;
    KDL::Frame reached;
    fk.JntToCart(out, reached);
    if ((reached.p - goal.p).Norm() > 1e-4) return false;
    for (unsigned i = 0; i < 6; ++i) {
      // Bring each angle into its limits by whole turns when possible.
      while (out(i) > kUpperLimit[i]) out(i) -= 2 * kPi;
      while (out(i) < kLowerLimit[i]) out(i) += 2 * kPi;
      if (out(i) > kUpperLimit[i]) return false;
    }
    return true;
  }

  // The surface under (x, y): the top of the highest object whose footprint covers it, else the
  // table. The held object does not count.
  double surfaceBelow(double x, double y) const {
    double top = config.table_z;
    for (const SimulatedObject& o : objects) {
      if (o.id == holding) continue;
      if (std::hypot(o.position.x - x, o.position.y - y) <= o.radius)
        top = std::max(top, o.position.z);
    }
    return top;
  }

  SimulatedObject* held() {
    for (SimulatedObject& o : objects) {
      if (o.id == holding) return &o;
    }
    return nullptr;
  }

  void carry() {
    if (SimulatedObject* o = held()) {
      const Vec3 t = tool();
      o->position = {t.x + grasp_offset.x, t.y + grasp_offset.y, t.z + grasp_offset.z};
    }
  }

  // Moves the tool towards `goal` for up to `dt`, at the Cartesian speed and within the joint
  // speed limit. Returns true on arrival; false with `blocked` set when no joint solution exists.
  bool moveToward(const Vec3& goal, double speed, double dt, bool& blocked) {
    const Vec3 here = tool();
    const double remaining = distance(here, goal);
    if (remaining < 1e-6) return true;
    double fraction = std::min(1.0, speed * dt / remaining);
    for (int attempt = 0; attempt < 6; ++attempt, fraction *= 0.5) {
      const Vec3 next{here.x + (goal.x - here.x) * fraction, here.y + (goal.y - here.y) * fraction,
                      here.z + (goal.z - here.z) * fraction};
      KDL::JntArray solution(6);
      if (!solve(next, q, solution)) continue;
      double fastest = 0.0;
      for (unsigned i = 0; i < 6; ++i)
        fastest = std::max(fastest, std::abs(solution(i) - q(i)) / dt);
      if (fastest > config.max_joint_speed * 1.0001)
        continue;  // too fast for a joint: smaller step
      q = solution;
      carry();
      return fraction >= 1.0;
    }
    blocked = true;
    return false;
  }

  void planFor(const DriverCommand& c) {
    plan.clear();
    failure.clear();
    const Vec3 t = tool();
    const double travel_z = std::max(t.z, config.table_z + config.lift_height);
    switch (c.type) {
      case MessageType::Grasp: {
        const Vec3 above{c.target.x, c.target.y, c.target.z + config.approach_height};
        plan.push_back({Segment::Kind::Move, {t.x, t.y, std::max(travel_z, above.z)}});
        plan.push_back({Segment::Kind::Move, {above.x, above.y, std::max(travel_z, above.z)}});
        plan.push_back({Segment::Kind::Move, above});
        plan.push_back({Segment::Kind::Descend, {c.target.x, c.target.y, config.table_z}});
        plan.push_back({Segment::Kind::Close, {}});
        plan.push_back(
            {Segment::Kind::Move, {c.target.x, c.target.y, config.table_z + config.lift_height}});
        break;
      }
      case MessageType::Drop: {
        plan.push_back({Segment::Kind::Move, {t.x, t.y, travel_z}});
        plan.push_back({Segment::Kind::Move, {c.target.x, c.target.y, travel_z}});
        plan.push_back({Segment::Kind::Descend, {c.target.x, c.target.y, config.table_z}});
        plan.push_back({Segment::Kind::Open, {}});
        plan.push_back({Segment::Kind::Move, {c.target.x, c.target.y, travel_z}});
        break;
      }
      default:  // Home
        plan.push_back({Segment::Kind::Move, {t.x, t.y, std::max(t.z, config.home.z)}});
        plan.push_back({Segment::Kind::Move, config.home});
        break;
    }
    plan_size = static_cast<int>(plan.size());
  }

  // Advances the current segment by dt; true when it is done.
  bool advance(Segment& s, double dt, bool& blocked) {
    switch (s.kind) {
      case Segment::Kind::Move:
        return moveToward(s.to, config.cartesian_speed, dt, blocked);
      case Segment::Kind::Descend: {
        // Contact: fingertips on the surface, or the held object's base on it.
        const Vec3 t = tool();
        const SimulatedObject* o = held();
        const double base = o ? t.z + grasp_offset.z - o->height : t.z;
        const double contact = surfaceBelow(t.x, t.y);
        if (base <= contact + 1e-6) return true;
        const double drop = std::min(config.descend_speed * dt, base - contact);
        moveToward({t.x, t.y, t.z - drop}, config.descend_speed * 1.0001, dt, blocked);
        return false;
      }
      case Segment::Kind::Close:
      case Segment::Kind::Open: {
        gripper_time += dt;
        const double f = std::min(1.0, gripper_time / config.gripper_seconds);
        gripper = s.kind == Segment::Kind::Close ? 1.0 - f : f;
        if (f < 1.0) return false;
        gripper_time = 0.0;
        const Vec3 t = tool();
        if (s.kind == Segment::Kind::Close) {
          // Grasp what lies under the fingertips: its top within 5 mm, its axis within its radius.
          for (const SimulatedObject& o : objects) {
            if (std::hypot(o.position.x - t.x, o.position.y - t.y) <= o.radius &&
                std::abs(o.position.z - t.z) < 0.005) {
              holding = o.id;
              grasp_offset = {o.position.x - t.x, o.position.y - t.y, o.position.z - t.z};
            }
          }
          if (holding < 0) {
            char where[96];
            std::snprintf(where, sizeof where, "nothing to grasp at (%.3f, %.3f, %.3f)", t.x, t.y,
                          t.z);
            failure = where;
            // Lift back out empty-handed: only the last segment (the lift) remains.
            while (plan.size() > 2) plan.erase(plan.begin() + 1);
          }
        } else if (SimulatedObject* o = held()) {
          o->position.z = surfaceBelow(o->position.x, o->position.y) + o->height;
          holding = -1;
        }
        return true;
      }
    }
    return true;
  }
};

SimulatedArm::SimulatedArm(const RobotConfig& config) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.config = config;
  m.objects = config.objects;
  // Start at home: solve from a typical elbow-up, tool-down posture.
  KDL::JntArray seed(6);
  const double posture[6] = {kPi / 2, -kPi / 2, kPi / 2, -kPi / 2, -kPi / 2, 0.0};
  for (unsigned i = 0; i < 6; ++i) seed(i) = posture[i];
  if (!m.solve(config.home, seed, m.q))
    throw ConfigError("the home position is not reachable by the simulated arm");
}

SimulatedArm::~SimulatedArm() = default;

bool SimulatedArm::reachable(const Vec3& position) const {
  KDL::JntArray solution(6);
  return impl_->solve(position, impl_->q, solution);
}

std::vector<double> SimulatedArm::joints() const {
  return {impl_->q.data.data(), impl_->q.data.data() + 6};
}

std::optional<Rejection> SimulatedArm::check(const DriverCommand& c) const {
  const Impl& m = *impl_;
  const RobotConfig& cfg = m.config;
  if (c.type == MessageType::Grasp || c.type == MessageType::Drop) {
    const Vec3& p = c.target;
    if (auto outside = outsideWorkspace(cfg, p)) return outside;
    if (!reachable(p) || !reachable(approachPoint(cfg, p)))
      return Rejection{RejectReason::Unreachable, pointText(p) + " is out of the arm's reach"};
    if (c.type == MessageType::Grasp && m.holding >= 0) {
      return Rejection{RejectReason::InvalidState,
                       "already holding object " + std::to_string(m.holding)};
    }
    if (c.type == MessageType::Drop && m.holding < 0)
      return Rejection{RejectReason::InvalidState, "holding nothing to drop"};
  }
  return std::nullopt;
}

void SimulatedArm::start(const DriverCommand& c) {
  Impl& m = *impl_;
  m.command = c;
  m.planFor(c);
  m.gripper_time = 0.0;
  m.state = RobotState::Moving;
}

void SimulatedArm::stop() {
  Impl& m = *impl_;
  m.plan.clear();
  m.state = RobotState::Stopped;
}

std::optional<DriverResult> SimulatedArm::step(double seconds) {
  Impl& m = *impl_;
  if (m.state != RobotState::Moving) return std::nullopt;
  for (double done = 0.0; done < seconds - 1e-12;) {
    const double dt = std::min(kStep, seconds - done);
    done += dt;
    if (m.plan.empty()) break;
    bool blocked = false;
    if (m.advance(m.plan.front(), dt, blocked)) m.plan.pop_front();
    if (blocked) {
      m.plan.clear();
      m.state = RobotState::Fault;
      return DriverResult{Outcome::Failed,
                          "no joint motion reaches the next point (joint limit or singularity)"};
    }
  }
  if (!m.plan.empty()) return std::nullopt;
  m.state = RobotState::Idle;
  const Vec3 t = m.tool();
  char where[96];
  std::snprintf(where, sizeof where, "(%.3f, %.3f, %.3f)", t.x, t.y, t.z);
  if (!m.failure.empty()) return DriverResult{Outcome::Failed, m.failure};
  switch (m.command.type) {
    case MessageType::Grasp:
      return DriverResult{Outcome::Success, "holding object " + std::to_string(m.holding)};
    case MessageType::Drop:
      return DriverResult{Outcome::Success, std::string("released at ") + where};
    default:
      return DriverResult{Outcome::Success, std::string("at home ") + where};
  }
}

DriverStatus SimulatedArm::status() const {
  const Impl& m = *impl_;
  DriverStatus s;
  s.state = m.state;
  s.tool = m.tool();
  s.gripper_opening = m.gripper;
  s.holding = m.holding;
  s.progress = m.state == RobotState::Moving && m.plan_size > 0
                   ? 1.0 - static_cast<double>(m.plan.size()) / m.plan_size
                   : 0.0;
  return s;
}

std::vector<WorldObject> SimulatedArm::world() const {
  std::vector<WorldObject> out;
  for (const SimulatedObject& o : impl_->objects)
    out.push_back({o.id, o.position, o.id == impl_->holding});
  return out;
}

}  // namespace arbci::robot
