#pragma once

#include <rotorfit/model/discretization.h>

#include <deal.II/base/parameter_handler.h>

#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * A station of the rotor: the area-averaged lateral displacement of a
   * piece of its surface (doc/theory.md 5.1), where a bearing holds the
   * rotor, an unbalance acts or a response is probed. With the weights
   * a_i = (1/A) int_S N_i dA the station moves by u_x = sum a_i U_ix (exact
   * for rigid motion; RBE3-like), and a force F on the station puts a_i F on
   * node i (the transpose), so the work is F u_x.
   *
   * S is either a physical surface of the .geo (a shaft end face or a band
   * the geometry marks), or a band of a body's outer surface given by its
   * axial position and width: the surface points whose outward normal is
   * radial (n . e_r > 0.5: not an end face, not a bore) with
   * |z - z_0| <= w/2. A band is cut at the face quadrature points, so its
   * edges are as sharp as the surface mesh; the area found is compared with
   * 2 pi r w and logged.
   *
   * Parameters (in the owner's subsection): "Surface", or "Body",
   * "Axial position" and "Width".
   */
  struct Station
  {
    /// Declares Surface, Body, Axial position, Width; @p what names the
    /// owner in the help text ("the bearing", "the unbalance").
    static void
    declare_parameters(dealii::ParameterHandler &prm, const std::string &what);

    /// @p owner is the subsection ("Bearing left"), for the messages.
    void
    parse_parameters(dealii::ParameterHandler &prm, const std::string &owner);

    /// Weights from the mesh; an empty station is an input error naming
    /// the owner. Logs a band's area against 2 pi r w.
    void
    setup(const Discretization &model, Log &log);

    /// The band's line in the log, and a warning if its area is off 2 pi r w.
    void
    log_band(Log &log, const double z_min, const double z_max) const;

    /// "surface 'end_left'" or "band z = 0.12 m, w = 5 mm on body 'shaft'".
    std::string
    describe() const;

    bool
    is_band() const
    {
      return surface.empty();
    }

    std::string owner;
    std::string surface;
    std::string body;
    double      axial_position = 0, width = 0;

    // from the mesh
    std::vector<dealii::types::global_dof_index> dof_x, dof_y;
    std::vector<double>                          weight; ///< a_i, sum 1
    double area = 0;  ///< [m^2]
    double z    = 0;  ///< area centroid [m]
    double radius = 0; ///< area-mean distance from the axis [m]
  };
} // namespace rotorfit
