// xDAWN (Rivet et al. 2009, as OpenViBE's P300 pipeline): spatial filters that maximise the
// power of the target response against the power of the whole signal (generalised eigenvectors
// of the two covariances), then shrinkage LDA on the filtered, decimated epochs. The result is
// still linear in the original features, so it is stored as equivalent weights.
#include <Eigen/Eigenvalues>
#include <algorithm>

#include "linear_classifiers.h"

namespace arbci::bci {

void XdawnClassifier::train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                            const FeatureShape& shape, const Progress& progress) {
  checkTrainingData(features, target, shape);
  const int channels = shape.channels, bins = shape.bins;
  const Eigen::Index n = features.rows();
  if (progress) progress(0.0, "xDAWN spatial filters");
  Eigen::MatrixXd target_mean = Eigen::MatrixXd::Zero(channels, bins);
  Eigen::MatrixXd signal_covariance = Eigen::MatrixXd::Zero(channels, channels);
  int n_target = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::MatrixXd e(channels, bins);
    for (int c = 0; c < channels; ++c) {
      for (int b = 0; b < bins; ++b) e(c, b) = features(i, c * bins + b);
    }
    signal_covariance += e * e.transpose();
    if (target[static_cast<size_t>(i)]) {
      target_mean += e;
      ++n_target;
    }
  }
  target_mean /= n_target;
  signal_covariance /= static_cast<double>(n * bins);
  signal_covariance.diagonal().array() += 1e-9 * signal_covariance.trace() / channels;
  const Eigen::MatrixXd evoked_covariance = target_mean * target_mean.transpose() / bins;
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(evoked_covariance,
                                                                         signal_covariance);
  if (solver.info() != Eigen::Success)
    throw std::invalid_argument("xDAWN: the signal covariance is singular");
  if (settings_.filters < 1 || settings_.filters > channels) {
    throw std::invalid_argument("xDAWN: " + std::to_string(settings_.filters) +
                                " spatial filters asked for, the features have " +
                                std::to_string(channels) + " channels (1 to " +
                                std::to_string(channels) + " allowed)");
  }
  const int kept = settings_.filters;
  const Eigen::MatrixXd filters =
      solver.eigenvectors().rightCols(kept);  // largest eigenvalues last

  // Filtered epochs: kept x bins each, flattened filter-major.
  Eigen::MatrixXd projected(n, kept * bins);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int f = 0; f < kept; ++f) {
      for (int b = 0; b < bins; ++b) {
        double sum = 0.0;
        for (int c = 0; c < channels; ++c) sum += filters(c, f) * features(i, c * bins + b);
        projected(i, f * bins + b) = sum;
      }
    }
  }
  if (progress) progress(0.5, "xDAWN: shrinkage LDA");
  Eigen::VectorXd lda_weights;
  const double shrinkage = trainShrinkageLda(projected, target, lda_weights, bias_);
  // Equivalent weights: w(c, b) = sum_f v(f, b) W(c, f).
  weights_ = Eigen::VectorXd::Zero(shape.size());
  for (int c = 0; c < channels; ++c) {
    for (int b = 0; b < bins; ++b) {
      double w = 0.0;
      for (int f = 0; f < kept; ++f) w += lda_weights[f * bins + b] * filters(c, f);
      weights_[c * bins + b] = w;
    }
  }
  std::vector<std::vector<double>> filter_rows(static_cast<size_t>(kept));
  for (int f = 0; f < kept; ++f) {
    for (int c = 0; c < channels; ++c) filter_rows[static_cast<size_t>(f)].push_back(filters(c, f));
  }
  details_ = {{"filters", filter_rows}, {"shrinkage", shrinkage}};
  if (progress) progress(1.0, "xDAWN");
}

}  // namespace arbci::bci
