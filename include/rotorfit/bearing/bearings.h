#pragma once

#include <rotorfit/model/station.h>

#include <deal.II/base/parameter_handler.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>

#include <array>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * Bearings: stationary springs and dampers on the area-averaged lateral
   * displacement of a station (model/station.h: a shaft end face, a journal
   * band the .geo marks, or a band given by axial position and width;
   * doc/theory.md 5.1, RBE3-like). With the station's weights a_i, and
   * K = sum_{ab} k_ab a_a a_b^T, C = sum_{ab} c_ab a_a a_b^T (a, b in {x, y}).
   * No torsional or ovalisation restraint; exact for rigid motion.
   *
   * Coefficients are constant or, with a coefficient table, interpolated
   * linearly over speed (fluid-film bearings).
   *
   * Parameters: "Bearings" (list of names) and "subsection Bearing <name>".
   */
  class Bearings
  {
  public:
    /// Coefficients in the order xx, yy, xy, yx [N/m] and [N s/m].
    using Coefficients = std::array<double, 4>;

    struct Bearing
    {
      std::string  name;
      Station      station;
      Coefficients k{}, c{};
      /// rows: speed_rpm, kxx, kyy, kxy, kyx, cxx, cyy, cxy, cyx
      std::vector<std::array<double, 9>> table;
      std::string                        table_file;
    };

    static void
    declare_list(dealii::ParameterHandler &prm);

    static void
    declare_parameters(dealii::ParameterHandler       &prm,
                       const std::vector<std::string> &names);

    void
    parse_parameters(dealii::ParameterHandler &prm,
                     const std::string        &prm_directory);

    /// Station weights; an unknown or empty station is an input error.
    void
    setup(const Discretization &model, Log &log);

    void
    add_sparsity(dealii::DynamicSparsityPattern &dsp) const;

    /// k and c of bearing @p b at @p rpm (table: interpolated, held at the ends).
    /// Every bearing isotropic at @p rpm: [[k, q], [-q, k]] in stiffness
    /// and damping, which keeps the rotor axisymmetric.
    bool
    isotropic(const double rpm) const;

    void
    coefficients(const unsigned int b,
                 const double       rpm,
                 Coefficients      &k,
                 Coefficients      &c) const;

    /// Whether some coefficient depends on speed.
    bool
    speed_dependent() const;

    /// Whether every bearing's stiffness (and, with @p damping_too, its
    /// damping) is symmetric at @p rpm: k_xy = k_yx (c_xy = c_yx).
    bool
    symmetric(const double rpm, const bool damping_too) const;

    /// Add K_b and C_b at @p rpm into @p k and @p c (locally owned rows).
    void
    assemble(const double                              rpm,
             dealii::PETScWrappers::MPI::SparseMatrix &k,
             dealii::PETScWrappers::MPI::SparseMatrix &c) const;

    const std::vector<Bearing> &
    list() const
    {
      return bearings;
    }

    unsigned int
    size() const
    {
      return bearings.size();
    }

  private:
    std::vector<Bearing> bearings;
  };
} // namespace rotorfit
