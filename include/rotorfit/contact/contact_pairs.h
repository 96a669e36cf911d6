#pragma once

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>

#include <rotorfit/fit/fit_specification.h>

#include <array>
#include <string>
#include <map>
#include <vector>

namespace rotorfit
{
  class AssemblyMesh;

  /// A shrink-fit interface as given in subsection "Interface <name>".
  struct InterfaceDefinition
  {
    std::string name;
    std::string shaft_surface; ///< physical surface, shaft (inner) side
    std::string hub_surface;   ///< physical surface, hub (outer) side
    FitSpecification fit;      ///< the interference as given, friction, loads
  };

  /**
   * The shrink-fit interfaces: top-level entry "Interfaces" (names) and one
   * subsection "Interface <name>" per name.
   */
  class ContactInterfaces
  {
  public:
    static void
    declare_list(dealii::ParameterHandler &prm);

    static void
    declare_parameters(dealii::ParameterHandler       &prm,
                       const std::vector<std::string> &names);

    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// Declare subsection "Fit design": the reference temperature and the
    /// interference cases of toleranced fits.
    static void
    declare_fit_design(dealii::ParameterHandler &prm);

    /// The end of a toleranced fit's band this run uses (one case per run:
    /// the application runs the cases one after the other).
    FitSpecification::Case
    interference_case() const
    {
      return band_case;
    }

    /// Every case of "Fit design/Interference cases", in order.
    const std::vector<FitSpecification::Case> &
    interference_cases() const
    {
      return cases;
    }

    /// Some interface has a toleranced interference (ISO fit, deviations).
    bool
    any_toleranced() const;

    /// Temperature at which interferences, tolerances and the mesh are
    /// given [deg C].
    double
    reference_temperature() const
    {
      return reference_celsius;
    }

    const std::vector<InterfaceDefinition> &
    list() const
    {
      return interfaces;
    }

  private:
    std::vector<InterfaceDefinition>    interfaces;
    std::vector<FitSpecification::Case> cases;
    FitSpecification::Case              band_case         = FitSpecification::Case::smallest;
    double                              reference_celsius = 20;
  };

  /// What a fit's interference is in this run, once the mesh gives its diameter.
  struct FitGeometry
  {
    double diameter = 0;           ///< nominal: twice the mean pair radius [m]
    double r_min = 0, r_max = 0;   ///< pair radii [m]
    double z_min = 0, z_max = 0;   ///< axial extent of the pairs [m]
    double radial_interference = 0; ///< effective, at the reference temperature [m]
    double thermal_shift = 0;  ///< change of the radial interference by the temperatures at the mean radius [m]
    unsigned int shaft_body = 0, hub_body = 0; ///< material ids of the two sides
  };

  /**
   * One node-to-node pair: a shaft-side and a hub-side support point that
   * coincide in the reference mesh. Only the x and y DoFs take part in the
   * contact (frictionless, radial normal n = (x, y, 0)/r fixed in the
   * reference configuration); z is kept for output. Gap g = n.(u_hub - u_shaft) - delta, g < 0: penetration.
   */
  struct ContactPair
  {
    unsigned int                                 interface;
    std::array<dealii::types::global_dof_index, 3> shaft_dofs; ///< x, y, z
    std::array<dealii::types::global_dof_index, 3> hub_dofs;   ///< x, y, z
    dealii::Tensor<1, 3>                         normal;
    dealii::Point<3>                             position;
    double                                       interference;
  };

  /**
   * All contact pairs of all interfaces, and per interface the consistent
   * surface mass matrix that turns nodal contact forces into a pressure
   * field (N_i = int psi_i p dA; P2 vertex weights int psi_i dA are zero, so
   * a plain division would fail).
   */
  class ContactPairs
  {
  public:
    /**
     * Pair the support points of every interface. Throws InputError naming
     * the interface, the number of unmatched points and the first one.
     */
    void
    build(const AssemblyMesh                     &mesh,
          const dealii::DoFHandler<3>            &dof_handler,
          const std::vector<dealii::Point<3>>    &support_points,
          const ContactInterfaces                &interfaces,
          const std::vector<double>              &free_thermal_strain);

    /// One interface of the meridian model (harmonic/): its ring pairs
    /// (position (r, 0, z), normal e_r), the body of each side of each
    /// pair, and the shaft side's boundary lines as faces of local pair
    /// indices with their ring areas 2 pi int r ds and consistent mass
    /// matrices int psi_i psi_j 2 pi r ds.
    struct RingInterface
    {
      std::vector<ContactPair>                 pairs;
      std::vector<unsigned int>                shaft_body, hub_body;
      std::vector<std::vector<unsigned int>>   faces;
      std::vector<double>                      face_area;
      std::vector<dealii::FullMatrix<double>>  face_mass;
    };

