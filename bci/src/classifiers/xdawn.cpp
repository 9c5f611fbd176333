// xDAWN (Rivet et al. 2009, as OpenViBE's P300 pipeline): spatial filters that maximise the
// power of the target response against the power of the whole signal (generalised eigenvectors
// of the two covariances), then shrinkage LDA on the filtered, decimated epochs. The result is
// still linear in the original features, so it is stored as equivalent weights.
#include <algorithm>

#include "arbci/bci/evaluation.h"
#include "classifiers/linear.h"
#include "xdawn_filters.h"

namespace arbci::bci {
namespace {

class XdawnClassifier final : public LinearClassifierBase {
 public:
  explicit XdawnClassifier(const XdawnSettings& settings) : settings_(settings) {}
  std::string method() const override { return "xdawn"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override;

 private:
  XdawnSettings settings_;
};

}  // namespace

void XdawnClassifier::train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                            const FeatureShape& shape, const Progress& progress) {
  checkTrainingData(features, target, shape);
  const int channels = shape.channels, bins = shape.bins;
  const Eigen::Index n = features.rows();
  if (progress) progress(0.0, "xDAWN spatial filters");
  const int kept = settings_.filters;
  const Eigen::MatrixXd filters = xdawnFilters(features, shape, target, kept).filters;

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

ClassifierRegistry::Entry xdawnClassifier() {
  ClassifierParts parts;
  parts.make = [](const TrainingSettings& s) { return std::make_unique<XdawnClassifier>(s.xdawn); };
  parts.restore = [](const nlohmann::json& json, const FeatureShape& shape) {
    return restoreLinear<XdawnClassifier>(json, shape, XdawnSettings{});
  };
  parts.check = [](const TrainingSettings& s, const FeatureShape& shape) {
    checkFilterCount(s.xdawn.filters, shape.channels);
  };
  parts.parameters = [](const TrainingSettings& s) {
    return nlohmann::json{{"filters", s.xdawn.filters}};
  };
  parts.xdawn_filters = 4;  // OpenViBE's P300 scenario
  return {"xdawn",
          "xDAWN spatial filters (xdawn_filters kept, by default " +
              std::to_string(parts.xdawn_filters) +
              "), then shrinkage LDA: OpenViBE's P300 pipeline",
          std::move(parts)};
}

}  // namespace arbci::bci
