#include <rotorfit/base/input_error.h>
#include <rotorfit/refinement/mesh_refinement.h>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/petsc_vector.h>

#include <deal.II/numerics/error_estimator.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  void
  MeshRefinement::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Mesh refinement");
    prm.declare_entry("Cycles",
                      "0",
                      Patterns::Integer(0, 20),
                      "Adaptive refinement cycles before the sweep (Geometry/Mesher "
                      "= sections only: its hexahedra, or the harmonic model's "
                      "meridian). Each cycle solves the "
                      "Indicator speeds, writes its results to "
                      "<Output/Directory>/cycle_<k>/ and splits the axial layers "
                      "and radial intervals with the largest indicators; the sweep "
                      "then runs on the last mesh. 0: no refinement.");
    prm.declare_entry("Refinement fraction",
                      "0.3",
                      Patterns::Double(0.01, 1),
                      "Share of the axial layers and of the radial intervals split "
                      "per cycle (those with the largest indicator sums).");
    prm.declare_entry("DOF target",
                      "0",
                      Patterns::Integer(0),
                      "Stop refining once the mesh has at least this many DOFs "
                      "(the harmonic model: its largest harmonic's; 0: run all "
                      "Cycles).");
    prm.declare_entry("Indicator",
                      "static + modal",
                      Patterns::Selection("static|modal|static + modal"),
                      "What the cells' indicators come from: Kelly's jump indicator "
                      "of the static displacement, of the lowest whirl modes, or both "
                      "(each field normalised to a total of 1).");
    prm.declare_entry("Indicator speeds",
                      "0",
                      Patterns::List(Patterns::Double(0), 1),
                      "Speeds of a refinement cycle [r/min].");
    prm.declare_entry("Indicator modes",
                      "4",
                      Patterns::Integer(1, 100),
                      "Lowest whirl modes (real and imaginary parts; the harmonic "
                      "model: harmonic 1's) in the modal indicator.");
    prm.leave_subsection();
  }

  void
  MeshRefinement::parse_parameters(ParameterHandler &prm, const bool hexahedra)
  {
    prm.enter_subsection("Mesh refinement");
    n_cycles   = prm.get_integer("Cycles");
    fraction   = prm.get_double("Refinement fraction");
    target     = prm.get_integer("DOF target");
    n_modes    = prm.get_integer("Indicator modes");
    use_static = prm.get("Indicator") != "modal";
    use_modal  = prm.get("Indicator") != "static";
    speeds_rpm.clear();
    for (const auto &s : Utilities::split_string_list(prm.get("Indicator speeds"), ','))
      speeds_rpm.push_back(Utilities::string_to_double(s));
    prm.leave_subsection();
    if (n_cycles > 0 && !hexahedra)
      throw InputError("Mesh refinement/Cycles = " + std::to_string(n_cycles) +
                       " needs the hexahedra of Geometry/Mesher = sections: deal.II refines "
                       "tetrahedral meshes only uniformly (refine the gmsh mesh with "
                       "Geometry/Geometry parameters instead).");
  }

  void
  MeshRefinement::reset(const Discretization &model)
  {
    eta2.reinit(model.mesh().triangulation().n_active_cells());
    n_fields  = 0;
    n_skipped = 0;
  }

  template <int dim>
  void
  MeshRefinement::add_field(const Mapping<dim>       &mapping,
                            const DoFHandler<dim>    &dofs,
                            const Quadrature<dim - 1> &face_rule,
                            const Vector<double>     &field)
  {
    Vector<float> eta(dofs.get_triangulation().n_active_cells());
    KellyErrorEstimator<dim>::estimate(mapping, dofs, face_rule, {}, field, eta);
    double total = 0;
    for (const float e : eta)
      total += double(e) * e;
    if (!(total > 0) || !std::isfinite(total))
      {
        // a field without jumps (rigid motion) tells nothing; a NaN one is
        // a failed solve: both are left out and counted in the log line
        ++n_skipped;
        return;
      }
    for (unsigned int k = 0; k < eta.size(); ++k)
      eta2[k] += double(eta[k]) * eta[k] / total;
    ++n_fields;
  }

  void
  MeshRefinement::add_static(const Discretization &model, const StaticState &state)
  {
    if (!use_static)
      return;
    const IndexSet             all = complete_index_set(model.dofs().n_dofs());
    PETScWrappers::MPI::Vector u(model.locally_owned_dofs(), all, model.mpi_communicator());
    state.displacement(u);
    Vector<double> field(model.dofs().n_dofs());
    for (types::global_dof_index i = 0; i < field.size(); ++i)
      field[i] = u[i];
    add_field(model.mesh().mapping(), model.dofs(),
              model.mesh().face_rule(model.element_order() + 1), field);
  }

  void
  MeshRefinement::add_modes(const Discretization &model, const EigenSolution &solution)
  {
    if (!use_modal)
      return;
    for (unsigned int k = 0; k < std::min<std::size_t>(n_modes, solution.elastic.size()); ++k)
      {
        for (const auto *part : {&solution.elastic[k].phi.re, &solution.elastic[k].phi.im})
          add_field(model.mesh().mapping(), model.dofs(),
                    model.mesh().face_rule(model.element_order() + 1), *part);
      }
  }

  void
  MeshRefinement::reset_meridian(const MeridianModel &meridian)
  {
    eta2.reinit(meridian.triangulation().n_active_cells());
    n_fields  = 0;
    n_skipped = 0;
  }

  void
  MeshRefinement::add_meridian_static(const MeridianModel &meridian, const Vector<double> &u)
  {
    if (use_static)
      add_field(meridian.mapping(), meridian.dofs(), meridian.face_quadrature(), u);
  }

  void
  MeshRefinement::add_meridian_mode(const MeridianModel                     &meridian,
                                    const unsigned int                       index,
                                    const std::vector<std::complex<double>> &u)
  {
    if (!use_modal || index > n_modes)
      return;
    Vector<double> re(u.size()), im(u.size());
    for (unsigned int i = 0; i < u.size(); ++i)
      re[i] = u[i].real(), im[i] = u[i].imag();
    for (const auto *part : {&re, &im})
      add_field(meridian.mapping(), meridian.dofs(), meridian.face_quadrature(), *part);
  }

  SectionMesh::Refinement
  MeshRefinement::refine(const Discretization &model, Log &log) const
  {
    return refine(model.mesh().sections(), model.mesh().triangulation(), log);
  }

  SectionMesh::Refinement
  MeshRefinement::refine_meridian(const SectionMesh   &sections,
                                  const MeridianModel &meridian,
                                  Log                 &log) const
  {
    return refine(sections, meridian.triangulation(), log);
  }

  template <int dim>
  SectionMesh::Refinement
  MeshRefinement::refine(const SectionMesh &sections, const Triangulation<dim> &tria, Log &log) const
  {
    Vector<float> eta(eta2.size());
    for (unsigned int k = 0; k < eta.size(); ++k)
      eta[k] = std::sqrt(eta2[k]);
    const auto next = sections.refined(tria, eta, fraction);
    std::ostringstream m;
    m << "Mesh refinement: " << n_fields << " indicator field(s)";
    if (n_skipped > 0)
      m << " (" << n_skipped << " left out: no jumps, or not finite)";
    m << "; split " << next.layers_split
      << " axial layer(s) and " << next.intervals_split << " radial interval(s)\n";
    log << m.str();
    return next;
  }
} // namespace rotorfit
