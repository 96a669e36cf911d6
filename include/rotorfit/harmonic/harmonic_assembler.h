#pragma once

#include <rotorfit/harmonic/fourier_basis.h>
#include <rotorfit/harmonic/meridian_model.h>
#include <rotorfit/model/station.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <vector>

namespace rotorfit
{
  /**
   * The matrices of the harmonic model (doc/theory.md 14.4): every 3D
   * integral of sections 1-5 evaluated on the Fourier fields of one
   * harmonic, r dr dz over the meridian times the angle rule of
   * FourierBasis, in Cartesian components. Nothing is rederived in
   * cylindrical components, so the harmonic model is the 3D weak form
   * restricted to the harmonic's fields (a Ritz method), and the signs of
   * G, K_theta and K_sigma are those of the 3D model by construction.
   */
  class HarmonicAssembler
  {
  public:
    explicit HarmonicAssembler(const MeridianModel &model);

    /// The static problem (harmonic 0, fields a and e) in the full numbering
    /// with MeridianModel::static_constraints().
    struct StaticSystem
    {
      dealii::PETScWrappers::MPI::SparseMatrix stiffness, spin_softening;
      dealii::PETScWrappers::MPI::Vector       unit_centrifugal_load;
      dealii::Vector<double>                   stiffness_diagonal; ///< unconstrained K
      std::vector<double>                      mass, polar;        ///< per body [kg], [kg m^2]
    };
    void
    assemble_static(StaticSystem &s, const bool spin_softening, const MPI_Comm comm) const;

    /// The speed-independent matrices of harmonic n in its free numbering.
    struct Harmonic
    {
      unsigned int                   n = 0;
      MeridianModel::FreeDofs        free;
      dealii::SparsityPattern        pattern;
      dealii::SparseMatrix<double>   K, M, G, K_theta;
      /// ring tie per unit penalty, field by field (1/2 pi) int phi_k . phi_l dtheta
      dealii::FullMatrix<double>     tie;
      /// lateral station weights (n = 1 only): a_x, a_y in the free numbering
      std::vector<std::vector<std::pair<unsigned int, double>>> station_x, station_y;
    };
    void
    assemble_harmonic(const unsigned int n, const std::vector<Station> &stations, Harmonic &h) const;

    /// K_sigma of the static displacement @p u (full numbering) into @p
    /// k_sigma (on @p h's pattern).
    void
    assemble_prestress(const Harmonic               &h,
                       const dealii::Vector<double> &u,
                       dealii::SparseMatrix<double> &k_sigma) const;

    /// @p k_sigma plus @p scale times ties of the pairs @p closed with
    /// penalties @p penalty [N/m] into @p k (pattern of @p h).
    void
    add_ties(const Harmonic               &h,
             const std::vector<bool>      &closed,
             const std::vector<double>    &penalty,
             dealii::SparseMatrix<double> &k) const;

    const MeridianModel &
    meridian() const
    {
      return model;
    }

  private:
    const MeridianModel &model;
  };

  /// Set the values of @p a into @p p, made by copy_to_petsc() from a
  /// matrix of the same pattern.
  void
  copy_values(const dealii::SparseMatrix<double> &a, dealii::PETScWrappers::MPI::SparseMatrix &p);

  /// Copy a serial matrix into new PETSc matrices of its pattern (one
  /// rank; the pattern is made once for all of @p targets).
  void
  copy_to_petsc(const dealii::SparseMatrix<double>                           &a,
                const std::vector<dealii::PETScWrappers::MPI::SparseMatrix *> &targets,
                const MPI_Comm                                                comm);
} // namespace rotorfit
