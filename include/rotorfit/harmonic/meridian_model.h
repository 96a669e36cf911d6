#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/harmonic/fourier_basis.h>
#include <rotorfit/material/bodies.h>
#include <rotorfit/model/station.h>

#include <deal.II/base/quadrature_lib.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/mapping_q1.h>

#include <deal.II/grid/tria.h>

#include <deal.II/lac/affine_constraints.h>

#include <array>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace rotorfit
{
  class SectionMesh;

  /**
   * What the harmonic model stands on (doc/theory.md 14): the meridian
   * plane of the bodies' Sections in quadrilaterals (x = r, y = z), the six
   * Fourier fields of FourierBasis on every node (one FESystem of six
   * scalar Lagrange elements), the ring pairs of every fit and the weights of
   * stations. Which fields a harmonic uses and what holds on the axis are
   * AffineConstraints (free_dofs(), static_constraints()). Built once by
   * setup(), read-only afterwards.
   */
  class MeridianModel
  {
  public:
    explicit MeridianModel(Log &log);

    /// Mesh, DoFs, ring pairs. @p sections: the section mesher's plan;
    /// @p order: the element order; @p rollers: surfaces with u_z = 0.
    void
    setup(const SectionMesh              &sections,
          const unsigned int              order,
          const Bodies                   &bodies,
          const ContactInterfaces        &interfaces,
          const std::vector<std::string> &rollers);

    const dealii::DoFHandler<2> &
    dofs() const
    {
      return dof_handler;
    }
    /// Straight cells: cylinders and cones are lines of the meridian.
    const dealii::Mapping<2> &
    mapping() const
    {
      return linear_mapping;
    }
    const dealii::Triangulation<2> &
    triangulation() const
    {
      return tria;
    }
    /// One rule for every area integral (Gauss, order + 1 points a side).
    dealii::QGauss<2>
    cell_quadrature() const
    {
      return dealii::QGauss<2>(order + 1);
    }
    /// The same on a cell's faces.
    dealii::QGauss<1>
    face_quadrature() const
    {
      return dealii::QGauss<1>(order + 1);
    }
    const Bodies &
    bodies() const
    {
      return *body_list;
    }
    const ContactPairs &
    pairs() const
    {
      return contact_pairs;
    }
    /// The six DoFs (fields a, d, e, b, c, f) of every node.
    const std::vector<std::array<dealii::types::global_dof_index, 6>> &
    nodes() const
    {
      return node_dofs;
    }
    /// (r, z) of every node.
    const std::vector<dealii::Point<2>> &
    node_points() const
    {
      return node_position;
    }
    /// Body (material id) of every node.
    const std::vector<unsigned int> &
    node_bodies() const
    {
      return node_body;
    }
    /// The node of a DoF.
    unsigned int
    node_of(const dealii::types::global_dof_index i) const
    {
      return dof_node[i];
    }

    /**
     * The DoFs a harmonic keeps and their relations: fields the harmonic
     * does not use are zero, and on the axis (doc/theory.md 14.3)
     * n = 0: a = c = 0; n = 1: e = f = 0, d = a, c = b; n >= 2: all zero.
     * Each DoF expands into (free index, weight) terms; a zero DoF has none.
     */
    struct FreeDofs
    {
      unsigned int n_free = 0;
      std::vector<std::vector<std::pair<unsigned int, double>>> expansion;
      /// the DoF of every free index
      std::vector<dealii::types::global_dof_index> dof;
    };
    FreeDofs
    free_dofs(const unsigned int n) const;

    /**
     * The static problem's constraints (harmonic 0, fields a and e): every
     * other field zero, a = 0 on the axis, e = 0 on the axial roller
     * surfaces, and every body without a roller held axially at one node
     * (e = 0 at its node nearest its mid-length): statically determinate, so
     * it takes no reaction from the self-equilibrated loads.
     */
    const dealii::AffineConstraints<double> &
    static_constraints() const
    {
      return statics;
    }

    /**
     * Weights of @p s (a named surface or a band of a body's outer surface,
     * as in 3D) on the meridian: dof_x lists fields a and d of every node of
     * the station, dof_y fields b and c, each with half its weight
     * (1/A) int N_i 2 pi r ds, so that the harmonic-1 lateral average is
     * u_x = sum w (a + d) / 2 (exact for a rigid translation, a = d = X).
     */
    void
    station_weights(Station &s) const;

    /// The named boundary lines.
    bool
    on_surface(const std::string                               &name,
               const dealii::DoFHandler<2>::active_cell_iterator &cell,
               const unsigned int                                f) const;
    void
    check_surface_exists(const std::string &name, const std::string &entry) const;

    /// Smallest radius that counts as on the axis [m].
    double
    axis_tolerance() const
    {
      return axis_tol;
    }

  private:
    void
    build_pairs(const ContactInterfaces &interfaces);

    Log                                               &log;
    unsigned int                                       order = 2;
    const Bodies                                      *body_list = nullptr;
    dealii::Triangulation<2>                           tria;
    dealii::MappingQ1<2>                               linear_mapping;
    std::map<dealii::types::boundary_id, std::set<std::string>> boundary_names;
    std::unique_ptr<dealii::FESystem<2>>               fe;
    dealii::DoFHandler<2>                              dof_handler;
    std::vector<std::array<dealii::types::global_dof_index, 6>> node_dofs;
    std::vector<dealii::Point<2>>                      node_position;
    std::vector<unsigned int>                          node_body;
    std::vector<unsigned int>                          dof_node;
    ContactPairs                                       contact_pairs;
    dealii::AffineConstraints<double>                  statics;
    double                                             axis_tol = 0;
    std::vector<std::string>                           fit_surfaces;
  };
} // namespace rotorfit
