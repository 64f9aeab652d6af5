#include "adjustment/error_model.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

Eigen::MatrixXd Covariance(const ProcessSamples& s, double sigma,
                           double tau_s) {
  const int n = s.size();
  Eigen::MatrixXd C(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      C(i, j) = sigma * sigma *
                std::exp(-std::abs(s.time_s[i] - s.time_s[j]) / tau_s);
    }
    C(i, i) += s.variance[i];
  }
  return C;
}

// log N(y; 0, C), or -infinity when C is not positive definite.
double LogLikelihood(const ProcessSamples& s, double sigma, double tau_s) {
  const int n = s.size();
  const Eigen::LLT<Eigen::MatrixXd> llt(Covariance(s, sigma, tau_s));
  if (llt.info() != Eigen::Success) {
    return -std::numeric_limits<double>::infinity();
  }
  const Eigen::Map<const Eigen::VectorXd> y(s.value.data(), n);
  const Eigen::VectorXd w = llt.matrixL().solve(y);
  double log_det = 0.0;
  for (int i = 0; i < n; ++i) log_det += 2.0 * std::log(llt.matrixL()(i, i));
  return -0.5 * w.squaredNorm() - 0.5 * log_det - 0.5 * n * std::log(2.0 * kPi);
}

// The sigma in [min, max] of the largest likelihood at `tau_s`: golden
// section on log(sigma) (the likelihood is unimodal in sigma for a fixed
// correlation structure), then the bounds themselves.
GaussMarkovFit BestSigma(const ProcessSamples& s, double tau_s,
                         const GaussMarkovFitOptions& options) {
  double a = std::log(options.min_sigma);
  double b = std::log(options.max_sigma);
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  auto f = [&](double x) { return LogLikelihood(s, std::exp(x), tau_s); };
  double c = b - ratio * (b - a);
  double d = a + ratio * (b - a);
  double fc = f(c);
  double fd = f(d);
  for (int iteration = 0; iteration < 40 && b - a > 1e-3; ++iteration) {
    if (fc > fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - ratio * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + ratio * (b - a);
      fd = f(d);
    }
  }
  GaussMarkovFit fit;
  fit.tau_s = tau_s;
  fit.sigma = std::exp(0.5 * (a + b));
  fit.log_likelihood = f(0.5 * (a + b));
  for (double bound : {options.min_sigma, options.max_sigma}) {
    const double value = LogLikelihood(s, bound, tau_s);
    if (value > fit.log_likelihood) {
      fit.sigma = bound;
      fit.log_likelihood = value;
    }
  }
  return fit;
}

}  // namespace

ProcessSamples ProcessSamples::Without(int i) const {
  ProcessSamples out;
  for (int j = 0; j < size(); ++j) {
    if (j != i) out.Add(time_s[j], value[j], variance[j]);
  }
  return out;
}

std::string GaussMarkovFitOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, min_sigma, 0.0);
  OPTION_GE(check, max_sigma, min_sigma);
  OPTION_GT(check, default_tau_s, 0.0);
  check.Require(!tau_grid_s.empty(), "tau_grid_s", std::string("[]"),
                "must not be empty");
  for (double tau : tau_grid_s) {
    check.Require(tau > 0.0 && std::isfinite(tau), "tau_grid_s[]", tau,
                  "every tau must be > 0");
  }
  return check.problem();
}

GaussMarkovFit FitGaussMarkov(const ProcessSamples& samples,
                              const GaussMarkovFitOptions& options) {
  if (samples.size() == 0) {
    GaussMarkovFit fit;
    fit.sigma = options.min_sigma;
    fit.tau_s = options.default_tau_s;
    return fit;
  }
  if (samples.size() < options.min_samples_for_tau) {
    return BestSigma(samples, options.default_tau_s, options);
  }
  // A weak prior on log(tau) around the default (a factor of 4 is one
  // sigma): the likelihood of a few samples is flat in tau.
  const double spread = std::log(4.0);
  GaussMarkovFit best;
  double best_score = -std::numeric_limits<double>::infinity();
  for (double tau : options.tau_grid_s) {
    GaussMarkovFit fit = BestSigma(samples, tau, options);
    const double z = std::log(tau / options.default_tau_s) / spread;
    const double score = fit.log_likelihood - 0.5 * z * z;
    if (score > best_score) {
      best_score = score;
      best = fit;
    }
  }
  best.tau_estimated = true;
  return best;
}

ProcessPrediction PredictLeaveOneOut(const ProcessSamples& samples, int i,
                                     const GaussMarkovFit& fit) {
  ProcessPrediction prediction;
  const double prior = fit.sigma * fit.sigma;
  const ProcessSamples others = samples.Without(i);
  const int m = others.size();
  double conditional = prior;
  if (m > 0) {
    const Eigen::MatrixXd C = Covariance(others, fit.sigma, fit.tau_s);
    Eigen::VectorXd k(m);
    for (int j = 0; j < m; ++j) {
      k[j] = prior * std::exp(-std::abs(samples.time_s[i] - others.time_s[j]) /
                              fit.tau_s);
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(C);
    const Eigen::VectorXd alpha = ldlt.solve(k);
    const Eigen::Map<const Eigen::VectorXd> y(others.value.data(), m);
    prediction.mean = alpha.dot(y);
    conditional = std::max(0.0, prior - alpha.dot(k));
  }
  prediction.variance = conditional + samples.variance[i];
  prediction.standardized = (samples.value[i] - prediction.mean) /
                            std::sqrt(std::max(prediction.variance, 1e-12));
  return prediction;
}

}  // namespace zebrageo
