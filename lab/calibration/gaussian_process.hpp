#pragma once
// Gaussian-process regression (C. E. Rasmussen and C. K. I. Williams, Gaussian Processes for
// Machine Learning, MIT Press 2006): the surrogate of each calibration target. Inputs are
// points of the unit cube (the free parameters scaled to their bounds), the kernel is
// Matern 5/2 with one length per input (ARD: a long length is an input the target hardly
// depends on), the mean a constant, and each observation has its own noise variance (the
// seed scatter of its mean, known) plus a fitted nugget (what the seeds' scatter does not
// explain: a sample's roughness in the parameters).

#include <Eigen/Dense>
#include <vector>

namespace rocklab::calibration {

using Point = std::vector<double>;

struct Hyperparameters {
  double signal = 1.0;         // the kernel's standard deviation, in y's units
  std::vector<double> length;  // one per input, in the unit cube's
  double nugget = 1e-6;        // variance added to every observation's, in y's units squared
};

struct Prediction {
  double mean = 0.0;
  double variance = 0.0;  // of the latent function (without the observations' noise)
};

class GaussianProcess {
 public:
  // Fits the hyperparameters (maximum marginal likelihood, several starts) and conditions on
  // the observations. `noise` is each y's known variance. Needs one observation at least.
  void fit(const std::vector<Point>& x, const std::vector<double>& y,
           const std::vector<double>& noise);
  // Conditions on observations with given hyperparameters (the optimiser's fantasies).
  void condition(const std::vector<Point>& x, const std::vector<double>& y,
                 const std::vector<double>& noise, const Hyperparameters& h);

  Prediction predict(const Point& u) const;
  const Hyperparameters& hyperparameters() const { return h_; }
  // log p(y | x, h): what the fit maximises (R&W eq. 2.30).
  double logMarginalLikelihood() const { return log_ml_; }

 private:
  double kernel(const Point& a, const Point& b) const;
  bool factor();  // false when the covariance is not positive definite

  std::vector<Point> x_;
  Eigen::VectorXd y_, noise_, alpha_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  Hyperparameters h_;
  double mean_ = 0.0, log_ml_ = 0.0;
};

}  // namespace rocklab::calibration