    /// The pairs of the meridian model, one RingInterface per interface (in
    /// the order of @p interfaces); interferences as in build().
    void
    build_rings(const ContactInterfaces    &interfaces,
                std::vector<RingInterface> &&rings,
                const std::vector<double>   &free_thermal_strain);

    const std::vector<ContactPair> &
    pairs() const
    {
      return pair_list;
    }

    unsigned int
    n_interfaces() const
    {
      return surfaces.size();
    }

    /// Global pair indices of interface @p i.
    const std::vector<unsigned int> &
    pairs_of(const unsigned int i) const
    {
      return surfaces[i].pairs;
    }

    /// Material ids (body indices) of the shaft side [0] and the hub side
    /// [1] of interface @p i: the body holding most of that side's points.
    std::array<unsigned int, 2>
    bodies(const unsigned int i) const
    {
      return {{surfaces[i].geometry.shaft_body, surfaces[i].geometry.hub_body}};
    }

    /// Diameter, extent, bodies and interference of interface @p i.
    const FitGeometry &
    geometry(const unsigned int i) const
    {
      return surfaces[i].geometry;
    }

    /// Area of interface @p i [m^2] (shaft side, curved geometry).
    double
    area(const unsigned int i) const
    {
      return surfaces[i].area;
    }

    /// Area of the faces of interface @p i weighted by the share of their
    /// pair points that are closed [m^2].
    double
    closed_area(const unsigned int i, const std::vector<bool> &closed) const;

    /// Pressure at each pair [Pa] from nodal normal forces @p force [N]
    /// (both indexed by global pair number).
    std::vector<double>
    pressure(const std::vector<double> &force) const;

    /**
     * Rotational symmetry of the closed set of interface @p i [-]: the
     * interface is cut into 4 axial rings and 8 angular sectors; in each
     * ring, 1 - (least closed fraction of a sector) / (largest one); the
     * largest over the rings. 0: every sector of every ring equally closed
     * (or the ring all open); 1: a sector of a ring holds while another is
     * open. Relative on purpose: near the loss of fit the last pairs on one
     * side hold a body at a point, the most lopsided joint there is. The
     * stationary-frame eigenproblem assumes 0.
     */
    double
    asymmetry(const unsigned int i, const std::vector<bool> &closed) const;

  private:
    struct Surface
    {
      std::vector<unsigned int>              pairs;
      std::vector<std::vector<unsigned int>> faces; // local pair indices
      std::vector<double>                    face_area;
      double                                 area = 0;
      FitGeometry                            geometry;
      dealii::SparsityPattern                pattern;
      dealii::SparseMatrix<double>           mass;
      std::shared_ptr<dealii::SparseDirectUMFPACK> inverse;
    };

    /// Support points and faces of the two sides of one interface.
    struct InterfaceSides;

    /// The pairs of interface @p f: pair_list and surfaces[f].pairs;
    /// returns the pair number of each shaft-side x DoF.
    std::map<dealii::types::global_dof_index, unsigned int>
    match_sides(const unsigned int         f,
                const InterfaceDefinition &definition,
                const InterfaceSides      &sides,
                const double               tolerance,
                const std::string         &hint);

    /// The fit geometry of interface @p f from its pairs, and each pair's
    /// interference: the fit's effective one (case @p c) changed by the
    /// free thermal expansion of the two bodies, -r (eps_hub - eps_shaft).
    void
    set_interference(const unsigned int f, const InterfaceDefinition &definition,
                     const FitSpecification::Case c, const std::vector<unsigned int> &shaft_body,
                     const std::vector<unsigned int> &hub_body,
                     const std::vector<double> &free_thermal_strain);

    /// Surface mass matrix and face areas of interface @p f (shaft side).
    void
    assemble_surface(const unsigned int                                             f,
                     const InterfaceSides                                          &sides,
                     const std::map<dealii::types::global_dof_index, unsigned int> &pair_of,
                     const AssemblyMesh                                            &mesh,
                     const dealii::FiniteElement<3>                                &fe);

    std::vector<ContactPair> pair_list;
    std::vector<Surface>     surfaces;
  };

  /// The interference of interface @p i as the log states it, both models:
  /// the fit given (an ISO fit or deviations: its designation, diameter and
  /// the band's end this run uses), the radial interference and the
  /// temperatures' shift.
  std::string
  describe_interference(const ContactInterfaces &interfaces, const ContactPairs &pairs,
                        const unsigned int i);
} // namespace rotorfit
