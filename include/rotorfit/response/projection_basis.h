#pragma once

#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/response/unbalance_response.h>

#include <deal.II/lac/vector.h>

#include <vector>

namespace rotorfit
{
  /// The Galerkin basis of the unbalance response (UnbalanceResponse::solve,
  /// doc/theory.md 13.2): the eigen reduced model's basis V_h of this speed
  /// (if it was solved on it: its projections are known) followed by
  /// explicit columns e, orthonormal and M-orthogonal to V_h, with their
  /// products by M, D, K.
  struct ProjectionBasis
  {
      const PrestressedEigenproblem::SpeedOperators &op;
      std::vector<dealii::Vector<double>> v, mv, dv, kv;
      /// the adopted columns' kept projections (adopt()) and the speed
      const UnbalanceResponse::KeptProducts *affine = nullptr;
      double                                 omega  = 0;
      /// W^T M W, W^T D W, W^T K W over W = [V_h e], grown with the basis
      std::vector<std::vector<double>> mr, dr, kr;

      unsigned int
      head() const;

      unsigned int
      size() const;

      /// Galerkin on the basis: U = W y with (A + i B) y = W^T f, A = W^T (K -
      /// w^2 M) W, B = w W^T D W, solved as the real block system
      /// [A -B; B A] [y_re; y_im] = [W^T f_re; W^T f_im]; @p r becomes the
      /// full-space residual f - (K - w^2 M + i w D) U.
      void
      solve(const ComplexVector &f,
            const double         w,
            const double         tolerance,
            ComplexVector       &u,
            ComplexVector       &r);

      /// [W^T g_re; W^T g_im].
      dealii::Vector<double>
      project_vector(const ComplexVector &g) const;

      /// u = W y and r = f - (K - w^2 M + i w D) u.
      void
      residual(const ComplexVector  &f,
               const double          w,
               const dealii::Vector<double> &y,
               ComplexVector        &u,
               ComplexVector        &r) const;

      /// Complete the reduced matrices for the columns added since the
      /// last call (only the new rows and columns are computed).
      void
      project();

      /// Take columns kept from an earlier speed on the same head (already
      /// M-orthonormal to it and each other, @p mx their M products); their
      /// products with this speed's D and K come from the affine share
      /// kept in @p p within its contact segment (checked every tenth
      /// speed), else afresh.
      void
      adopt(const std::vector<dealii::Vector<double>> &x,
            const std::vector<dealii::Vector<double>> &mx,
            UnbalanceResponse::KeptProducts   &p,
            const double                        omega);

      /// Orthogonalise the columns @p xs against the basis and each other
      /// (twice) and append those not in its span; true if any was. Their
      /// products with M, D, K are block products (one pass over a matrix
      /// for all of them: the real and imaginary parts of a correction).
      bool
      add(std::vector<dealii::Vector<double>> xs);

    private:
      /// add() on a head: the columns @p x (of 2-norms @p norm0, replaced by
      /// their M-norms) M-orthonormal to the head, the explicit columns and
      /// each other.
      void
      add_m_orthonormal(std::vector<dealii::Vector<double>> &x, std::vector<double> &norm0);
      /// add() without a head: orthonormal in the 2-norm, then their M
      /// products.
      void
      add_orthonormal(std::vector<dealii::Vector<double>> &x, const std::vector<double> &norm0);
      /// project(): the adopted columns from their kept projections.
      void
      project_adopted();
      /// project(): the head's rows and columns of the columns from @p first.
      void
      project_on_head(const std::size_t first);
      /// project(): the explicit columns' block from column @p first.
      void
      project_explicit(const std::size_t first);
  };
} // namespace rotorfit
