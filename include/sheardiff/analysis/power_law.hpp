#pragma once
#include <vector>

namespace sheardiff {

// Ordinary least-squares line y = intercept + slope x with the textbook standard errors
// (residual variance s^2 = SSR / (n - 2)). Shared by the power-law and diffusion fits.
// Throws std::invalid_argument for n < 3, mismatched sizes, non-finite values or constant x.
struct LineFit {
  double intercept = 0, slope = 0, intercept_stderr = 0, slope_stderr = 0;
  double ssr = 0;  // residual sum of squares
  double r2 = 0;
  long n = 0;
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

// g = a x^b fitted in log-log space (seed Appendix B): OLS of log g on log x. se_b is the slope's
// standard error; a's is propagated from the intercept's, se_a = a * se_log_a. r2 is that of the
// log-log fit. Throws std::invalid_argument for n < 3, mismatched sizes, x <= 0 or g <= 0.
struct PowerLawFit {
  double a = 0, b = 0, a_stderr = 0, b_stderr = 0;
  long n = 0;
  double r2 = 0;
};
PowerLawFit fit_power_law(const std::vector<double>& x, const std::vector<double>& g);

// phi(x) = phi_c - a x^b by the seed's Appendix B procedure:
//  (1) phi_c minimises the residual of the log-log line fit of phi_c - phi against x, searched in
//      (max(phi), max(phi) + 0.5] (log-spaced grid in phi_c - max(phi), then golden section);
//  (2) with phi_c fixed, law = fit_power_law(x, phi_c - phi);
//  (3) with a, b fixed, the least-squares phi_c (mean of phi + a x^b); phi_c_err is its
//      distance to the value of (1).
// law's standard errors are the seed's: conditional on phi_c, they ignore that phi_c was tuned
// to the same data and underestimate the scatter of a and b several-fold. Steps (1)+(2) are the
// joint least-squares minimum of the log-space residual over (phi_c, log a, b), so the *_joint
// errors come from that fit's linearised covariance s^2 (J^T J)^-1, s^2 = SSR / (n - 3); use
// them for error bars. phi_c_err (seed step 3) is typically far smaller than phi_c_stderr.
// Needs at least 4 points: with 3, three parameters interpolate exactly and every error is 0.
struct DilatancyFit {
  double phi_c = 0, phi_c_err = 0;
  PowerLawFit law;
  double phi_c_stderr = 0, a_stderr_joint = 0, b_stderr_joint = 0;
};
DilatancyFit fit_dilatancy(const std::vector<double>& x, const std::vector<double>& phi);

}  // namespace sheardiff
