#include <rotorfit/output/paraview_output.h>

#include <deal.II/base/mpi.h>

#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <fstream>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// The stress fields [Pa] from the displacement gradient, per body: von
    /// Mises, and the radial, hoop and axial components about the spin axis
    /// (the ones a fit is designed with).
    class StressFields : public DataPostprocessor<3>
    {
    public:
      explicit StressFields(const Bodies &bodies)
        : bodies(bodies)
      {}

      std::vector<std::string>
      get_names() const override
      {
        return {"von_mises_Pa", "radial_stress_Pa", "hoop_stress_Pa", "axial_stress_Pa"};
      }

      std::vector<DataComponentInterpretation::DataComponentInterpretation>
      get_data_component_interpretation() const override
      {
        return std::vector<DataComponentInterpretation::DataComponentInterpretation>(
          4, DataComponentInterpretation::component_is_scalar);
      }

      UpdateFlags
      get_needed_update_flags() const override
      {
        return update_gradients | update_quadrature_points;
      }

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
            // on the axis the radial direction is undefined: x's
            const Point<3> &x = inputs.evaluation_points[q];
            const double    r = std::hypot(x[0], x[1]);
            const Tensor<1, 3> e_r = r > 0 ? Tensor<1, 3>({x[0] / r, x[1] / r, 0.}) :
                                             Tensor<1, 3>({1., 0., 0.});
            const Tensor<1, 3> e_t({-e_r[1], e_r[0], 0.});
            computed[q](1) = e_r * (sigma * e_r);
            computed[q](2) = e_t * (sigma * e_t);
            computed[q](3) = sigma[2][2];
          }
      }

    private:
      const Bodies &bodies;
    };
  } // namespace

  ParaViewOutput::ParaViewOutput(const Discretization &model, const std::string &directory)
    : model(model)
    , directory(directory)
  {}

  void
  ParaViewOutput::write_static(const StaticState &state, const std::string &series,
                               const unsigned int index)
  {
    PETScWrappers::MPI::Vector u;
    state.displacement(u);

    // contact fields on the pair nodes (status 1 closed / 0 open, pressure,
    // gap) carried in a vector with the displacement's layout
    const auto    &dof_handler = model.dofs();
    Vector<double> contact_fields(dof_handler.n_dofs());
    const auto    &list = model.pairs().pairs();
    const auto    &c    = state.contact;
    for (unsigned int i = 0; i < list.size(); ++i)
      for (const auto &dofs : {list[i].shaft_dofs, list[i].hub_dofs})
        {
          contact_fields[dofs[0]] = c.active[i] ? 1. : 0.;          // x: status
          contact_fields[dofs[1]] = c.active[i] ? c.pressure[i] : 0.; // y: pressure
          contact_fields[dofs[2]] = c.gap[i];                        // z: gap
        }

    const auto   &tria = model.mesh().triangulation();
    Vector<float> body(tria.n_active_cells());
    for (const auto &cell : tria.active_cell_iterators())
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
    StressFields stress(model.bodies());
    data_out.add_data_vector(u, stress);
    data_out.add_data_vector(body, "body", DataOut<3>::type_cell_data);
    data_out.build_patches(model.mesh().mapping(), model.element_order());

    write(data_out, series, index, state.rpm, records[series]);
  }

  void
  ParaViewOutput::write_modes(const ModalResult &result, const std::string &series,
                              const unsigned int index)
  {
    const auto &dof_handler = model.dofs();
    const auto &modes       = result.modes;
    DataOut<3>  data_out;
    data_out.attach_dof_handler(dof_handler);
    const std::vector<DataComponentInterpretation::DataComponentInterpretation>
      vector3(3, DataComponentInterpretation::component_is_part_of_vector);
    for (unsigned int m = 0; m < modes.size(); ++m)
      {
        std::ostringstream name;
        name << "mode_" << std::setw(2) << std::setfill('0') << m + 1;
        data_out.add_data_vector(modes[m].phi.re,
                                 std::vector<std::string>(3, name.str() + "_re"),
                                 DataOut<3>::type_dof_data, vector3);
        data_out.add_data_vector(modes[m].phi.im,
                                 std::vector<std::string>(3, name.str() + "_im"),
                                 DataOut<3>::type_dof_data, vector3);
      }
    Vector<double> tie(dof_handler.n_dofs());
    const auto    &list = model.pairs().pairs();
    for (unsigned int i = 0; i < list.size(); ++i)
      for (const auto &d : {list[i].shaft_dofs, list[i].hub_dofs})
        for (const auto dof : d)
          tie[dof] = result.tied[i] ? 1. : 0.;
    data_out.add_data_vector(tie,
                             std::vector<std::string>(3, "contact_tied"),
                             DataOut<3>::type_dof_data, vector3);
    // vertices only: a mode shape reads as well on them, at a third of the
    // file (twelve complex modes are 75 values per point)
    data_out.build_patches(model.mesh().mapping(), 1);
    write(data_out, series, index, result.rpm, records[series]);
  }

  void
  ParaViewOutput::write(DataOut<3>                                   &data_out,
                        const std::string                            &series,
                        const unsigned int                            index,
                        const double                                  rpm,
                        std::vector<std::pair<double, std::string>> &records) const
  {
    // one .pvtu per speed (pieces per rank) and the .pvd index of the
    // series, rewritten each time so that an interrupted run keeps it
    const MPI_Comm    comm = model.mpi_communicator();
    DataOutBase::VtkFlags flags;
    flags.compression_level = DataOutBase::VtkFlags::default_compression;
    data_out.set_flags(flags);
    const std::string name =
      data_out.write_vtu_with_pvtu_record(directory + "/", series, index, comm, 4, 0);
    records.emplace_back(rpm, name);
    if (Utilities::MPI::this_mpi_process(comm) == 0)
      {
        std::ofstream pvd(directory + "/" + series + ".pvd");
        DataOutBase::write_pvd_record(pvd, records);
      }
  }
} // namespace rotorfit
