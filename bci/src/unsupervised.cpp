#include "arbci/bci/unsupervised.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

#include "arbci/bci/evaluation.h"
#include "classifiers/linear.h"

namespace arbci::bci {
namespace {

struct Problem {
  Eigen::MatrixXd x;                   // the fitted epochs' features, centred
  std::vector<std::vector<int>> rows;  // per selection: its rows of x
  std::vector<int> code;               // per row
  int choices = 0;
  std::vector<std::vector<int>> codes_of;  // per choice: its codes
};

struct Start {
  std::vector<int> choice;
  std::vector<double> posterior;
  Eigen::VectorXd w;
  int iterations = 0;
  // The share of the data's (Mahalanobis) variance the two classes explain: with one covariance
  // for all starts, the Gaussian model's likelihood grows with it.
  double explained = 0.0;
};

// Each epoch's log-odds of being a target from its projection y and the target probabilities p:
// a Gaussian per class with a shared variance.
Eigen::VectorXd logOdds(const Eigen::VectorXd& y, const Eigen::VectorXd& p) {
  const double wt = p.sum(), wo = static_cast<double>(p.size()) - wt;
  const double mt = p.dot(y) / std::max(wt, 1e-9);
  const double mo = (Eigen::VectorXd::Ones(p.size()) - p).dot(y) / std::max(wo, 1e-9);
  double var = 0.0;
  for (Eigen::Index i = 0; i < y.size(); ++i)
    var += p[i] * (y[i] - mt) * (y[i] - mt) + (1.0 - p[i]) * (y[i] - mo) * (y[i] - mo);
  var = std::max(var / static_cast<double>(y.size()), 1e-12);
  return ((mt - mo) / var) * (y.array() - 0.5 * (mt + mo)).matrix();
}

// The posterior of each choice of each selection from the epochs' log-odds; each epoch's
// probability of being a target; the MAP choices.
double expectation(const Problem& pr, const Eigen::VectorXd& odds, Eigen::VectorXd& p,
                   std::vector<int>& choice, std::vector<double>& best) {
  double change = 0.0;
  choice.assign(pr.rows.size(), 0);
  best.assign(pr.rows.size(), 0.0);
  std::vector<double> by_code;
  std::vector<double> post(static_cast<size_t>(pr.choices));
  for (size_t s = 0; s < pr.rows.size(); ++s) {
    std::map<int, double> sum;
    for (int r : pr.rows[s]) sum[pr.code[static_cast<size_t>(r)]] += odds[r];
    double top = -1e300;
    for (int c = 0; c < pr.choices; ++c) {
      double v = 0.0;
      for (int code : pr.codes_of[static_cast<size_t>(c)]) {
        const auto found = sum.find(code);
        if (found != sum.end()) v += found->second;
      }
      post[static_cast<size_t>(c)] = v;
      top = std::max(top, v);
    }
    double z = 0.0;
    for (double& v : post) z += (v = std::exp(v - top));
    std::map<int, double> target_of_code;
    for (int c = 0; c < pr.choices; ++c) {
      const double q = post[static_cast<size_t>(c)] / z;
      if (q > best[s]) {
        best[s] = q;
        choice[s] = c;
      }
      for (int code : pr.codes_of[static_cast<size_t>(c)]) target_of_code[code] += q;
    }
    for (int r : pr.rows[s]) {
      const double q = target_of_code[pr.code[static_cast<size_t>(r)]];
      change = std::max(change, std::abs(q - p[r]));
      p[r] = q;
    }
  }
  return change;
}

Start runStart(const Problem& pr, const Eigen::LDLT<Eigen::MatrixXd>& covariance,
               std::mt19937_64& random, int max_iterations) {
  std::normal_distribution<double> normal;
  Eigen::VectorXd w(pr.x.cols());
  for (Eigen::Index i = 0; i < w.size(); ++i) w[i] = normal(random);
  Eigen::VectorXd y = pr.x * w;
  // The first log-odds: the random projection, standardised.
  const double sd = std::sqrt(y.squaredNorm() / static_cast<double>(y.size()));
  Eigen::VectorXd odds = y / std::max(sd, 1e-12);
  Eigen::VectorXd p = Eigen::VectorXd::Zero(y.size());
  Start out;
  for (out.iterations = 1; out.iterations <= max_iterations; ++out.iterations) {
    const double change = expectation(pr, odds, p, out.choice, out.posterior);
    // Maximisation: the class means weighted by p; w from the label-free covariance.
    const double wt = p.sum(), wo = static_cast<double>(p.size()) - wt;
    const Eigen::VectorXd mt = pr.x.transpose() * p / std::max(wt, 1e-9);
    const Eigen::VectorXd mo =
        pr.x.transpose() * (Eigen::VectorXd::Ones(p.size()) - p) / std::max(wo, 1e-9);
    w = covariance.solve(mt - mo);
    const double n = static_cast<double>(p.size());
    out.explained = (wt / n) * (wo / n) * (mt - mo).dot(w);
    y = pr.x * w;
    odds = logOdds(y, p);
    if (change < 1e-4 && out.iterations > 1) break;
  }
  out.w = w;
  return out;
}

}  // namespace

UnsupervisedFit fitWithoutLabels(const P300Dataset& data, std::vector<int> selections,
                                 const UnsupervisedOptions& options) {
  if (selections.empty())
    for (size_t s = 0; s < data.selections.size(); ++s) selections.push_back(static_cast<int>(s));
  Problem pr;
  pr.choices = data.layout.choices();
  for (int c = 0; c < pr.choices; ++c) {
    const std::set<int> codes = data.layout.codesOf(c);
    pr.codes_of.emplace_back(codes.begin(), codes.end());
  }
  int n = 0;
  for (int s : selections)
    n += static_cast<int>(data.selections.at(static_cast<size_t>(s)).epochs.size());
  if (n == 0 || pr.choices < 2)
    throw std::invalid_argument("no epochs to learn from, or fewer than two choices");
  pr.x.resize(n, data.features.cols());
  int row = 0;
  for (int s : selections) {
    std::vector<int> rows;
    std::set<int> seen;
    for (int e : data.selections[static_cast<size_t>(s)].epochs) {
      pr.x.row(row) = data.features.row(e);
      pr.code.push_back(data.code[static_cast<size_t>(e)]);
      seen.insert(data.code[static_cast<size_t>(e)]);
      rows.push_back(row++);
    }
    // One attended choice among several: at least two choices whose codes were all flashed.
    int whole = 0;
    for (const auto& codes : pr.codes_of)
      whole += std::all_of(codes.begin(), codes.end(), [&](int c) { return seen.count(c) > 0; });
    if (whole < 2)
      throw std::invalid_argument("selection " + std::to_string(s + 1) + " flashes " +
                                  std::to_string(whole) +
                                  " whole choice(s) of the layout: no single attended stimulus "
                                  "among several to learn from");
    pr.rows.push_back(std::move(rows));
  }
  const Eigen::RowVectorXd mean = pr.x.colwise().mean();
  pr.x.rowwise() -= mean;
  // The covariance of all epochs: no label needed.
  double shrinkage = 0.0;
  const Eigen::LDLT<Eigen::MatrixXd> covariance = ledoitWolfCovariance(pr.x, shrinkage).ldlt();
  std::mt19937_64 random(options.seed);
  std::vector<Start> starts;
  for (int r = 0; r < options.restarts; ++r)
    starts.push_back(runStart(pr, covariance, random, options.max_iterations));
  // The most likely start: the labels that explain most of the data's variance. A start may settle
  // on the mirror solution (each selection's least P300-like stimulus as its target), a fixed
  // point too, but one that explains less.
  const Start& kept =
      *std::max_element(starts.begin(), starts.end(),
                        [](const Start& a, const Start& b) { return a.explained < b.explained; });
  UnsupervisedFit fit;
  fit.selections = selections;
  fit.restarts = options.restarts;
  for (const Start& s : starts) fit.agreeing += s.choice == kept.choice;
  fit.choice = kept.choice;
  fit.posterior = kept.posterior;
  fit.weights = kept.w;
  fit.iterations = kept.iterations;
  return fit;
}

P300Dataset withLabelsFound(const P300Dataset& data, const UnsupervisedFit& fit) {
  P300Dataset out = data;
  for (size_t k = 0; k < fit.selections.size(); ++k) {
    SelectionEpochs& selection = out.selections[static_cast<size_t>(fit.selections[k])];
    selection.target_codes = data.layout.codesOf(fit.choice[k]);
    for (int e : selection.epochs)
      out.target[static_cast<size_t>(e)] =
          selection.target_codes.count(data.code[static_cast<size_t>(e)]) > 0;
  }
  return out;
}

UnsupervisedReport evaluateWithoutLabels(const P300Dataset& data,
                                         const UnsupervisedOptions& options) {
  UnsupervisedReport report;
  report.fit = fitWithoutLabels(data, {}, options);
  const auto truth = [&](int s) -> const std::set<int>& {
    return data.selections[static_cast<size_t>(s)].target_codes;
  };
  report.labelled = true;
  for (size_t s = 0; s < data.selections.size(); ++s)
    report.labelled &= !truth(static_cast<int>(s)).empty();
  const int selections = static_cast<int>(data.selections.size());
  for (int k = 0; k < selections; ++k) {
    if (report.labelled)
      report.right += data.layout.codesOf(report.fit.choice[static_cast<size_t>(k)]) == truth(k);
    std::vector<int> first;
    for (int i = 0; i <= k; ++i) first.push_back(i);
    const UnsupervisedFit online = fitWithoutLabels(data, first, options);
    report.curve.push_back(
        {k + 1, report.labelled && data.layout.codesOf(online.choice.back()) == truth(k),
         online.agreeing});
  }
  if (!report.labelled || selections < 2) return report;
  std::vector<double> scores;
  std::vector<bool> target;
  for (int k = 0; k < selections; ++k) {
    std::vector<int> others;
    for (int i = 0; i < selections; ++i)
      if (i != k) others.push_back(i);
    const UnsupervisedFit fit = fitWithoutLabels(data, others, options);
    for (int e : data.selections[static_cast<size_t>(k)].epochs) {
      scores.push_back(data.features.row(e).dot(fit.weights));
      target.push_back(data.target[static_cast<size_t>(e)]);
    }
  }
  report.cross_validated_auc = areaUnderCurve(scores, target);
  return report;
}

}  // namespace arbci::bci
