#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/eigen/mode_classifier.h>
#include <rotorfit/eigen/reduced_estimates.h>
#include <rotorfit/eigen/reduced_model.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/lac/full_matrix.h>

#include <chrono>
#include <complex>
#include <sstream>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * A speed solved on the reduced model (doc/theory.md 8.6): the projected
   * quadratic eigenproblem, its modes' vectors and residuals from the kept
   * products, and the checks that decide whether the speed is served: the
   * backward error on the full matrices, the products against the speed's
   * sparse matrices, the reach of modes outside the basis since the nearest
   * anchor, and the estimated eigenvalue error against the Reduced
   * tolerance. A speed that fails them needs a new anchor or the full solve.
   */
  class ReducedSolve
  {
  public:
    /// Speeds on @p reduced, checked with @p estimates.
    ReducedSolve(ReducedModel            &reduced,
                 ReducedEstimates        &estimates,
                 const SpeedTangent      &operators,
                 const DampedEigensolver &eigensolver,
                 const ModeClassifier    &classifier,
                 Log                     &log);

    /// The modes of @p state from the basis, @p nev eigenvalues nearest the
    /// shift, checked on the full matrices unless not @p checked (a
    /// root-solve trial: sorted, nothing checked); false (and @p why) if
    /// they do not pass and the speed needs the full solve. @p worst: the
    /// largest backward error of a speed served.
    bool
    solve(const StaticState       &state,
          const std::vector<bool> &loose_body,
          const unsigned int       nev,
          EigenSolution           &solution,
          std::string             &why,
          const bool               checked,
          double                  &worst);

    double       worst_estimate = 0; ///< largest error estimate of a reduced solve
    double       worst_products = 0; ///< largest product mismatch of a reduced solve
    unsigned int checks_skipped = 0; ///< product checks left out (ReducedModel::ProductCheck)

  private:
    using Clock = std::chrono::steady_clock;

    /// The projected problem of a speed and the eigenpairs picked from it.
    struct Dense
    {
      double                          omega = 0, w = 0;
      dealii::FullMatrix<double>      Kr, Cr;
      std::vector<ReducedBasis::Pair> all;
      std::vector<std::size_t>        picked; ///< the nev nearest the shift
      std::vector<std::vector<std::complex<double>>> y;
      std::vector<std::complex<double>>              lambda;
    };
    /// Their vectors V y / scale, M V y / scale and right residuals (or
    /// only the residuals' norms, from the Gram matrix).
    struct Expansion
    {
      std::vector<ComplexVector>        v, mv, residual;
      std::vector<double>               norm_r, scale;
      std::vector<bool>                 usable;
      std::vector<std::complex<double>> sum; ///< of the columns y / scale
      bool                              gram_norms = false;
    };

    bool
    solve_dense(const StaticState &state, const unsigned int nev, Dense &d, std::string &why) const;
    void
    expand(const Dense &d, const BackwardError &backward_error, const bool checked, Expansion &e);
    /// The residual vectors after all where a mode's norm from the Gram
    /// matrix lies near the Backward error limit.
    void
    residuals_near_limit(const Dense &d, const BackwardError &backward_error, Expansion &e);
    /// The kept products against this speed's matrices (or the last check).
    double
    check_products(const Dense         &d,
                   const Expansion     &e,
                   const BackwardError &backward_error,
                   const bool           checked,
                   const double         rpm,
                   bool                &checked_now,
                   std::ostringstream  &reason);
    /// The usable modes as eigenpairs (their backward errors where
    /// @p checked); returns the largest |lambda - sigma|.
    double
    make_pairs(Dense                  &d,
               Expansion              &e,
               const BackwardError    &backward_error,
               const bool              checked,
               std::vector<EigenPair> &pairs);
    /// Whether a mode outside the basis may have moved into the modes kept.
    void
    check_reach(const double omega, const double radius, std::ostringstream &reason) const;
    /// The wanted modes' eigenvalue error estimates; returns the largest.
    double
    estimate_errors(const Dense         &d,
                    const Expansion     &e,
                    const BackwardError &backward_error,
                    const double         rpm,
                    EigenSolution       &solution);
    void
    log_speed(const EigenSolution &solution,
              const double         worst,
              const double         estimate,
              const double         mismatch,
              const bool           checked_now,
              const double         t_projections,
              const double         t_modes,
              const double         t_estimate,
              const Clock::time_point t0) const;

    ReducedModel            &reduced;
    ReducedEstimates        &estimates;
    const SpeedTangent      &operators;
    const DampedEigensolver &eigensolver;
    const ModeClassifier    &classifier;
    Log                     &log;
  };
} // namespace rotorfit
