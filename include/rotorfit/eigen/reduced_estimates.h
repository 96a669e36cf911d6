#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/reduced_basis.h>
#include <rotorfit/eigen/reduced_model.h>
#include <rotorfit/eigen/speed_tangent.h>

#include <deal.II/lac/full_matrix.h>

#include <complex>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * The error estimates of a reduced speed's eigenvalues (doc/theory.md
   * 8.6), from the right and left residuals of its modes in the S^-1 norm of
   * the latest factorisation: by back-substitution, or from the Gram matrix
   * of the residual blocks (the kept products A V) where the basis serves
   * many speeds.
   */
  class ReducedEstimates
  {
  public:
    /// The estimates on @p reduced with the latest factorisation of
    /// @p eigensolver.
    ReducedEstimates(ReducedModel            &reduced,
                     const SpeedTangent      &operators,
                     const DampedEigensolver &eigensolver,
                     const Bearings          &bearings,
                     Log                     &log);

    /// The residual blocks' Gram matrix in the S^-1 norm of the latest
    /// factorisation (replicated_inverse_gram): the error estimates of a
    /// basis that serves many speeds without a back-substitution per speed.
    /// Built for a lasting anchor's basis at once, for another once its
    /// estimates have cost as many back-substituted columns as the Gram
    /// matrix does.
    struct ResidualGram
    {
      std::vector<double>           g;
      std::vector<const RowBlock *> blocks; ///< ReducedModel::residual_blocks()
      /// basis version, K_sigma decomposition, tangent and bearing speeds,
      /// operators of the linear solver: what it was made for (the basis's
      /// version: the Gram matrix lives apart from the basis and is matched
      /// with it by value)
      std::optional<std::tuple<unsigned int, unsigned int, double, double, unsigned int>> key;
      unsigned int spent   = 0;     ///< columns back-substituted for estimates on this key
      bool         refused = false; ///< disagreed with the back-substitutions
      bool         checked = false; ///< compared with them (once, at its first speed)
      double       seconds = 0;
      /// B^T B of the same blocks B: the right residuals' norms of a
      /// speed's modes without their n-long vectors (made with g, checked
      /// once against the vectors at its first speed)
      std::vector<double> e;
      bool                e_checked = false, e_refused = false;
    };
    /// The Gram matrices of the current key.
    const ResidualGram &
    gram() const
    {
      return residual_gram;
    }

    /// The Gram matrix for the current basis, tangent and factorisation:
    /// made where @p due (the estimates have cost as many back-substituted
    /// columns) or the basis is a lasting anchor's. Called by a reduced
    /// solve before it expands its modes, so that the block solves and the
    /// mode vectors are not held at once.
    void
    prepare_gram(bool due);

    /// Estimated relative errors of reduced modes' eigenvalues, from their
    /// residuals (of the vectors V y / scale; null where the reduced solve
    /// made none: then made here if back-substituted) and the reduced
    /// damping matrix @p Cr of the speed @p rpm.
    std::vector<double>
    estimates(const BackwardError                           &backward_error,
              const std::vector<const EigenPair *>          &modes,
              const std::vector<const ReducedBasis::Pair *> &dense,
              const std::vector<double>                     &scale,
              const std::vector<const ComplexVector *>      &residual,
              const dealii::FullMatrix<double>              &Cr,
              const double                                   omega,
              const double                                   w,
              const double                                   rpm);

    /// The first comparison of the residual norms from ResidualGram::e with
    /// the vectors' (largest relative difference @p difference).
    void
    check_residual_norms(const double difference);

    /// The undamped anchor's S = K_t + sigma^2 M is factorised: operators
    /// of the linear solver and tangent assembly (SpeedTangent::serial()),
    /// or none (S of another tangent plus the ties). Where both name the
    /// tangent of the projections, S^-1 K_t V = V - sigma^2 S^-1 M V spares
    /// the Gram matrix a fifth of its columns.
    void
    set_undamped_factor(const std::optional<std::pair<unsigned int, unsigned int>> &factor)
    {
      undamped_factor = factor;
    }

    /// How far a new Gram matrix's estimates may stray from the
    /// back-substituted ones: relative, or by gram_floor (its rounding
    /// floor, with a margin) where they are smaller; used where the
    /// tolerance is 10 x the floor.
    static constexpr double gram_agreement = 1e-2, gram_floor = 1e-10;

    /// Gram matrices checked against back-substitutions, and the largest
    /// relative difference of their estimates
    unsigned int builds = 0;
    double       worst_difference = 0;
    /// largest relative difference of residual norms from ResidualGram::e
    /// against the vectors' (at each such matrix's first speed)
    double norms_worst_difference = 0;
    /// reduced solves whose residual norms came from ResidualGram::e alone
    unsigned int norm_speeds = 0;

  private:
    /// y^H Q'(lambda) phi / |lambda| of each mode, on the basis
    std::vector<double>
    denominators(const std::vector<const EigenPair *>          &modes,
                 const std::vector<const ReducedBasis::Pair *> &dense,
                 const std::vector<double>                     &scale,
                 const dealii::FullMatrix<double>              &Cr) const;
    /// Whether the left residuals come from the kept products (decided on
    /// the sum @p sum of the left vectors).
    bool
    transposed_kept(const BackwardError                     &backward_error,
                    const std::vector<std::complex<double>> &sum,
                    const double                             omega,
                    const double                             w,
                    const double                             rpm);
    /// The left residuals from the sparse transposed products.
    std::vector<ComplexVector>
    sparse_left_residuals(const std::vector<std::vector<std::complex<double>>> &left,
                          const std::vector<const EigenPair *>                 &modes,
                          const double                                          omega,
                          const double                                          w) const;
    /// The estimates from the Gram matrix.
    std::vector<double>
    from_gram(const std::vector<const EigenPair *>          &modes,
              const std::vector<const ReducedBasis::Pair *> &dense,
              const std::vector<double>                     &scale,
              const std::vector<double>                     &denominator,
              const double                                   omega,
              const double                                   w) const;
    /// The estimates by back-substitution of both residuals.
    void
    back_substitute(const std::vector<const ComplexVector *> &right,
                    const std::vector<ComplexVector>         &s,
                    const std::vector<double>                &denominator,
                    std::vector<double>                      &estimate) const;
    /// A new Gram matrix against the back-substituted estimates (once).
    void
    check_gram(const std::vector<double> &gram_estimate, const std::vector<double> &estimate);

    ReducedModel            &reduced;
    const SpeedTangent      &operators;
    const DampedEigensolver &eigensolver;
    const Bearings          &bearings;
    Log                     &log;

    ResidualGram residual_gram;
    std::optional<std::pair<unsigned int, unsigned int>> undamped_factor;
  };
} // namespace rotorfit
