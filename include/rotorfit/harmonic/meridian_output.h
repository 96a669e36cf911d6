#pragma once

#include <rotorfit/harmonic/meridian_model.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/lac/vector.h>

#include <complex>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * The harmonic model's ParaView files (doc/axisymmetric.md, "ParaView"):
   * the static state on the meridian plane (x = r, y = z), and the mode
   * shapes swept around the axis into a 3D mesh of hexahedra, so that a
   * mode with n nodal diameters is seen as it moves. Each series has its
   * .pvd index, rewritten at every file so that an interrupted run keeps it.
   */
  class MeridianOutput
  {
  public:
    /// @p sectors: the angular divisions of the swept mesh.
    MeridianOutput(const MeridianModel &model,
                   const std::string   &directory,
                   const unsigned int   sectors);

    /// The static displacement @p u (all DoFs of the meridian, fields a = u_r
    /// and e = u_z), the stresses about the axis, the ring pairs' status,
    /// pressure and gap, the body of each cell.
    void
    write_static(const dealii::Vector<double> &u,
                 const StaticState            &state,
                 const std::string            &series,
                 const unsigned int            index) const;

    /// A mode of harmonic n: its complex value at every DoF of the meridian.
    struct Shape
    {
      unsigned int                      harmonic = 0, index = 0;
      std::vector<std::complex<double>> value;
    };

    /// Every shape at one speed, swept: per shape the Cartesian displacement
    /// of its real part (phase 0) and of its imaginary part (a quarter period
    /// later), named h<n>_mode_<index>_re / _im as in campbell.csv.
    void
    write_modes(const std::vector<Shape> &shapes,
                const double              rpm,
                const std::string        &series,
                const unsigned int        index) const;

  private:
    void
    record(const std::string &series, const double rpm, const std::string &file) const;

    const MeridianModel &model;
    std::string          directory;
    unsigned int         sectors;
    mutable std::map<std::string, std::vector<std::pair<double, std::string>>> records;
  };
} // namespace rotorfit
