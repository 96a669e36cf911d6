#pragma once

#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/reduced_basis.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/linear_algebra/row_block.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include <array>
#include <complex>
#include <optional>
#include <vector>

namespace rotorfit
{
  /**
   * The reduced model of the damped eigenproblem (doc/theory.md 8.6): the
   * basis V, the projections V^T A V of the speed's matrices and the kept
   * products A V they were made of, from which a reduced speed's mode
   * vectors, their products with the full matrices and their residuals come
   * without sparse products. The projections belong to the basis: every
   * change of the basis goes through this class and drops them; they are
   * made again where the tangent's segment or the bearing coefficients they
   * were made for change (update_projections()).
   */
  class ReducedModel
  {
  public:
    /// The reduced model of the speed's @p operators.
    ReducedModel(const SpeedTangent &operators, const Bearings &bearings);

    /// The basis and its settings.
    const ReducedBasis &
    basis() const
    {
      return reduced;
    }
    /// The basis's entries (ReducedBasis::parse_parameters()).
    void
    parse_parameters(dealii::ParameterHandler &prm)
    {
      reduced.parse_parameters(prm);
    }

    /// A new, empty basis.
    void
    clear();
    /// ReducedBasis::add(); the projections go where the basis grew.
    unsigned int
    add(const std::vector<const dealii::Vector<double> *> &x,
        const dealii::PETScWrappers::MPI::SparseMatrix    &M);
    /// The coverage of an anchor whose vectors were added.
    void
    add_anchor(const ReducedBasis::Anchor &anchor)
    {
      reduced.anchors.push_back(anchor);
    }
    /// Drop the anchors after the first @p n (their coverage claims).
    void
    keep_anchors(const std::size_t n)
    {
      if (reduced.anchors.size() > n)
        reduced.anchors.resize(n);
    }
    /// The basis as it is now is a lasting anchor's (its Gram matrix is
    /// built at once); a change of the basis ends that.
    void
    mark_lasting()
    {
      lasting_basis = true;
    }
    /// The basis is a lasting anchor's, unchanged since.
    bool
    lasting() const
    {
      return lasting_basis;
    }

    /// What a tangent or bearing projection was made for: the K_sigma
    /// decomposition (0: none) and the speed (-1: any speed of the segment).
    struct ProjectionKey
    {
      unsigned int k_sigma = 0;
      double       rpm     = -1;
      bool
      operator==(const ProjectionKey &o) const
      {
        return k_sigma == o.k_sigma && rpm == o.rpm;
      }
    };

    /// The projections of the matrices of this speed, made again where what
    /// they were made for changed.
    void
    update_projections(const StaticState &state);
    /// Free the products A V (before a factorisation: the memory peak); the
    /// projections are made again at the next reduced speed.
    void
    free_products();

    /// V^T X V of M, G, the tangent at w = 0 and its d/dw, bearing damping
    struct Projections
    {
      dealii::FullMatrix<double> mass, gyro, tangent0, tangent2, bearing_c;
      /// A V of the projections, the tangent's at w_tangent: a reduced
      /// speed's residuals and the response are made of them (C_b V by the
      /// bearings' rows alone)
      RowBlock av_mass, av_gyro, av_tangent, av_tangent2, av_bearing_c;
      double   w_tangent = 0;
      /// the tangent assembly (SpeedTangent::serial()) av_tangent was made of
      unsigned int tangent_serial = 0;
    };
    /// The projections of the latest update_projections().
    const Projections &
    projections() const
    {
      return p;
    }
    /// What the tangent projection was made for (empty: dropped).
    std::optional<ProjectionKey>
    tangent_key() const
    {
      return key_tangent;
    }
    /// What the bearing projection was made for (empty: dropped).
    std::optional<ProjectionKey>
    bearing_key() const
    {
      return key_bearing;
    }

