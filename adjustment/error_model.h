// The GNSS/INS error as a first-order Gauss-Markov process, seen through
// the control: at each matched crossing, the discrepancy between the
// database and the image-only position with the INS trajectory is the
// trajectory's error there plus the database's own error. From those
// discrepancies, per axis (along-track, cross-track, up):
//   - FitGaussMarkov: sigma and correlation time tau by maximum likelihood,
//       y ~ N(0, sigma^2 K(tau) + D),  K_ij = exp(-|t_i - t_j| / tau),
//     D the discrepancies' own variances (database, triangulation);
//   - PredictLeaveOneOut: what the others predict at one crossing, and the
//     standardised residual there (control_selection.h tests each crossing
//     with it).
// Units: metres, seconds.
#ifndef ZEBRAGEO_ADJUSTMENT_ERROR_MODEL_H_
#define ZEBRAGEO_ADJUSTMENT_ERROR_MODEL_H_

#include <string>
#include <vector>

namespace zebrageo {

// One axis' discrepancies: time, value, variance of the value.
struct ProcessSamples {
  std::vector<double> time_s;
  std::vector<double> value;
  std::vector<double> variance;

  int size() const { return static_cast<int>(time_s.size()); }
  void Add(double t, double y, double v) {
    time_s.push_back(t);
    value.push_back(y);
    variance.push_back(v);
  }
  // Without sample `i`.
  ProcessSamples Without(int i) const;
};

struct GaussMarkovFitOptions {
  double min_sigma = 0.03;
  double max_sigma = 5.0;
  // Used when tau is not estimated (too few samples), and as the centre of
  // a weak prior on log(tau) when it is (a few samples cannot tell 10 s
  // from 100 s on their own).
  double default_tau_s = 30.0;
  // Estimate tau only from at least this many samples.
  int min_samples_for_tau = 3;
  // The candidate correlation times.
  std::vector<double> tau_grid_s = {2.0,  5.0,   10.0,  20.0, 40.0,
                                    80.0, 160.0, 320.0, 640.0};

  std::string Check() const;
};

struct GaussMarkovFit {
  double sigma = 0.0;
  double tau_s = 0.0;
  double log_likelihood = 0.0;
  bool tau_estimated = false;
};

// Maximum-likelihood sigma (and tau, see the options) of the samples; with
// no sample, min_sigma and default_tau_s.
GaussMarkovFit FitGaussMarkov(const ProcessSamples& samples,
                              const GaussMarkovFitOptions& options);

// The process' prediction at sample `i` from the others (conditional mean),
// the variance of sample i's value about it (process + its own variance),
// and the standardised residual (value - mean) / sqrt(variance).
struct ProcessPrediction {
  double mean = 0.0;
  double variance = 0.0;
  double standardized = 0.0;
};
ProcessPrediction PredictLeaveOneOut(const ProcessSamples& samples, int i,
                                     const GaussMarkovFit& fit);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ERROR_MODEL_H_
