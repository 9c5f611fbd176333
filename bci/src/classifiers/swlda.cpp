// Stepwise linear discriminant analysis as BCI2000's P300Classifier (after MATLAB's stepwisefit):
// regress the labels (+1 target, -1 non-target) on the features, adding at each step the
// feature whose coefficient would be most significant (p < p-enter) or, when none qualifies,
// removing the least significant one (p > p-remove), until neither applies or the model holds
// the maximum number of features. The weights are the least-squares coefficients of the
// features kept.
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "arbci/bci/evaluation.h"
#include "classifiers/linear.h"
#include "statistics.h"

namespace arbci::bci {
namespace {

class SwldaClassifier final : public LinearClassifierBase {
 public:
  explicit SwldaClassifier(const SwldaSettings& settings) : settings_(settings) {}
  std::string method() const override { return "swlda"; }
  void train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
             const FeatureShape& shape, const Progress& progress) override;

 private:
  SwldaSettings settings_;
};

}  // namespace

namespace {

struct Fit {
  Eigen::VectorXd coefficients;  // intercept first
  Eigen::VectorXd p_values;      // of each feature's coefficient (not the intercept)
};

// Least squares of y on [1, X_S] with the two-sided p-value of each coefficient.
Fit fitModel(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const std::vector<int>& selected) {
  const Eigen::Index n = x.rows();
  const auto k = static_cast<Eigen::Index>(selected.size());
  Eigen::MatrixXd design(n, k + 1);
  design.col(0).setOnes();
  for (Eigen::Index j = 0; j < k; ++j) design.col(j + 1) = x.col(selected[static_cast<size_t>(j)]);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(design);
  Fit fit;
  fit.coefficients = qr.solve(y);
  const double df = static_cast<double>(n - k - 1);
  const double sigma2 = (y - design * fit.coefficients).squaredNorm() / df;
  const Eigen::MatrixXd r =
      qr.matrixQR().topLeftCorner(k + 1, k + 1).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inverse =
      r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(k + 1, k + 1));
  fit.p_values.resize(k);
  for (Eigen::Index j = 0; j < k; ++j) {
    const double variance = sigma2 * r_inverse.row(j + 1).squaredNorm();
    fit.p_values[j] =
        variance > 0.0 ? studentTwoSidedP(fit.coefficients[j + 1] / std::sqrt(variance), df) : 1.0;
  }
  return fit;
}

// The candidates' columns with the span of [1, X_S] projected out, kept up to date as features
// enter (and rebuilt when one leaves).
class Residuals {
 public:
  Residuals(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) : x_(x), y_(y) { rebuild({}); }

  void rebuild(const std::vector<int>& selected) {
    residual_x_ = x_;
    residual_y_ = y_;
    basis_.clear();
    add(Eigen::VectorXd::Ones(x_.rows()));
    for (int j : selected) add(x_.col(j));
  }
  // Adds a column to the span (Gram-Schmidt, twice for stability).
  void add(Eigen::VectorXd v) {
    for (int pass = 0; pass < 2; ++pass) {
      for (const Eigen::VectorXd& q : basis_) v -= q.dot(v) * q;
    }
    const double norm = v.norm();
    if (norm < 1e-12) return;
    v /= norm;
    residual_x_ -= v * (v.transpose() * residual_x_);
    residual_y_ -= v.dot(residual_y_) * v;
    basis_.push_back(std::move(v));
  }
  // p-value of adding feature j (t-test of its coefficient in the enlarged model).
  double enterP(int j) const {
    const auto col = residual_x_.col(j);
    const double ss = col.squaredNorm();
    if (ss < 1e-10 * std::max(1.0, x_.col(j).squaredNorm()))
      return 1.0;  // collinear with the model
    const double cross = col.dot(residual_y_);
    const double rss_old = residual_y_.squaredNorm();
    const double rss_new = rss_old - cross * cross / ss;
    const double df = static_cast<double>(x_.rows()) - static_cast<double>(basis_.size()) - 1.0;
    if (df < 1.0 || rss_new <= 0.0) return 0.0;
    return studentTwoSidedP(std::sqrt((rss_old - rss_new) / (rss_new / df)), df);
  }

