#include "xdawn_filters.h"

#include <Eigen/Eigenvalues>
#include <stdexcept>
#include <string>

namespace arbci::bci {

Eigen::MatrixXd epochOf(const Eigen::Ref<const Eigen::RowVectorXd>& row,
                        const FeatureShape& shape) {
  Eigen::MatrixXd e(shape.channels, shape.bins);
  for (int c = 0; c < shape.channels; ++c) {
    for (int b = 0; b < shape.bins; ++b) e(c, b) = row(c * shape.bins + b);
  }
  return e;
}

void checkFilterCount(int kept, int channels) {
  if (kept < 1 || kept > channels) {
    throw std::invalid_argument(
        "xDAWN: " + std::to_string(kept) + " spatial filters asked for, the features have " +
        std::to_string(channels) + " channels (1 to " + std::to_string(channels) + " allowed)");
  }
}

XdawnFilters xdawnFilters(const Eigen::MatrixXd& features, const FeatureShape& shape,
                          const std::vector<bool>& in_class, int kept) {
  const int channels = shape.channels, bins = shape.bins;
  checkFilterCount(kept, channels);
  const Eigen::Index n = features.rows();
  XdawnFilters out;
  out.evoked = Eigen::MatrixXd::Zero(channels, bins);
  Eigen::MatrixXd signal_covariance = Eigen::MatrixXd::Zero(channels, channels);
  int members = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::MatrixXd e = epochOf(features.row(i), shape);
    signal_covariance += e * e.transpose();
    if (in_class[static_cast<size_t>(i)]) {
      out.evoked += e;
      ++members;
    }
  }
  if (members == 0) throw std::invalid_argument("xDAWN: a class without epochs");
  out.evoked /= members;
  signal_covariance /= static_cast<double>(n * bins);
  signal_covariance.diagonal().array() += 1e-9 * signal_covariance.trace() / channels;
  const Eigen::MatrixXd evoked_covariance = out.evoked * out.evoked.transpose() / bins;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(evoked_covariance,
                                                                         signal_covariance);
  if (solver.info() != Eigen::Success)
    throw std::invalid_argument("xDAWN: the signal covariance is singular");
  out.filters = solver.eigenvectors().rightCols(kept);  // largest eigenvalues last
  return out;
}

}  // namespace arbci::bci
