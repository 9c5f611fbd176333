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

// Decodings whose leave-one-out consistency is measured: the most likely distinct ones.
constexpr size_t kCandidates = 3;

struct Problem {
  Eigen::MatrixXd x;                   // the fitted epochs' features, centred
  std::vector<std::vector<int>> rows;  // per selection: its rows of x
  std::vector<int> code;               // per row
  std::vector<int> known;              // per selection: its choice when given (else -1)
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
      // A choice not flashed whole in this selection (an object out of view) cannot be it.
      double v = 0.0;
      bool whole = true;
      for (int code : pr.codes_of[static_cast<size_t>(c)]) {
        const auto found = sum.find(code);
        if (found == sum.end()) {
          whole = false;
        } else {
          v += found->second;
        }
      }
      if (pr.known[s] >= 0) v = c == pr.known[s] ? 0.0 : -1e300;
      post[static_cast<size_t>(c)] = whole ? v : -1e300;
      top = std::max(top, post[static_cast<size_t>(c)]);
    }
    double z = 0.0;
    for (double& v : post) z += (v = v <= -1e299 ? 0.0 : std::exp(v - top));
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

// One EM run from a random projection, or from `projection` (the textbook P300 as a matched
// filter), or (`initial`: a choice per selection, -1 where none) from a decoding.
Start runStart(const Problem& pr, const Eigen::LDLT<Eigen::MatrixXd>& covariance,
               std::mt19937_64& random, int max_iterations,
               const std::vector<int>* initial = nullptr,
               const Eigen::VectorXd* projection = nullptr) {
  std::normal_distribution<double> normal;
  Eigen::VectorXd w(pr.x.cols());
  // Every start takes the same numbers from the stream, whichever kind it is.
  for (Eigen::Index i = 0; i < w.size(); ++i) w[i] = normal(random);
  if (projection) w = *projection;
  Eigen::VectorXd y = pr.x * w;
  // The first log-odds: the random projection, standardised; or the decoding given, firmly.
  const double sd = std::sqrt(y.squaredNorm() / static_cast<double>(y.size()));
  Eigen::VectorXd odds = y / std::max(sd, 1e-12);
  if (initial) {
    odds.setZero();
    for (size_t s = 0; s < pr.rows.size(); ++s) {
      const int c = (*initial)[s];
      if (c < 0) continue;
      const auto& codes = pr.codes_of[static_cast<size_t>(c)];
      for (int r : pr.rows[s])
        odds[r] =
            std::find(codes.begin(), codes.end(), pr.code[static_cast<size_t>(r)]) != codes.end()
                ? 3.0
                : -3.0;
    }
  }
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

// The decoding of selection `s` by projection `w`: the whole choice with the most summed score.
int decode(const Problem& pr, size_t s, const Eigen::VectorXd& w) {
  std::map<int, double> by_code;
  for (int r : pr.rows[s]) by_code[pr.code[static_cast<size_t>(r)]] += pr.x.row(r).dot(w);
  int best = -1;
  double top = -1e300;
  for (int c = 0; c < pr.choices; ++c) {
    double v = 0.0;
    bool whole = true;
    for (int code : pr.codes_of[static_cast<size_t>(c)]) {
      const auto found = by_code.find(code);
      whole = whole && found != by_code.end();
      if (found != by_code.end()) v += found->second;
    }
    if (whole && v > top) {
      top = v;
      best = c;
    }
  }
  return best;
}

// The problem without selection `s`.
Problem without(const Problem& pr, size_t s) {
  Problem out;
  out.choices = pr.choices;
  out.codes_of = pr.codes_of;
  std::vector<int> keep;
  for (size_t k = 0; k < pr.rows.size(); ++k) {
    if (k == s) continue;
    std::vector<int> rows;
    for (int r : pr.rows[k]) {
      rows.push_back(static_cast<int>(keep.size()));
      keep.push_back(r);
    }
    out.rows.push_back(std::move(rows));
    out.known.push_back(pr.known[k]);
  }
  out.x.resize(static_cast<Eigen::Index>(keep.size()), pr.x.cols());
  for (size_t i = 0; i < keep.size(); ++i) {
    out.x.row(static_cast<Eigen::Index>(i)) = pr.x.row(keep[i]);
    out.code.push_back(pr.code[static_cast<size_t>(keep[i])]);
  }
  return out;
}

// A direction in the problem's feature space (UnsupervisedOptions::p300_direction) is given.
bool hasDirection(const Problem& pr, const Eigen::VectorXd& direction) {
  return direction.size() == pr.x.cols() && direction.squaredNorm() > 0.0;
}

// Target minus non-target by the decoding `choice`, projected on `direction` in units of it (what
// UnsupervisedFit::p300_uv says); none without a direction.
std::optional<double> alongP300(const Problem& pr, const std::vector<int>& choice,
                                const Eigen::VectorXd& direction) {
  if (!hasDirection(pr, direction)) return std::nullopt;
  Eigen::RowVectorXd target = Eigen::RowVectorXd::Zero(pr.x.cols());
  Eigen::RowVectorXd other = target;
  int targets = 0, others = 0;
  for (size_t k = 0; k < pr.rows.size(); ++k) {
    const auto& codes = pr.codes_of[static_cast<size_t>(choice[k])];
    for (int r : pr.rows[k]) {
      const bool is_target =
          std::find(codes.begin(), codes.end(), pr.code[static_cast<size_t>(r)]) != codes.end();
      (is_target ? target : other) += pr.x.row(r);
      (is_target ? targets : others) += 1;
    }
  }
  if (targets == 0 || others == 0) return std::nullopt;
  return (target / targets - other / others).dot(direction.transpose()) / direction.squaredNorm();
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
    const auto given = options.known.find(s);
    pr.known.push_back(given == options.known.end() ? -1 : given->second);
  }
  const Eigen::RowVectorXd mean = pr.x.colwise().mean();
  pr.x.rowwise() -= mean;
  // The covariance of all epochs: no label needed.
  double shrinkage = 0.0;
  const Eigen::LDLT<Eigen::MatrixXd> covariance = ledoitWolfCovariance(pr.x, shrinkage).ldlt();
  std::mt19937_64 random(options.seed);
  // A start from the textbook P300 (known before any data): with few selections most random
  // starts settle on a labelling of noise or the mirror, and this one starts near the response.
  const bool has_template = hasDirection(pr, options.p300_direction);
  const auto starting = [&](const Problem& problem) {
    std::vector<Start> out;
    for (int r = 0; r < options.restarts; ++r)
      out.push_back(runStart(problem, covariance, random, options.max_iterations));
    if (has_template)
      out.push_back(runStart(problem, covariance, random, options.max_iterations, nullptr,
                             &options.p300_direction));
    return out;
  };
  std::vector<Start> starts = starting(pr);
  // The most likely start: the labels that explain most of the data's variance. A start may settle
  // on the mirror solution (each selection's least P300-like stimulus as its target), a fixed
  // point too, but one that explains less.
  const auto best = [](const std::vector<Start>& all) -> const Start& {
    return *std::max_element(all.begin(), all.end(), [](const Start& a, const Start& b) {
      return a.explained < b.explained;
    });
  };
  // A start from the decoding given (an earlier fit's): a solution found before is not lost to
  // the random starts of this fit.
  std::vector<int> initial(selections.size(), -1);
  bool warm = false;
  for (size_t k = 0; k < selections.size(); ++k) {
    const auto given = options.initial.find(selections[k]);
    if (given == options.initial.end()) continue;
    initial[k] = given->second;
    warm = true;
  }
  if (warm) starts.push_back(runStart(pr, covariance, random, options.max_iterations, &initial));
  // The leave-one-out consistency of a decoding: each selection left out, the rest fitted again
  // from new starts, and the left-out one decoded by that fit. The P300 generalises from selection
  // to selection, so a fit that found it finds it again without any one selection, and decodes
  // that one as the whole fit does; a labelling of noise (with few selections and many features,
  // any labelling explains some variance) is not found again, and agrees by chance.
  const auto positive = [&](const Problem& problem, const Start& start) {
    const auto along = alongP300(problem, start.choice, options.p300_direction);
    return !along || *along > 0.0;
  };
  const auto heldOut = [&](const Start& start) {
    int same = 0;
    for (size_t s = 0; s < pr.rows.size(); ++s) {
      const Problem rest = without(pr, s);
      const std::vector<Start> again = starting(rest);
      std::vector<Start> admissible;
      for (const Start& refit : again)
        if (positive(rest, refit)) admissible.push_back(refit);
      same += decode(pr, s, best(admissible.empty() ? again : admissible).w) == start.choice[s];
    }
    return static_cast<double>(same) / static_cast<double>(pr.rows.size());
  };
  // The candidates: the most likely starts (the labels that explain most of the data's variance)
  // and the warm one. With the leave-one-out measures, the one that generalises best is kept (the
  // most likely of those alike): the mirror solution (each selection's least P300-like stimulus as
  // its target) or a labelling of noise can explain much variance, but neither generalises.
  std::vector<size_t> order(starts.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return starts[a].explained > starts[b].explained; });
  std::vector<size_t> candidates;
  const size_t wanted = options.held_out && pr.rows.size() >= 2 ? kCandidates : 1;
  for (size_t i : order) {
    if (candidates.size() >= wanted) break;
    const bool seen = std::any_of(candidates.begin(), candidates.end(),
                                  [&](size_t c) { return starts[c].choice == starts[i].choice; });
    if (!seen) candidates.push_back(i);
  }
  // The warm start and the template's are candidates too, however much they explain.
  const auto offer = [&](size_t i) {
    if (options.held_out && pr.rows.size() >= 2 &&
        std::none_of(candidates.begin(), candidates.end(),
                     [&](size_t c) { return starts[c].choice == starts[i].choice; }))
      candidates.push_back(i);
  };
  if (has_template) offer(static_cast<size_t>(options.restarts));
  if (warm) offer(starts.size() - 1);
  size_t keep = candidates.front();
  double kept_consistency = 0.0;
  if (options.held_out && pr.rows.size() >= 2) {
    // A candidate whose response is a positive P300 (along the template, known before any data)
    // before one that is its mirror, however consistent: the mirror is never trusted, and kept it
    // would be the next fit's warm start, holding the fits on it selection after selection.
    // Among the positive ones (or among mirrors, when no candidate is positive), the most
    // consistent.
    bool kept_positive = false;
    kept_consistency = -1.0;
    for (size_t c : candidates) {
      const double measured = heldOut(starts[c]);
      const bool is_positive = positive(pr, starts[c]);
      if (std::pair(is_positive, measured) > std::pair(kept_positive, kept_consistency)) {
        kept_positive = is_positive;
        kept_consistency = measured;
        keep = c;
      }
    }
  }
  const Start& kept = starts[keep];
  UnsupervisedFit fit;
  fit.selections = selections;
  fit.restarts = static_cast<int>(starts.size());
  // Two decodings of many selections may differ on a doubtful one or two and still be one
  // solution: those that differ on at most a tenth of the selections count as agreeing.
  const auto tolerance = static_cast<long>(kept.choice.size() / 10);
  for (const Start& s : starts) {
    long differ = 0;
    for (size_t k = 0; k < s.choice.size(); ++k) differ += s.choice[k] != kept.choice[k];
    fit.agreeing += differ <= tolerance;
  }
  fit.choice = kept.choice;
  fit.posterior = kept.posterior;
  fit.weights = kept.w;
  fit.iterations = kept.iterations;
  fit.consistency = kept_consistency;
  fit.p300_uv = alongP300(pr, kept.choice, options.p300_direction);
  fit.explained = kept.explained;
  if (options.shuffles > 0) {
    // The same fit with each selection's codes shuffled among its epochs: a response that repeats
    // with its stimulus's flashes is gone, what the fit explains of noise alone is left.
    for (int k = 0; k < options.shuffles; ++k) {
      Problem shuffled = pr;
      for (const auto& rows : pr.rows) {
        std::vector<int> codes;
        for (int r : rows) codes.push_back(pr.code[static_cast<size_t>(r)]);
        std::shuffle(codes.begin(), codes.end(), random);
        for (size_t i = 0; i < rows.size(); ++i)
          shuffled.code[static_cast<size_t>(rows[i])] = codes[i];
      }
      const double explained = best(starting(shuffled)).explained;
      fit.shuffled_explained = std::max(fit.shuffled_explained, explained);
      fit.beats_shuffled += kept.explained > explained;
    }
  }
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
         online.agreeing, online.consistency});
  }
  if (!report.labelled || selections < 2) return report;
  std::vector<double> scores;
  std::vector<bool> target;
  for (int k = 0; k < selections; ++k) {
    std::vector<int> others;
    for (int i = 0; i < selections; ++i)
      if (i != k) others.push_back(i);
    UnsupervisedOptions plain = options;
    plain.held_out = false;  // its weights only
    plain.shuffles = 0;
    const UnsupervisedFit fit = fitWithoutLabels(data, others, plain);
    for (int e : data.selections[static_cast<size_t>(k)].epochs) {
      scores.push_back(data.features.row(e).dot(fit.weights));
      target.push_back(data.target[static_cast<size_t>(e)]);
    }
  }
  report.cross_validated_auc = areaUnderCurve(scores, target);
  return report;
}

}  // namespace arbci::bci