 private:
  const Eigen::MatrixXd& x_;
  const Eigen::VectorXd& y_;
  Eigen::MatrixXd residual_x_;
  Eigen::VectorXd residual_y_;
  std::vector<Eigen::VectorXd> basis_;
};

}  // namespace

void SwldaClassifier::train(const Eigen::MatrixXd& features, const std::vector<bool>& target,
                            const FeatureShape& shape, const Progress& progress) {
  checkTrainingData(features, target, shape);
  if (!(settings_.p_enter > 0.0 && settings_.p_enter < settings_.p_remove &&
        settings_.p_remove < 1.0)) {
    throw std::invalid_argument("SWLDA needs 0 < p-enter < p-remove < 1");
  }
  const Eigen::Index n = features.rows(), p = features.cols();
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) y[i] = target[static_cast<size_t>(i)] ? 1.0 : -1.0;

  std::vector<int> selected;
  Residuals residuals(features, y);
  const int max_steps = 4 * settings_.max_features + 20;  // stepwise fits can cycle; bound them
  for (int step = 0; step < max_steps; ++step) {
    if (progress)
      progress(std::min(1.0, static_cast<double>(selected.size()) / settings_.max_features),
               "SWLDA step " + std::to_string(step + 1));
    // Try to add the most significant feature.
    int best = -1;
    double best_p = settings_.p_enter;
    if (static_cast<int>(selected.size()) < settings_.max_features) {
      for (Eigen::Index j = 0; j < p; ++j) {
        if (std::find(selected.begin(), selected.end(), static_cast<int>(j)) != selected.end())
          continue;
        const double pj = residuals.enterP(static_cast<int>(j));
        if (pj < best_p) {
          best_p = pj;
          best = static_cast<int>(j);
        }
      }
    }
    if (best >= 0) {
      selected.push_back(best);
      residuals.add(features.col(best));
      continue;
    }
    // Otherwise remove the least significant one.
    if (selected.empty()) break;
    const Fit fit = fitModel(features, y, selected);
    Eigen::Index worst = 0;
    const double worst_p = fit.p_values.maxCoeff(&worst);
    if (worst_p <= settings_.p_remove) break;
    selected.erase(selected.begin() + worst);
    residuals.rebuild(selected);
  }
  if (selected.empty()) {
    throw std::invalid_argument("SWLDA: no feature separates targets from non-targets at p < " +
                                std::to_string(settings_.p_enter));
  }
  const Fit fit = fitModel(features, y, selected);
  weights_ = Eigen::VectorXd::Zero(p);
  nlohmann::json kept = nlohmann::json::array();
  for (size_t j = 0; j < selected.size(); ++j) {
    const int feature = selected[j];
    weights_[feature] = fit.coefficients[static_cast<Eigen::Index>(j) + 1];
    kept.push_back({{"channel", feature / shape.bins},
                    {"bin", feature % shape.bins},
                    {"weight", weights_[feature]},
                    {"p", fit.p_values[static_cast<Eigen::Index>(j)]}});
  }
  bias_ = fit.coefficients[0];
  details_ = {{"p_enter", settings_.p_enter},
              {"p_remove", settings_.p_remove},
              {"max_features", settings_.max_features},
              {"features", kept}};
  if (progress) progress(1.0, "SWLDA: " + std::to_string(selected.size()) + " features");
}

ClassifierRegistry::Entry swldaClassifier() {
  ClassifierParts parts;
  parts.make = [](const TrainingSettings& s) { return std::make_unique<SwldaClassifier>(s.swlda); };
  parts.restore = [](const nlohmann::json& json, const FeatureShape& shape) {
    return restoreLinear<SwldaClassifier>(json, shape, SwldaSettings{});
  };
  parts.parameters = [](const TrainingSettings& s) {
    return nlohmann::json{{"p_enter", s.swlda.p_enter},
                          {"p_remove", s.swlda.p_remove},
                          {"max_features", s.swlda.max_features}};
  };
  return {"swlda",
          "stepwise LDA as BCI2000's P300Classifier: features enter below p_enter and leave "
          "above p_remove, at most max_features; least-squares weights",
          std::move(parts)};
}

}  // namespace arbci::bci
