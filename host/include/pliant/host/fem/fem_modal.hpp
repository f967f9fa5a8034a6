// Modal analysis of a FemModel: natural frequencies and mode shapes of small vibrations.
//
// Solves the generalized symmetric eigenproblem K phi = omega^2 M phi over the DOFs of the nodes
// that are not fixed, with K the corotational tangent sum_e R_e K_e R_e^T at a configuration (the
// linear stiffness at the rest shape by default) and M the lumped (diagonal) mass. Because M is
// diagonal the problem is transformed to the standard one M^-1/2 K M^-1/2 y = omega^2 y and
// solved for the smallest eigenvalues with Spectra's shift-and-invert Lanczos, the shifted
// matrix factorized once by a sparse LDL^T. Damping does not enter (the undamped modes; with
// Rayleigh damping the mode shapes are the same and mode k has damping ratio
// rayleigh_alpha / (2 omega_k) + rayleigh_beta omega_k / 2).
//
// Units: omega in rad/s, frequency in Hz, mode shapes in m per sqrt(kg) (mass-normalised:
// phi^T M phi = 1). Host code: allocates, throws. Cost: one sparse factorization plus a few
// dozen solves; well under a second for 10^4 DOFs.
#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_model.hpp"

namespace pliant::host::fem {

struct FemModalOptions {
  int mode_count = 6;  ///< >= 1 and below the number of free DOFs
  /// Shift (rad^2/s^2) of the shift-and-invert transform; modes are found nearest to it. NaN:
  /// a tiny negative value, which finds the lowest modes, rigid-body modes of an unconstrained
  /// body included (they come out at ~0 Hz).
  double shift_rad2_s2 = std::numeric_limits<double>::quiet_NaN();
  int max_restarts = 1000;
  double tolerance = 1e-10;  ///< relative, on the Ritz values
};

struct FemModes {
  Eigen::VectorXd omega_rad_s;   ///< ascending, mode_count entries
  Eigen::VectorXd frequency_hz;  ///< omega / (2 pi)
  Eigen::MatrixXd shape;         ///< 3n x mode_count, mass-normalised; zero rows at fixed nodes
  int iterations = 0;            ///< Lanczos restarts used
};

/// Lowest modes with `fixed_nodes` clamped (any order, no repeats). position_m: configuration to
/// linearize about (3n) or empty for the rest shape. Throws std::invalid_argument on bad input and
/// std::runtime_error if the eigen solver does not converge.
FemModes modal_analysis(const FemModel& model, const std::vector<int>& fixed_nodes, const FemModalOptions& options = {},
                        const Eigen::Ref<const Eigen::VectorXd>& position_m = Eigen::VectorXd());

}  // namespace pliant::host::fem
