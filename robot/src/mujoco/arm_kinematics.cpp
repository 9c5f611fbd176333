#include "mujoco/arm_kinematics.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace arbci::robot::mujoco {
namespace {

constexpr double kPositionTolerance = 1e-7;  // m: set points differ by this, not by noise
constexpr double kAngleTolerance = 1e-6;     // rad
constexpr double kDamping = 0.02;            // keeps steps bounded near singular postures
constexpr double kMaxStep = 0.3;             // rad per iteration

}  // namespace

ArmKinematics::ArmKinematics(const mjModel& model, const Contract& contract)
    : model_(model), contract_(contract), data_(mj_makeData(&model)) {}

void ArmKinematics::place(const std::vector<double>& q) const {
  for (size_t k = 0; k < q.size(); ++k) data_->qpos[contract_.qpos[k]] = q[k];
  mj_kinematics(&model_, data_.get());
  mj_comPos(&model_, data_.get());
}

Vec3 ArmKinematics::tool(const std::vector<double>& q) const {
  place(q);
  const double* p = data_->site_xpos + 3 * contract_.tcp;
  return {p[0], p[1], p[2]};
}

std::optional<std::vector<double>> ArmKinematics::solve(const Vec3& target,
                                                        const std::vector<double>& seed,
                                                        int iterations) const {
  const int n = static_cast<int>(contract_.joints.size());
  std::vector<double> q = seed;
  std::vector<double> jacp(3 * model_.nv), jacr(3 * model_.nv);
  // Tool down: x along the robot's x, z along -z.
  const Eigen::Vector3d want[3] = {{1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  for (int it = 0; it <= iterations; ++it) {
    place(q);
    const double* p = data_->site_xpos + 3 * contract_.tcp;
    const double* r = data_->site_xmat + 9 * contract_.tcp;
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = Eigen::Vector3d(target.x - p[0], target.y - p[1], target.z - p[2]);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    for (int a = 0; a < 3; ++a) w += Eigen::Vector3d(r[a], r[3 + a], r[6 + a]).cross(want[a]);
    e.tail<3>() = 0.5 * w;
    if (e.head<3>().norm() < kPositionTolerance && e.tail<3>().norm() < kAngleTolerance) return q;
    if (it == iterations) break;
    mj_jacSite(&model_, data_.get(), jacp.data(), jacr.data(), contract_.tcp);
    Eigen::MatrixXd J(6, n);
    for (int k = 0; k < n; ++k) {
      const int dof = contract_.dof[k];
      for (int row = 0; row < 3; ++row) {
        J(row, k) = jacp[row * model_.nv + dof];
        J(3 + row, k) = jacr[row * model_.nv + dof];
      }
    }
    const Eigen::Matrix<double, 6, 6> A =
        J * J.transpose() + kDamping * kDamping * Eigen::Matrix<double, 6, 6>::Identity();
    Eigen::VectorXd dq = J.transpose() * A.ldlt().solve(e);
    const double largest = dq.cwiseAbs().maxCoeff();
    if (largest > kMaxStep) dq *= kMaxStep / largest;
    for (int k = 0; k < n; ++k) {
      q[k] += dq[k];
      const int j = contract_.joints[k];
      if (model_.jnt_limited[j])
        q[k] = std::clamp(q[k], model_.jnt_range[2 * j], model_.jnt_range[2 * j + 1]);
    }
  }
  return std::nullopt;
}

std::optional<std::vector<double>> ArmKinematics::solveAnywhere(const Vec3& p) const {
  const int n = static_cast<int>(contract_.joints.size());
  std::optional<std::vector<double>> best;
  double best_height = -1e9;
  // A fixed lattice of starts (reproducible): each joint at -pi/2, 0 or pi/2 for the first
  // three, the rest at 0 or -pi/2.
  const double pi = std::numbers::pi;
  const double first[3] = {-pi / 2, 0.0, pi / 2};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c)
        for (int rest = 0; rest < 2; ++rest) {
          std::vector<double> seed(static_cast<size_t>(n), rest ? -pi / 2 : 0.0);
          seed[0] = first[a];
          seed[1] = first[b] / 2;
          seed[2] = first[c];
          const auto q = solve(p, seed, 300);
          if (!q) continue;
          place(*q);
          double height = 0.0;
          for (int body = 1; body < model_.nbody; ++body) {
            if (model_.body_dofnum[body] == 0 ||
                model_.jnt_type[model_.body_jntadr[body]] == mjJNT_FREE)
              continue;
            height += data_->xpos[3 * body + 2];
          }
          if (height > best_height + 1e-9) {
            best_height = height;
            best = q;
          }
        }
  return best;
}

}  // namespace arbci::robot::mujoco
