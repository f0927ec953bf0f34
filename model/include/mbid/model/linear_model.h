#pragma once

#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

namespace mbid::model {

// The linearized equations of motion about a static equilibrium (method.md, eq. 1 with r = 0):
//   M q'' + D q' + C q = 0,   y = H q,
// with q the deviation of the generalized coordinates from the equilibrium (rad) and y the
// deviation of the outputs (rad). C includes the geometric (gravity) stiffness.
struct LinearModel {
  std::vector<std::string> coordinates;  // n names
  std::vector<std::string> outputs;      // m names
  Eigen::MatrixXd M;                     // n x n, kg*m^2
  Eigen::MatrixXd D;                     // n x n, N*m*s/rad
  Eigen::MatrixXd C;                     // n x n, N*m/rad
  Eigen::MatrixXd H;                     // m x n, rad/rad
  // Per output, the derivative of q that H maps: 0 (y = H q), 1 (y = H q'), 2 (y = H q'').
  // Empty means all 0.
  std::vector<int> output_orders;
  // Per coordinate "rad" or "m", per output its unit; empty means all "rad".
  std::vector<std::string> coordinate_units;
  std::vector<std::string> output_units;
};

// The unit of a stiffness ("N*m/rad", "N/m") or damping ("N*m*s/rad", "N*s/m") of one
// coordinate, and of a whole matrix of them ("SI, per coordinate" when the coordinates mix
// angles and lengths).
std::string StiffnessUnits(const std::string& coordinate_unit);
std::string DampingUnits(const std::string& coordinate_unit);
std::string StiffnessMatrixUnits(const std::vector<std::string>& coordinate_units);
std::string DampingMatrixUnits(const std::vector<std::string>& coordinate_units);

// One complex pole of the first-order system and its shape. For an underdamped pair only the
// member with Im(lambda) > 0 is kept.
struct Mode {
  std::complex<double> lambda;    // 1/s; decaying modes have Re(lambda) < 0
  Eigen::VectorXcd shape;         // per coordinate, unit largest magnitude
  Eigen::VectorXcd output_shape;  // H * shape, times lambda^order for rate outputs

  double frequency_hz() const;           // Im(lambda) / (2 pi), damped
  double decay_rate_per_s() const;       // -Re(lambda)
  double damping_ratio() const;          // -Re(lambda) / |lambda|
  double undamped_frequency_hz() const;  // |lambda| / (2 pi)
  double log_decrement() const;          // 2 pi decay / omega_d
  double half_life_s() const;            // ln 2 / decay
};

// The exact modes: eigenvalues of [0 I; -M^-1 C  -M^-1 D] by ascending damped frequency: the
// real (overdamped, free) poles, frequency 0, first by increasing decay, then the oscillatory
// ones (Im > 0).
std::vector<Mode> CalcModes(const LinearModel& linear);

// One line per mode that grows (Re(lambda) > 0): the machine is unstable at rest, and a test
// of it topples instead of decaying ("mode 1 grows at 2.31 1/s: the machine is unstable at rest
// (a spring weaker than gravity's overturning stiffness?)").
std::vector<std::string> FindGrowingModes(const std::vector<Mode>& modes);

// One line when the modes span so many orders of magnitude that double precision leaves the
// slowest with fewer than 6 digits (about eps omega_max^2 / omega_min^2 of itself): a joint
// given a stiffness 1e12 times the others' to make it rigid.
std::vector<std::string> FindImpreciseModes(const std::vector<Mode>& modes);

// What the two above say of `modes`: the warnings of a model's exact modes.
std::vector<std::string> FindModeDoubts(const std::vector<Mode>& modes);

}  // namespace mbid::model
