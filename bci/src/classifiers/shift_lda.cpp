// Latency-tolerant shrinkage LDA, for responses whose latency varies from trial to trial (the
// error-related potential: its negativity and positivity move by tens of milliseconds between
// feedbacks, which smears a fixed-latency template and caps every linear method on fixed bins).
//
// Training: the epochs through the target class's xDAWN spatial filters (xdawn_filters, 1 by
// default: one virtual channel), then shrinkage LDA on the window's central part (a margin of
// shift_ms cut off each side). Scoring: the same weights slid over the window a bin at a time, up
// to shift_ms each way; the score is the score at no shift plus the largest over the shifts. The
// unshifted score keeps what a fixed template knows; the largest catches a response that came early
// or late. Their equal sum has no parameter to fit: with a calibration block's 25 errors a fitted
// combination (logistic regression on out-of-fold scores) was worse on every one of five
// simulated subjects (seeds 11-15, 100-feedback blocks) and no better with 6,400 feedbacks.
// Not linear in the features: no BCI2000 export.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "arbci/bci/evaluation.h"
#include "classifiers/linear.h"
#include "xdawn_filters.h"

namespace arbci::bci {
namespace {

class ShiftLdaClassifier final : public Classifier {
 public:
  ShiftLdaClassifier(double shift_ms, int spatial_filters)
      : shift_ms_(shift_ms), spatial_filters_(spatial_filters) {}
  std::string method() const override { return "shift-lda"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override;
  double score(const Eigen::Ref<const Eigen::VectorXd>& features) const override;
  Eigen::VectorXd weights() const override { return {}; }  // not linear
  double bias() const override { return 0.0; }
  nlohmann::json toJson() const override;
  void restore(const nlohmann::json& json, const FeatureShape& shape);

 private:
  // The central bins of each row of `x` (rows of shape_.bins: the filtered epoch) moved by
  // `shift` bins, as one vector.
  Eigen::VectorXd core(const Eigen::Ref<const Eigen::VectorXd>& x, int shift) const;
  // An epoch's features through `filters` (channels x kept): kept x bins, as one row.
  Eigen::VectorXd filtered(const Eigen::Ref<const Eigen::VectorXd>& x,
                           const Eigen::MatrixXd& filters) const;
  // {score at no shift, largest score over the shifts} with weights w and bias b.
  Eigen::Vector2d shiftScores(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::VectorXd& w,
                              double b) const;

  double shift_ms_;
  int spatial_filters_;  // xDAWN filters of the target class kept
  FeatureShape shape_;
  Eigen::MatrixXd filters_;  // channels x kept
  int shift_bins_ = 0, core_bins_ = 0;
  Eigen::VectorXd weights_;
  double bias_ = 0.0;
};

int shiftBins(double shift_ms, const FeatureShape& shape) {
  if (!(shape.bin_s > 0.0))
    throw std::invalid_argument("shift-lda: the features' bin duration is not known");
  const int shift = static_cast<int>(std::lround(shift_ms / 1000.0 / shape.bin_s));
  if (shape.bins - 2 * shift < 2) {
    throw std::invalid_argument("shift-lda: a window of " + std::to_string(shape.bins) +
                                " bins leaves fewer than 2 after cutting " + std::to_string(shift) +
                                " bins of shift each way: widen the window or lower shift_ms");
  }
  return shift;
}

Eigen::VectorXd ShiftLdaClassifier::filtered(const Eigen::Ref<const Eigen::VectorXd>& x,
                                             const Eigen::MatrixXd& filters) const {
  const Eigen::MatrixXd epoch = filters.transpose() * epochOf(x.transpose(), shape_);
  Eigen::VectorXd out(epoch.size());
  for (Eigen::Index c = 0; c < epoch.rows(); ++c)
    out.segment(c * shape_.bins, shape_.bins) = epoch.row(c).transpose();
  return out;
}

Eigen::VectorXd ShiftLdaClassifier::core(const Eigen::Ref<const Eigen::VectorXd>& x,
                                         int shift) const {
  const int rows = static_cast<int>(x.size()) / shape_.bins;
  Eigen::VectorXd out(rows * core_bins_);
  for (int c = 0; c < rows; ++c)
    out.segment(c * core_bins_, core_bins_) =
        x.segment(c * shape_.bins + shift_bins_ + shift, core_bins_);
  return out;
}

Eigen::Vector2d ShiftLdaClassifier::shiftScores(const Eigen::Ref<const Eigen::VectorXd>& x,
                                                const Eigen::VectorXd& w, double b) const {
  const double centred = w.dot(core(x, 0)) + b;
  double largest = centred;
  for (int k = -shift_bins_; k <= shift_bins_; ++k)
    largest = std::max(largest, w.dot(core(x, k)) + b);
  return {centred, largest};
}

void ShiftLdaClassifier::train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                               const FeatureShape& shape, const Progress& progress) {
  checkTrainingData(features, target, shape);
  shape_ = shape;
  shift_bins_ = shiftBins(shift_ms_, shape);
  core_bins_ = shape.bins - 2 * shift_bins_;
  if (progress) progress(0.0, "shift-LDA");
  Eigen::MatrixXd filters = xdawnFilters(features, shape, target, spatial_filters_).filters;
  Eigen::MatrixXd cores(features.rows(), filters.cols() * core_bins_);
  for (Eigen::Index i = 0; i < features.rows(); ++i)
    cores.row(i) = core(filtered(features.row(i).transpose(), filters), 0).transpose();
  trainShrinkageLda(cores, target, weights_, bias_);
  filters_ = std::move(filters);
  if (progress) progress(1.0, "shift-LDA");
}

double ShiftLdaClassifier::score(const Eigen::Ref<const Eigen::VectorXd>& features) const {
  if (features.size() != shape_.size()) {
    throw std::invalid_argument("classifier: " + std::to_string(features.size()) +
                                " features given, the model has " + std::to_string(shape_.size()));
  }
  const Eigen::Vector2d z = shiftScores(filtered(features, filters_), weights_, bias_);
  return z[0] + z[1];
}

nlohmann::json ShiftLdaClassifier::toJson() const {
  return {{"method", method()},
          {"shift_ms", shift_ms_},
          {"shift_bins", shift_bins_},
          {"spatial_filters", spatial_filters_},
          {"filters", std::vector<double>(filters_.data(), filters_.data() + filters_.size())},
          {"weights", std::vector<double>(weights_.data(), weights_.data() + weights_.size())},
          {"bias", bias_}};
}

void ShiftLdaClassifier::restore(const nlohmann::json& json, const FeatureShape& shape) {
  const auto number = [&](const char* key) {
    if (!json.contains(key) || !json[key].is_number())
      throw std::invalid_argument(std::string("shift-lda classifier: ") + key + " missing");
    return json[key].get<double>();
  };
  shift_ms_ = number("shift_ms");
  shape_ = shape;
  shift_bins_ = static_cast<int>(number("shift_bins"));
  core_bins_ = shape.bins - 2 * shift_bins_;
  if (shift_bins_ < 0 || core_bins_ < 2)
    throw std::invalid_argument("shift-lda classifier: shift_bins does not fit the window");
  bias_ = number("bias");
  spatial_filters_ = static_cast<int>(number("spatial_filters"));
  const int kept = spatial_filters_;
  const std::vector<double> filters = json.value("filters", std::vector<double>{});
  if (kept < 1 || kept > shape.channels ||
      static_cast<int>(filters.size()) != shape.channels * kept)
    throw std::invalid_argument(
        "shift-lda classifier: the spatial filters do not fit the channels");
  filters_ = Eigen::Map<const Eigen::MatrixXd>(filters.data(), shape.channels, kept);
  const std::vector<double> w = json.value("weights", std::vector<double>{});
  if (static_cast<int>(w.size()) != kept * core_bins_)
    throw std::invalid_argument("shift-lda classifier: " + std::to_string(w.size()) +
                                " weights, the window needs " + std::to_string(kept * core_bins_));
  weights_ = Eigen::Map<const Eigen::VectorXd>(w.data(), static_cast<Eigen::Index>(w.size()));
}

}  // namespace

ClassifierRegistry::Entry shiftLdaClassifier() {
  ClassifierParts parts;
  parts.make = [](const TrainingSettings& s) {
    return std::make_unique<ShiftLdaClassifier>(s.shift_ms, s.xdawn.filters);
  };
  parts.restore = [](const nlohmann::json& json, const FeatureShape& shape) {
    auto classifier = std::make_unique<ShiftLdaClassifier>(0.0, 0);
    classifier->restore(json, shape);
    return classifier;
  };
  parts.check = [](const TrainingSettings& s, const FeatureShape& shape) {
    shiftBins(s.shift_ms, shape);
    checkFilterCount(s.xdawn.filters, shape.channels);
  };
  parts.parameters = [](const TrainingSettings& s) {
    return nlohmann::json{{"shift_ms", s.shift_ms}, {"filters", s.xdawn.filters}};
  };
  parts.linear = false;
  parts.xdawn_filters = 1;
  return {"shift-lda",
          "latency-tolerant shrinkage LDA on xdawn_filters (by default " +
              std::to_string(parts.xdawn_filters) +
              ") spatial filters: the weights of the window's centre slid up to shift_ms each "
              "way, the centred and the best score summed (for ErrPs, whose latency varies); not "
              "linear (no BCI2000 export)",
          std::move(parts)};
}

}  // namespace arbci::bci
