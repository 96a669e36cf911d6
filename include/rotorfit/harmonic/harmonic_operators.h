#pragma once

#include <rotorfit/bearing/bearings.h>
#include <rotorfit/contact/contact_solver.h>
#include <rotorfit/harmonic/harmonic_assembler.h>
#include <rotorfit/harmonic/harmonic_reduced_model.h>
#include <rotorfit/model/station.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/sparse_matrix.h>

#include <memory>
#include <vector>

namespace rotorfit
{
  /**
   * The matrices of every listed harmonic at a speed on a contact law
   * (doc/theory.md 14.4, 14.6), the harmonic model's counterpart of the 3D
   * SpeedTangent: the speed-independent M, K, G, K_theta of each harmonic,
   * K_sigma of the law's interference and centrifugal parts, and from them
   * the law's K_0 = K + K_sigma(u_I) + ties and K_2 = K_sigma(u_C) - K_theta
   * (made again where the law changes), the bearings' couplings on the
   * station directions, and a speed's K_t = K_0 + Omega^2 K_2 + K_b and
   * C = Omega G + C_b, in deal.II's form and PETSc's for the solvers.
   */
  class HarmonicOperators
  {
  public:
    /// The model entries the matrices follow (subsection "Eigenproblem").
    struct Settings
    {
      bool   prestress = true, centrifugal_prestress = true, convective = true;
      double tie_scale = 1000;
    };

    /// Assemble the harmonics @p list of @p assembler's meridian with the
    /// @p stations (bearings first) of @p bearings, on @p contact's pairs;
    /// @p stiffness_diagonal: the static stiffness' diagonal (tie penalties).
    HarmonicOperators(const HarmonicAssembler         &assembler,
                      const ContactSolver             &contact,
                      const Bearings                  &bearings,
                      const std::vector<unsigned int> &list,
                      const std::vector<Station>      &stations,
                      const dealii::Vector<double>    &stiffness_diagonal,
                      const Settings                  &settings,
                      const MPI_Comm                   comm);

    /// Harmonic @p k (index into the list).
    const HarmonicAssembler::Harmonic &
    harmonic(const unsigned int k) const
    {
      return matrices[k];
    }
    const std::vector<HarmonicAssembler::Harmonic> &
    harmonics() const
    {
      return matrices;
    }
    std::size_t
    size() const
    {
      return matrices.size();
    }

    /// K_0 and K_2 of harmonic @p k on @p state's law (made again where the
    /// law changed); returns the law's number (a new law, a new number).
    std::size_t
    law_matrices(const unsigned int k, const StaticState &state);

    /// The bearings' springs and dampers of harmonic @p k at @p rpm on its
    /// station directions.
    std::vector<HarmonicReducedModel::Coupling>
    bearing_couplings(const unsigned int k, const double rpm) const;

    /// Harmonic @p k's matrices on its current law, for the reduced model.
    HarmonicReducedModel::Operators
    law_operators(const unsigned int k) const;

    /// K_t and C of harmonic @p k at @p state.rpm on @p state's law, on the
    /// harmonic's pattern.
    void
    speed_matrices(const unsigned int            k,
                   const StaticState            &state,
                   dealii::SparseMatrix<double> &stiffness,
                   dealii::SparseMatrix<double> &damping);

    /// The same into the PETSc matrices stiffness() and damping() (the
    /// full solve's); returns the seconds it took.
    double
    assemble_speed(const unsigned int k, const StaticState &state);

    const dealii::PETScWrappers::MPI::SparseMatrix &
    mass(const unsigned int k) const
    {
      return petsc_m[k];
    }
    const dealii::PETScWrappers::MPI::SparseMatrix &
    damping(const unsigned int k) const
    {
      return petsc_c[k];
    }
    /// (non-const: a factorisation borrows its storage)
    dealii::PETScWrappers::MPI::SparseMatrix &
    stiffness(const unsigned int k)
    {
      return petsc_k[k];
    }
    const dealii::PETScWrappers::MPI::SparseMatrix &
    stiffness(const unsigned int k) const
    {
      return petsc_k[k];
    }

    /// K_sigma assemblies so far (two per harmonic and law).
    unsigned int
    prestress_assemblies() const
    {
      return n_prestress;
    }

  private:
    /// K_sigma of @p state's law (kept while the law is shared).
    void
    prepare_prestress(const StaticState &state);

    const HarmonicAssembler &assembler;
    const ContactSolver     &contact;
    const Bearings          &bearings;
    const Settings           settings;

    std::vector<HarmonicAssembler::Harmonic> matrices;
    /// per harmonic: M, and the K, C of a speed (same pattern); G and the
    /// law's K_0, K_2 for the reduced model's products
    std::vector<dealii::PETScWrappers::MPI::SparseMatrix> petsc_m, petsc_c, petsc_k, petsc_g,
      petsc_k0, petsc_k2;
    std::vector<dealii::SparseMatrix<double>> law_k0, law_k2;
    std::vector<std::size_t>                  law_number;
    std::vector<std::vector<HarmonicReducedModel::Direction>> bearing_directions;
    std::shared_ptr<const ContactSolver::Decomposition>       law_of_matrices;
    double                                                    law_rpm = -1;
    std::size_t                                               n_laws  = 0;
    /// K_sigma is linear in the static displacement u = u_I + w u_C: per
    /// harmonic K_sigma(u_I) and K_sigma(u_C) of the law they were made for
    std::shared_ptr<const ContactSolver::Decomposition>        prestress_law;
    std::vector<std::unique_ptr<dealii::SparseMatrix<double>>> k_sigma_I, k_sigma_C;
    unsigned int                                               n_prestress = 0;
    std::vector<double> tie_penalty; ///< per ring pair
  };
} // namespace rotorfit
