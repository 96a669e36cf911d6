#include <rotorfit/statics/static_problem.h>

#include <deal.II/base/mpi.h>

#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <fstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// von Mises stress [Pa] from the displacement gradient, per body.
    class VonMises : public DataPostprocessorScalar<3>
    {
    public:
      explicit VonMises(const Bodies &bodies)
        : DataPostprocessorScalar<3>("von_mises_Pa", update_gradients)
        , bodies(bodies)
      {}

      void
      evaluate_vector_field(const DataPostprocessorInputs::Vector<3> &inputs,
                            std::vector<Vector<double>> &computed) const override
      {
        const auto  cell = inputs.template get_cell<3>();
        const Body &body = bodies[cell->material_id()];
        for (unsigned int q = 0; q < computed.size(); ++q)
          {
            Tensor<2, 3> grad;
            for (unsigned int c = 0; c < 3; ++c)
              grad[c] = inputs.solution_gradients[q][c];
            const SymmetricTensor<2, 3> eps = symmetrize(grad);
            const SymmetricTensor<2, 3> sigma =
              body.lambda() * trace(eps) * unit_symmetric_tensor<3>() +
              2 * body.mu() * eps;
            const SymmetricTensor<2, 3> s = deviator(sigma);
            computed[q](0) = std::sqrt(1.5 * scalar_product(s, s));
          }
      }

    private:
      const Bodies &bodies;
    };
  } // namespace

  void
  StaticProblem::write_vtu(const unsigned int          step,
                           const double                rpm,
                           const ContactSolver::State &state,
                           const std::vector<double>  &pressure)
  {
    const double w = std::pow(SpeedSchedule::rpm_to_rad_per_s(rpm), 2);
    PETScWrappers::MPI::Vector u;
    contact.displacement(w, u);

    // contact fields on the pair nodes (status 1 closed / 0 open, pressure,
    // gap) carried in a vector with the displacement's layout
    Vector<double> contact_fields(dof_handler.n_dofs());
    const auto    &list = pairs.pairs();
    for (unsigned int i = 0; i < list.size(); ++i)
      for (const auto &dofs : {list[i].shaft_dofs, list[i].hub_dofs})  // x: status, y: pressure
        {
          contact_fields[dofs[0]]     = state.active[i] ? 1. : 0.;
          contact_fields[dofs[1]]     = state.active[i] ? pressure[i] : 0.;
        }
    // the z DoF of each pair node carries the gap
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        contact_fields[list[i].shaft_dofs[2]] = state.gap[i];
        contact_fields[list[i].hub_dofs[2]]   = state.gap[i];
      }

    Vector<float> body(mesh.triangulation().n_active_cells());
    for (const auto &cell : mesh.triangulation().active_cell_iterators())
      body[cell->active_cell_index()] = cell->material_id();

    DataOut<3> data_out;
    data_out.attach_dof_handler(dof_handler);
    const std::vector<DataComponentInterpretation::DataComponentInterpretation>
      vector3(3, DataComponentInterpretation::component_is_part_of_vector),
      scalar3(3, DataComponentInterpretation::component_is_scalar);
    data_out.add_data_vector(u,
                             std::vector<std::string>(3, "displacement_m"),
                             DataOut<3>::type_dof_data,
                             vector3);
    data_out.add_data_vector(contact_fields,
                             {"contact_closed", "contact_pressure_Pa", "contact_gap_m"},
                             DataOut<3>::type_dof_data,
                             scalar3);
    VonMises von_mises(bodies);
    data_out.add_data_vector(u, von_mises);
    data_out.add_data_vector(body, "body", DataOut<3>::type_cell_data);
    data_out.build_patches(mesh.mapping(), mesh.element_order());

    const std::string name = data_out.write_vtu_with_pvtu_record(
      output_dir + "/", "solution", step, comm, 4, 0);
    pvd_records.emplace_back(rpm, name);
    if (Utilities::MPI::this_mpi_process(comm) == 0)
      {
        std::ofstream pvd(output_dir + "/solution.pvd");
        DataOutBase::write_pvd_record(pvd, pvd_records);
      }
  }
} // namespace rotorfit
