#pragma once

#include <rotorfit/eigen/damped_eigensolver.h>

#include <complex>
#include <fstream>
#include <string>
#include <vector>

namespace rotorfit
{
  /// An elastic whirl mode at one speed, as the Campbell diagram sees it.
  struct WhirlMode
  {
    std::complex<double> lambda; ///< [rad/s], Im >= 0
    double               backward_error = 0;
    std::string          whirl; ///< forward, backward, mixed, non-lateral
    double               whirl_ratio = 0; ///< -1 (backward) .. +1 (forward)
    ComplexVector        phi, m_phi;      ///< shape and M * shape (for MAC)
    unsigned int         tracked_id = 0;  ///< set by Campbell::add_speed

    double
    frequency_hz() const
    {
      return lambda.imag() / (2 * M_PI);
    }
  };

  /**
   * Campbell diagram bookkeeping (THEORY 9): tracks modes from speed to
   * speed with the mass-weighted complex MAC (forward and backward members of
   * a family are M-orthogonal, so they are never confused), writes
   * campbell.csv row by row and finds the critical speeds where a tracked
   * line crosses an excitation order k X (linear interpolation between
   * speeds) into critical_speeds.csv.
   */
  class Campbell
  {
  public:
    void
    open(const std::string              &directory,
         const bool                      root,
         const std::vector<unsigned int> &orders,
         const double                    mac_threshold);

    /// Assign tracked ids to @p modes, write their rows and any crossings.
    /// @p static_converged and @p asymmetry describe the static state the
    /// modes rest on (ContactSolver::State); every row carries them.
    void
    add_speed(const double             rpm,
              std::vector<WhirlMode>  &modes,
              const std::string       &fit_state,
              const bool               static_converged,
              const double             asymmetry);

    unsigned int
    n_critical_speeds() const
    {
      return n_critical;
    }

    /// Complex MAC with the mass matrix: |a^H M b|^2 / (a^H M a  b^H M b).
    static double
    mac(const ComplexVector &a, const ComplexVector &m_a,
        const ComplexVector &b, const ComplexVector &m_b);

  private:
    struct Track
    {
      unsigned int  id;
      double        frequency_hz;
      std::string   whirl;
      ComplexVector phi, m_phi;
    };

    std::vector<Track>        previous;
    double                    previous_rpm = 0;
    unsigned int              next_id      = 1;
    unsigned int              n_critical   = 0;
    std::vector<unsigned int> orders;
    double                    threshold = 0.8;
    bool                      root      = false;
    std::ofstream             campbell_csv, critical_csv;
  };
} // namespace rotorfit
