#include "rpp.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>

#include <opencv2/core.hpp>

namespace arbci::vision {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// The object-space geometry of orthogonal iteration: line-of-sight projections F_i and the
// closed-form optimal translation for a rotation.
class ObjectSpace {
 public:
  ObjectSpace(std::span<const cv::Point3d> object, std::span<const cv::Point2d> rays) {
    const size_t n = object.size();
    Matrix3d sum_f = Matrix3d::Zero();
    for (size_t i = 0; i < n; ++i) {
      points_.emplace_back(object[i].x, object[i].y, object[i].z);
      const Vector3d v(rays[i].x, rays[i].y, 1.0);
      projections_.push_back(v * v.transpose() / v.squaredNorm());
      sum_f += projections_.back();
    }
    const double count = static_cast<double>(n);
    // t*(R) = translation_factor_ * sum_i (F_i - I) R p_i
    translation_factor_ = (Matrix3d::Identity() - sum_f / count).inverse() / count;
  }

  Vector3d optimalTranslation(const Matrix3d& r) const {
    Vector3d sum = Vector3d::Zero();
    for (size_t i = 0; i < points_.size(); ++i) {
      sum += (projections_[i] - Matrix3d::Identity()) * (r * points_[i]);
    }
    return translation_factor_ * sum;
  }

  // Residuals (I - F_i)(R p_i + t*(R)); linear in R.
  std::vector<Vector3d> residuals(const Matrix3d& r) const {
    const Vector3d t = optimalTranslation(r);
    std::vector<Vector3d> out;
    for (size_t i = 0; i < points_.size(); ++i) {
      out.push_back((Matrix3d::Identity() - projections_[i]) * (r * points_[i] + t));
    }
    return out;
  }

  double error(const Matrix3d& r, const Vector3d& t) const {
    double e = 0.0;
    for (size_t i = 0; i < points_.size(); ++i) {
      e += ((Matrix3d::Identity() - projections_[i]) * (r * points_[i] + t)).squaredNorm();
    }
    return e;
  }

  // Lu-Hager-Mjolsness: project the posed points onto their lines of sight, then solve the
  // absolute orientation problem, until the object-space error stops falling.
  RppSolution orthogonalIteration(Matrix3d r) const {
    Vector3d t = optimalTranslation(r);
    double previous = error(r, t);
    const size_t n = points_.size();
    Vector3d p_mean = Vector3d::Zero();
    for (const Vector3d& p : points_) p_mean += p;
    p_mean /= static_cast<double>(n);
    std::vector<Vector3d>& q = scratch_;
    q.resize(n);
    for (int iteration = 0; iteration < 200; ++iteration) {
      Vector3d q_mean = Vector3d::Zero();
      for (size_t i = 0; i < n; ++i) {
        q[i] = projections_[i] * (r * points_[i] + t);
        q_mean += q[i];
      }
      q_mean /= static_cast<double>(n);
      Matrix3d m = Matrix3d::Zero();
      for (size_t i = 0; i < n; ++i) m += (q[i] - q_mean) * (points_[i] - p_mean).transpose();
      Eigen::JacobiSVD<Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
      Matrix3d d = Matrix3d::Identity();
      d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
      r = svd.matrixU() * d * svd.matrixV().transpose();
      t = optimalTranslation(r);
      const double e = error(r, t);
      if (std::abs(previous - e) <= 1e-16 + 1e-8 * previous) {
        previous = e;
        break;
      }
      previous = e;
    }
    return toSolution(r, t, previous);
  }

  static RppSolution toSolution(const Matrix3d& r, const Vector3d& t, double e) {
    cv::Matx33d rotation;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) rotation(i, j) = r(i, j);
    }
    return {rotation, cv::Vec3d(t.x(), t.y(), t.z()), e};
  }

 private:
  std::vector<Vector3d> points_;
  std::vector<Matrix3d> projections_;
  Matrix3d translation_factor_;
  mutable std::vector<Vector3d> scratch_;
};

Matrix3d rotationZ(double a) {
  Matrix3d r;
  r << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return r;
}