    /// V y_c and M V y_c, C V y_c, K_t V y_c at @p omega, @p w = omega^2
    /// from the kept products (one dgemm per matrix for all columns); for
    /// @p transpose C_b - omega G and K_t, which are C^T and K_t^T where the
    /// bearings are symmetric.
    struct Expanded
    {
      std::vector<ComplexVector> v, m, c, k;
      /// how far the kept products of the sum of all columns are from the
      /// sparse ones (BackwardError::mismatch): one combination checks all
      double
      mismatch(const BackwardError &backward_error, bool transpose) const;
    };
    Expanded
    expanded(const std::vector<std::vector<std::complex<double>>> &y,
             const double                                          omega,
             const double                                          w,
             const bool                                            transpose) const;
    /// Q(lambda_c) V y_c for each column y_c, from the kept products (one
    /// dgemm per product for all columns); Q(lambda_c)^H V y_c with
    /// @p transpose, as expanded() makes it.
    std::vector<ComplexVector>
    residuals(const std::vector<std::vector<std::complex<double>>> &y,
              const std::vector<std::complex<double>>              &lambda,
              double                                                omega,
              double                                                w,
              bool                                                  transpose) const;
    /// The kept products A V whose columns span every residual of a reduced
    /// speed: M, C_b, G, K_t, K_t2, the dense ones first and those kept by
    /// their rows last (zero ones left out; the order of
    /// residual_coefficients() and of the Gram matrices).
    std::vector<const RowBlock *>
    residual_blocks() const;
    /// x with Q(lambda) V y = [A_1 V .. A_b V] x for @p blocks, those of
    /// residual_blocks() (the left residual Q(lambda)^H V y with @p transpose).
    std::vector<std::complex<double>>
    residual_coefficients(const std::vector<std::complex<double>> &y,
                          std::complex<double>                     lambda,
                          double                                   omega,
                          double                                   w,
                          bool                                     transpose,
                          const std::vector<const RowBlock *>     &blocks) const;
    /// (A V)^T X for A = M, C_b, G, K_t, K_t2 (SpeedOperators::row_parts).
    void
    row_parts(const std::vector<const dealii::Vector<double> *> &x,
              std::array<std::vector<double>, 5>                &parts) const;

    /// The kept products' check on a speed's sparse matrices: made at the
    /// first speed of each basis, projections and tangent segment, then
    /// every check_interval-th speed. Between, the sparse matrices and the
    /// kept products move by the same affine share of the speed, so the
    /// check would repeat the first one's rounding (a fifth of a reduced
    /// speed on TS: six sparse products).
    struct ProductCheck
    {
      ProjectionKey tangent, bearing;
      unsigned int  segment = 0, speeds = 0;
      double        mismatch = 0, rpm = 0;
      bool          transposed_known = false, transposed_kept = false;
      bool          due = false; ///< checked at this speed
    };
    static constexpr unsigned int check_interval = 10;
    /// How far the kept products (A V) y may stray from A (V y), relative.
    /// Rounding, amplified by the cancellation that penalty ties cause in
    /// K_t phi, reaches 6.7e-9 on the tutorial disk and 5e-10 on TS; a
    /// product kept from another speed or tied set errs by the speed's own
    /// share of the tangent or more (Omega^2 K_t2 phi: 1e-3 .. 1e-2 of
    /// K_t phi), a tangent 1e-4 off is refused.
    static constexpr double product_tolerance = 1e-6;
    /// true where this speed's products are to be checked (and the check
    /// moved on to this key)
    bool
    product_check_due(const double rpm);
    /// The check of the current basis (empty before its first).
    std::optional<ProductCheck> &
    product_check()
    {
      return check;
    }

    /// The reduced C and K_t of the latest speed, if it was solved reduced.
    void
    keep_speed(dealii::FullMatrix<double> &&Cr, dealii::FullMatrix<double> &&Kr)
    {
      speed_Cr = std::move(Cr);
      speed_Kr = std::move(Kr);
    }
    /// V^T C V of the latest reduced speed
    const dealii::FullMatrix<double> &
    speed_damping() const
    {
      return speed_Cr;
    }
    /// V^T K_t V of the latest reduced speed
    const dealii::FullMatrix<double> &
    speed_stiffness() const
    {
      return speed_Kr;
    }

  private:
    /// A change of the basis: its projections, products and their check go.
    void
    drop_projections();
    void
    project_tangent(const StaticState &state);

    const SpeedTangent &operators;
    const Bearings     &bearings;

    ReducedBasis reduced;
    bool         lasting_basis = false;
    Projections  p;
    /// the projections of M and G are of the current basis
    bool                         basis_projected = false;
    std::optional<ProjectionKey> key_tangent, key_bearing;
    std::optional<ProductCheck>  check;
    dealii::FullMatrix<double>   speed_Cr, speed_Kr;
  };
} // namespace rotorfit
