#pragma once

#include <rotorfit/statics/stress_field.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/lac/vector.h>

#include <array>
#include <vector>

namespace rotorfit
{
  class MeridianModel;

  /**
   * The fit designer's stresses on the axisymmetric model: the static state
   * is harmonic 0, u_r = a(r, z), u_z = e(r, z) on the meridian, with the
   * strains eps_rr = a_r, eps_tt = a / r, eps_zz = e_z, eps_rz = (a_z + e_r)
   * / 2 and sigma = lambda tr(eps) I + 2 mu eps. The same numbers as the 3D
   * model's BodyStress: per body the largest von Mises stress over the
   * cells' quadrature points (located at (r, 0, z)), and per fit the bores'
   * stresses at the fit's mid-plane, on a surface from the strains along it
   * and its traction (StressField::surface_stress), on the axis of a solid
   * shaft the whole stress. The field has no angle: one point per bore
   * stands for the 3D model's mean over 8.
   */
  class MeridianStress : public StressField
  {
  public:
    /// Finds the fits' bodies, extents and bore points.
    explicit MeridianStress(const MeridianModel &model);

    std::vector<Peak>
    max_von_mises(const dealii::PETScWrappers::MPI::Vector &u) const override;

    std::vector<FitBore>
    bore(const dealii::PETScWrappers::MPI::Vector &u,
         const std::vector<double>                &pair_pressure) const override;

  private:
    /// A bore point, located in a cell of its body.
    struct BorePoint
    {
      dealii::DoFHandler<2>::active_cell_iterator cell;
      dealii::Point<2>                            unit;
      bool surface = false; ///< false: the axis of a solid shaft
      bool on_fit  = false; ///< its traction: the fit's ring pressure
    };

    /// The cell of @p body that holds @p p (r, z), nearest in unit
    /// coordinates; @p distance: how far outside its reference cell p was.
    BorePoint
    locate(const dealii::Point<2> &p, const unsigned int body, double &distance) const;

    /// The strains (rr, tt, zz, rz) at unit point @p unit of @p cell.
    std::array<double, 4>
    strains(const dealii::DoFHandler<2>::active_cell_iterator &cell,
            const dealii::Point<2>                            &unit,
            const dealii::Vector<double>                      &u) const;

    const MeridianModel &model;
    /// per interface: hub [0] and shaft [1]
    std::vector<std::array<BorePoint, 2>> points;
  };
} // namespace rotorfit
