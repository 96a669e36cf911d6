#pragma once

#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/rotor_matrices.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/timer.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <optional>
#include <vector>

namespace rotorfit
{
  /**
   * The operators of the eigenproblem at one speed (doc/theory.md 3, 4, 7.4,
   * 7.8): the speed-independent M, K, G, K_theta, the stress stiffness
   * K + K_sigma of the static state, the contact ties, the bearing
   * matrices, and from them the tangent K_t and the damping C = C_b + Omega G
   * of the speed, with what they were made for. Within one contact segment
   * (the same ties, K_sigma parts and bearing coefficients) a new speed moves
   * the tangent and the damping by the speed's affine share alone.
   *
   * Parameters: set by PrestressedEigenproblem from subsection
   * "Eigenproblem" (Settings).
   */
  class SpeedTangent
  {
  public:
    enum class ContactModel
    {
      bonded,
      frictionless,
      fixed,
      frozen
    };
    enum class StressStiffening
    {
      off,
      interference,
      full
    };

    /// The model entries of subsection "Eigenproblem" the operators follow.
    struct Settings
    {
      ContactModel     contact_model   = ContactModel::bonded;
      double           contact_scale   = 1000;
      StressStiffening stiffening      = StressStiffening::full;
      bool             convective_term = true;
      /// the static problem's spin softening
      bool static_spin_softening = false;
    };

    /// The operators of @p model with its @p bearings.
    SpeedTangent(const Discretization &model, const Bearings &bearings, dealii::TimerOutput &timer);

    /// Set by PrestressedEigenproblem::parse_parameters().
    Settings settings;

    /// The sparsity patterns of every matrix (after Bearings::setup()).
    void
    setup();

    /// M, K, G, K_theta; @p before_fold sees K_theta before it is folded
    /// into K_sigma(u_C) and freed (the self-check's energies).
    template <typename BeforeFold>
    void
    assemble_speed_independent(const BeforeFold &before_fold)
    {
      assemble_matrices();
      before_fold(matrices);
      if (convective_folded)
        matrices.convective.clear();
    }

    /// The pairs tied in the eigenproblem at @p state (the contact model).
    std::vector<bool>
    tied_pairs(const StaticState &state);

    /// K_t and C of @p state with the ties @p tied; @p first_speed: the
    /// bearing matrices are assembled even if they do not change with speed.
    void
    assemble(const StaticState &state, const std::vector<bool> &tied, const bool first_speed);

    /// Pair @p i's tie spring in the eigenproblem (doc/theory.md 7.4).
    double
    tie_spring(const StaticState &state, const unsigned int i) const
    {
      return state.pair_penalty(i) * (settings.contact_scale / state.penalty_scale());
    }

    /// K_theta lives in k_sigma_C (K_t2 = K_sigma(u_C) - K_theta in one
    /// matrix) and the convective matrix is freed: every static state is
    /// affine (no spin softening) and stress stiffening is full.
    bool
    folded() const
    {
      return convective_folded;
    }

    /// Whether the speeds of the current segment differ only by their affine
    /// share that speed_share() applies (K_theta folded away or absent).
    bool
    affine_segment() const;
    /// G X and K_t2 X for the columns @p x (the speed's affine share).
    void
    speed_share(const std::vector<const dealii::Vector<double> *> &x,
                std::vector<dealii::Vector<double>>               &gx,
                std::vector<dealii::Vector<double>>               &k2x) const;
    /// K_t2 X = (K_sigma(u_C) - K_theta) X where stress stiffening is full
    /// (@p k2 left empty otherwise).
    void
    stiffening_share(const std::vector<const dealii::Vector<double> *> &x,
                     std::vector<dealii::Vector<double>>               &k2) const;

    /// The model's communicator.
    MPI_Comm
    communicator() const
    {
      return comm;
    }

    /// Stress stiffening moves with the speed (K_t2 != 0: full stiffening).
    bool
    stiffening_moves() const
    {
      return settings.stiffening == StressStiffening::full;
    }

    /// M, K + K_sigma, G, K_theta (K_theta empty where folded()).
    const RotorMatrices &
    speed_independent() const
    {
      return matrices;
    }
    /// M
    const dealii::PETScWrappers::MPI::SparseMatrix &
    mass() const
    {
      return matrices.mass;
    }
    /// K_t of the speed (the factorisations borrow its storage)
    dealii::PETScWrappers::MPI::SparseMatrix &
    stiffness()
    {
      return tangent;
    }
    const dealii::PETScWrappers::MPI::SparseMatrix &
    stiffness() const
    {
      return tangent;
    }
    /// C = C_b + Omega G of the speed
    const dealii::PETScWrappers::MPI::SparseMatrix &
    damping() const
    {
      return damping_matrix;
    }
    /// C_b of the bearings
    const dealii::PETScWrappers::MPI::SparseMatrix &
    bearing_damping() const
    {
      return bearing_c;
    }
    /// K_sigma(u_C) (- K_theta where folded)
    const dealii::PETScWrappers::MPI::SparseMatrix &
    centrifugal_stiffness() const
    {
      return k_sigma_C;
    }

    /// The static decomposition whose K_sigma the stiffness holds (the
    /// static room's serial of an affine law; 0: none or not affine).
    unsigned int
    k_sigma_serial() const
    {
      return stiffened_serial;
    }
    /// Assemblies of the tangent so far (the matrix changes in place).
    unsigned int
    serial() const
    {
      return tangent_serial;
    }
    /// Full assemblies of the tangent (contact segments) so far.
    unsigned int
    segment() const
    {
      return segment_serial;
    }

  private:
    void
    assemble_matrices();
    void
    update_stiffness(const StaticState &state);
    void
    add_contact_ties(const StaticState &state, const std::vector<bool> &tied);
    void
    reinit_bearing_matrices();

    const Discretization &model;
    const Bearings       &bearings;
    dealii::TimerOutput  &timer;
    MPI_Comm              comm;

    bool          convective_folded = false;
    RotorMatrices matrices;
    /// (the factorisations take the tangent's storage: no matrix of their own)
    dealii::PETScWrappers::MPI::SparseMatrix bearing_k, bearing_c, k_sigma_C, tangent,
      damping_matrix;
    /// the displacement whose K_sigma matrices.stiffness holds (empty: none)
    dealii::Vector<double> stiffened_by;
    unsigned int           stiffened_serial = 0;

    /// what the tangent and damping matrices hold: the ties, w = Omega^2
    /// and Omega they were made for (empty before the first assembly)
    struct MadeFor
    {
      std::vector<bool> tied;
      double            w = 0, omega = 0;
    };
    std::optional<MadeFor> made_for;
    /// A count, not a key: the tangent is changed in place by the affine
    /// share, and an LDL^T of S is matched with the tangent it was made of.
    unsigned int tangent_serial = 0;
    /// SpeedOperators::segment names a segment by this number.
    unsigned int segment_serial = 0;

    std::vector<bool> frozen_active;
  };
} // namespace rotorfit
