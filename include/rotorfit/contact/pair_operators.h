#pragma once

#include <rotorfit/contact/contact_pairs.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/vector.h>

#include <petscsys.h>

#include <utility>
#include <vector>

namespace rotorfit
{
  /// Throw std::runtime_error naming the PETSc call @p what if @p code is an error.
  void
  check_petsc(const PetscErrorCode code, const char *what);

  /**
   * Sum @p values over the ranks of @p comm, bitwise identical on every
   * rank (an allreduce need not be): the active-set decisions and the
   * choice between update and factorisation must never differ between
   * ranks.
   */
  void
  sum_replicated(std::vector<double> &values, const MPI_Comm comm);

  /**
   * The pair operator B of the static system (doc/theory.md 7): each pair's
   * vector b_i (+n on the hub node, -n on the shaft node) condensed by the
   * static constraints, b~ = C^T b, so that g_i = b~_i . u - delta_i on the
   * unconstrained DoFs; and each pair's penalty eps_i. Replicated: identical
   * on every rank.
   */
  class PairOperators
  {
  public:
    /// One entry of b~_i: a DoF and its coefficient.
    using Entry = std::pair<dealii::types::global_dof_index, double>;

    /// B and the penalties of @p pairs; @p stiffness_diagonal: the
    /// replicated diagonal of the unconstrained K; @p penalty_scale: alpha.
    void
    initialize(const ContactPairs                      &pairs,
               const dealii::AffineConstraints<double> &constraints,
               const dealii::Vector<double>            &stiffness_diagonal,
               const dealii::IndexSet                  &owned,
               const MPI_Comm                           comm,
               const double                             penalty_scale);

    /// Number of pairs.
    unsigned int
    size() const
    {
      return projection.size();
    }

    /// Penalty eps_i of pair @p i [N/m] (alpha times the mean radial
    /// diagonal stiffness of its two nodes).
    double
    penalty(const unsigned int i) const
    {
      return epsilon[i];
    }

    /// The rank that owns the shaft node's x DoF assembles the pair's spring.
    bool
    assembled_here(const unsigned int i) const
    {
      return owner_adds[i];
    }

    /// The nonzeros of b~_i.
    const std::vector<Entry> &
    entries(const unsigned int i) const
    {
      return projection[i];
    }

    /// @p dof is owned by this rank.
    bool
    owns(const dealii::types::global_dof_index dof) const
    {
      return dof >= first_owned && dof < end_owned;
    }

    /// Position of the owned @p dof in the local part of a vector.
    dealii::types::global_dof_index
    local(const dealii::types::global_dof_index dof) const
    {
      return dof - first_owned;
    }

    /// Number of DoFs owned by this rank.
    dealii::types::global_dof_index
    n_owned() const
    {
      return end_owned - first_owned;
    }

    /// B^T x for every pair (replicated on all ranks).
    std::vector<double>
    project(const dealii::PETScWrappers::MPI::Vector &x) const;

    /// rhs += sum_i f_i b~_i (locally owned rows only).
    void
    add_pair_forces(const std::vector<double> &f, dealii::PETScWrappers::MPI::Vector &rhs) const;

  private:
    /// eps_i and who assembles each pair.
    void
    make_penalties(const ContactPairs           &pairs,
                   const dealii::Vector<double> &stiffness_diagonal,
                   const dealii::IndexSet       &owned,
                   const double                  penalty_scale);

    /// b~_i of every pair.
    void
    make_projection(const ContactPairs &pairs, const dealii::AffineConstraints<double> &constraints);

    std::vector<double>             epsilon;
    std::vector<bool>               owner_adds;
    std::vector<std::vector<Entry>> projection;
    dealii::types::global_dof_index first_owned = 0, end_owned = 0;
    MPI_Comm                        comm        = MPI_COMM_SELF;
  };
} // namespace rotorfit
