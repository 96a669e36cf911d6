#pragma once

#include <rotorfit/eigen/damped_eigensolver.h>

#include <complex>
#include <string>
#include <vector>

namespace rotorfit
{
  /// A rigid-body, loose-body or overdamped eigenvalue: a row of rigid_modes.csv.
  struct RigidMode
  {
    std::string          kind; ///< rigid, loose or overdamped
    std::string          body; ///< the loose body, or "assembly"
    std::complex<double> lambda; ///< [rad/s]
    double               backward_error = 0;
    int                  harmonic = -1; ///< axisymmetric model: its harmonic (3D: -1)
  };

  /**
   * The damped eigenproblem at one speed: the elastic eigenpairs (lowest
   * first, at most the number of modes asked), the eigenvalues set apart
   * as rigid, loose-body or overdamped, and the pairs the eigenproblem tied.
   */
  struct EigenSolution
  {
    double                 rpm   = 0;
    unsigned int           index = 0; ///< position in the speed list
    std::vector<EigenPair> elastic;
    std::vector<RigidMode> rigid;
    std::vector<bool>      tied; ///< per contact pair
    /// the bearings at this speed are isotropic, and so is the rotor about
    /// its axis (RevolutionCheck::transverse_inertia)
    bool isotropic_supports = true;
  };
} // namespace rotorfit