Matrix3d nearestRotation(const Matrix3d& m) {
  Eigen::JacobiSVD<Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3d d = Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

// A starting rotation from the plane-to-image homography (DLT on the normalised rays).
Matrix3d homographyRotation(std::span<const cv::Point3d> object,
                            std::span<const cv::Point2d> rays) {
  const size_t n = object.size();
  Eigen::MatrixXd a(2 * n, 9);
  for (size_t i = 0; i < n; ++i) {
    const double x = object[i].x, y = object[i].y, u = rays[i].x, v = rays[i].y;
    a.row(2 * i) << -x, -y, -1, 0, 0, 0, u * x, u * y, u;
    a.row(2 * i + 1) << 0, 0, 0, -x, -y, -1, v * x, v * y, v;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd h = svd.matrixV().col(8);
  Matrix3d homography;
  homography << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  Vector3d h1 = homography.col(0), h2 = homography.col(1), h3 = homography.col(2);
  const double scale = 2.0 / (h1.norm() + h2.norm());
  if (h3.z() * scale < 0.0) h1 = -h1, h2 = -h2;  // the target lies in front of the camera
  Matrix3d r;
  r.col(0) = h1 * scale;
  r.col(1) = h2 * scale;
  r.col(2) = r.col(0).cross(r.col(1));
  return nearestRotation(r);
}

// Real roots of c[0] + c[1] u + ... + c[d] u^d (trailing zero coefficients dropped).
std::vector<double> realRoots(std::vector<double> c) {
  while (c.size() > 1 && std::abs(c.back()) < 1e-14 * (1.0 + std::abs(c.front()))) c.pop_back();
  const int degree = static_cast<int>(c.size()) - 1;
  std::vector<double> roots;
  if (degree < 1) return roots;
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(degree, degree);
  for (int i = 0; i < degree; ++i) companion(0, i) = -c[degree - 1 - i] / c[degree];
  for (int i = 1; i < degree; ++i) companion(i, i - 1) = 1.0;
  Eigen::EigenSolver<Eigen::MatrixXd> solver(companion, false);
  for (int i = 0; i < degree; ++i) {
    const std::complex<double> root = solver.eigenvalues()(i);
    if (std::abs(root.imag()) < 1e-7 * (1.0 + std::abs(root.real()))) roots.push_back(root.real());
  }
  return roots;
}

}  // namespace

std::vector<RppSolution> robustPlanarPose(std::span<const cv::Point3d> object,
                                          std::span<const cv::Point2d> rays) {
  const ObjectSpace space(object, rays);
  const RppSolution first = space.orthogonalIteration(homographyRotation(object, rays));
  Matrix3d r1;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r1(i, j) = first.rotation(i, j);
  }
  const Vector3d t1(first.translation[0], first.translation[1], first.translation[2]);

  // Turn the line of sight onto z: r_t * t1 is along +z.
  const Vector3d sight = t1.normalized(), z(0, 0, 1);
  Matrix3d r_t = Matrix3d::Identity();
  const Vector3d axis = sight.cross(z);
  if (axis.norm() > 1e-12) {
    r_t = Eigen::AngleAxisd(std::atan2(axis.norm(), sight.dot(z)), axis.normalized())
              .toRotationMatrix();
  }
  const Matrix3d aligned = r_t * r1;
  // aligned = Rz(gamma) Ry(beta) Rz(alpha).
  double gamma = std::atan2(aligned(1, 2), aligned(0, 2));
  double alpha = std::atan2(aligned(2, 1), -aligned(2, 0));
  if (std::hypot(aligned(0, 2), aligned(1, 2)) < 1e-9) {  // face-on: only gamma + alpha is defined
    gamma = 0.0;
    alpha = std::atan2(aligned(1, 0), aligned(0, 0));
  }
  // R(beta) = A cos(beta) + B sin(beta) + C.
  Matrix3d cosine = Matrix3d::Zero(), sine = Matrix3d::Zero(), constant = Matrix3d::Zero();
  cosine(0, 0) = cosine(2, 2) = 1.0;
  sine(0, 2) = 1.0;
  sine(2, 0) = -1.0;
  constant(1, 1) = 1.0;
  const Matrix3d outer = r_t.transpose() * rotationZ(gamma), inner = rotationZ(alpha);
  const auto a = space.residuals(outer * cosine * inner);
  const auto b = space.residuals(outer * sine * inner);
  const auto c = space.residuals(outer * constant * inner);
  // E(beta) = c1 cos^2 + c2 sin^2 + c3 sin cos + c4 cos + c5 sin + c6.
  double c1 = 0, c2 = 0, c3 = 0, c4 = 0, c5 = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    c1 += a[i].dot(a[i]);
    c2 += b[i].dot(b[i]);
    c3 += 2.0 * a[i].dot(b[i]);
    c4 += 2.0 * a[i].dot(c[i]);
    c5 += 2.0 * b[i].dot(c[i]);
  }
  // dE/dbeta = (c2 - c1) sin 2b + c3 cos 2b - c4 sin b + c5 cos b = 0, with u = tan(b / 2):
  const std::vector<double> polynomial{c3 + c5, 4.0 * (c2 - c1) - 2.0 * c4, -6.0 * c3,
                                       -4.0 * (c2 - c1) - 2.0 * c4, c3 - c5};
  std::vector<double> stationary{M_PI};  // u -> infinity
  for (double u : realRoots(polynomial)) stationary.push_back(2.0 * std::atan(u));
  // The first solution sits at one minimum (beta0); refine only the other minima.
  const double beta0 = std::atan2(std::hypot(aligned(0, 2), aligned(1, 2)), aligned(2, 2));
  auto curvature = [&](double b) {
    return 2.0 * (c2 - c1) * std::cos(2.0 * b) - 2.0 * c3 * std::sin(2.0 * b) - c4 * std::cos(b) -
           c5 * std::sin(b);
  };
  std::vector<double> betas;
  for (double beta : stationary) {
    const double from_first = std::abs(std::remainder(beta - beta0, 2.0 * M_PI));
    if (curvature(beta) > 0.0 && from_first > 1e-3) betas.push_back(beta);
  }

  std::vector<RppSolution> solutions{first};
  for (double beta : betas) {
    const Matrix3d r = outer * (cosine * std::cos(beta) + sine * std::sin(beta) + constant) * inner;
    const RppSolution candidate = space.orthogonalIteration(r);
    if (candidate.translation[2] <= 0.0) continue;  // behind the camera
    bool known = false;
    for (const RppSolution& s : solutions) {
      known = known || cv::norm(cv::Mat(s.rotation), cv::Mat(candidate.rotation)) < 1e-4;
    }
    if (!known) solutions.push_back(candidate);
  }
  std::sort(solutions.begin(), solutions.end(), [](const RppSolution& x, const RppSolution& y) {
    return x.object_space_error < y.object_space_error;
  });
  if (solutions.size() > 2) solutions.resize(2);
  return solutions;
}

}  // namespace arbci::vision
