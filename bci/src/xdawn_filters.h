// xDAWN spatial filters (Rivet et al. 2009): the generalised eigenvectors of one class's evoked
// covariance against the whole signal's, largest first. Shared by the xDAWN + LDA method and the
// Riemannian method's augmented covariances.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "arbci/bci/features.h"

namespace arbci::bci {

// One epoch of a feature row (channel-major: channel c's bins at c * bins) as channels x bins.
Eigen::MatrixXd epochOf(const Eigen::Ref<const Eigen::RowVectorXd>& row, const FeatureShape& shape);

// Throws std::invalid_argument unless `kept` is 1 to `channels`.
void checkFilterCount(int kept, int channels);

struct XdawnFilters {
  Eigen::MatrixXd filters;  // channels x kept, the strongest last
  Eigen::MatrixXd evoked;   // the class's mean epoch, channels x bins
};

// Filters for the epochs (rows of `features`) where `in_class` holds. Throws
// std::invalid_argument when `kept` is not 1 to the channel count or the signal is singular.
XdawnFilters xdawnFilters(const Eigen::MatrixXd& features, const FeatureShape& shape,
                          const std::vector<bool>& in_class, int kept);

}  // namespace arbci::bci
