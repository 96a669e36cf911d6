#include <rotorfit/harmonic/fourier_basis.h>
#include <rotorfit/harmonic/meridian_output.h>

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <tuple>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    using Interpretation = DataComponentInterpretation::DataComponentInterpretation;

    /// The axisymmetric static field (harmonic 0: u_r = a, u_z = e) as the
    /// displacement vector of the plane (r, z) and the stresses about the
    /// axis: von Mises, radial, hoop, axial and shear r-z (the 3D files'
    /// names, the shear added).
    class StaticFields : public DataPostprocessor<2>
    {
    public:
      explicit StaticFields(const Bodies &bodies)
        : bodies(bodies)
      {}

      std::vector<std::string>
      get_names() const override
      {
        return {"displacement_m",   "displacement_m",  "von_mises_Pa", "radial_stress_Pa",
                "hoop_stress_Pa",   "axial_stress_Pa", "shear_rz_stress_Pa"};
      }

      std::vector<Interpretation>
      get_data_component_interpretation() const override
      {
        std::vector<Interpretation> i(7, DataComponentInterpretation::component_is_scalar);
        i[0] = i[1] = DataComponentInterpretation::component_is_part_of_vector;
        return i;
      }

      UpdateFlags
      get_needed_update_flags() const override
      {
        return update_values | update_gradients | update_quadrature_points;
      }

      void
      evaluate_vector_field(const DataPostprocessorInputs::Vector<2> &inputs,
                            std::vector<Vector<double>>              &computed) const override
      {
        const auto  cell = inputs.template get_cell<2>();
        const Body &body = bodies[cell->material_id()];
        for (unsigned int q = 0; q < computed.size(); ++q)
          {
            const double        r   = inputs.evaluation_points[q][0];
            const double        u_r = inputs.solution_values[q][FourierBasis::a];
            const Tensor<1, 2> &g_r = inputs.solution_gradients[q][FourierBasis::a];
            const Tensor<1, 2> &g_z = inputs.solution_gradients[q][FourierBasis::e];
            // (r, theta, z); on the axis u_r / r -> d u_r / dr
            SymmetricTensor<2, 3> eps;
            eps[0][0] = g_r[0];
            eps[1][1] = r > 1e-12 ? u_r / r : g_r[0];
            eps[2][2] = g_z[1];
            eps[0][2] = 0.5 * (g_r[1] + g_z[0]);
            const SymmetricTensor<2, 3> sigma =
              body.lambda() * trace(eps) * unit_symmetric_tensor<3>() + 2 * body.mu() * eps;
            const SymmetricTensor<2, 3> s = deviator(sigma);
            computed[q](0)                = u_r;
            computed[q](1)                = inputs.solution_values[q][FourierBasis::e];
            computed[q](2)                = std::sqrt(1.5 * scalar_product(s, s));
            computed[q](3)                = sigma[0][0];
            computed[q](4)                = sigma[1][1];
            computed[q](5)                = sigma[2][2];
            computed[q](6)                = sigma[0][2];
          }
      }

    private:
      const Bodies &bodies;
    };

    /// Three fields of a vector in the meridian's layout, as named scalars.
    class Fields : public DataPostprocessor<2>
    {
    public:
      Fields(std::vector<std::string> names, std::vector<unsigned int> components)
        : names(std::move(names))
        , components(std::move(components))
      {}
      std::vector<std::string>
      get_names() const override
      {
        return names;
      }
      std::vector<Interpretation>
      get_data_component_interpretation() const override
      {
        return std::vector<Interpretation>(names.size(),
                                           DataComponentInterpretation::component_is_scalar);
      }
      UpdateFlags
      get_needed_update_flags() const override
      {
        return update_values;
      }
      void
      evaluate_vector_field(const DataPostprocessorInputs::Vector<2> &inputs,
                            std::vector<Vector<double>>              &computed) const override
      {
        for (unsigned int q = 0; q < computed.size(); ++q)
          for (unsigned int k = 0; k < components.size(); ++k)
            computed[q](k) = inputs.solution_values[q][components[k]];
      }

    private:
      std::vector<std::string>  names;
      std::vector<unsigned int> components;
    };
  } // namespace

  MeridianOutput::MeridianOutput(const MeridianModel &model,
                                 const std::string   &directory,
                                 const unsigned int   sectors)
    : model(model)
    , directory(directory)
    , sectors(sectors)
  {}

  void
  MeridianOutput::write_static(const Vector<double> &u,
                               const StaticState    &state,
                               const std::string    &series,
                               const unsigned int    index) const
  {
    // ring pairs: status (1 closed), pressure and gap on both nodes, carried
    // in fields a, d, e of a vector of the meridian's layout
    Vector<double> contact(model.dofs().n_dofs());
    const auto    &pairs = model.pairs().pairs();
    const auto    &c     = state.contact;
    for (unsigned int i = 0; i < pairs.size(); ++i)
      for (const auto dof : {pairs[i].shaft_dofs[0], pairs[i].hub_dofs[0]})
        {
          const auto &node               = model.nodes()[model.node_of(dof)];
          contact[node[FourierBasis::a]] = c.active[i] ? 1. : 0.;
          contact[node[FourierBasis::d]] = c.active[i] ? c.pressure[i] : 0.;
          contact[node[FourierBasis::e]] = c.gap[i];
        }
    Vector<float> body(model.triangulation().n_active_cells());
    for (const auto &cell : model.triangulation().active_cell_iterators())
      body[cell->active_cell_index()] = cell->material_id();

    StaticFields fields(model.bodies());
    Fields       contact_fields({"contact_closed", "contact_pressure_Pa", "contact_gap_m"},
                          {FourierBasis::a, FourierBasis::d, FourierBasis::e});
    DataOut<2>   data_out;
    data_out.attach_dof_handler(model.dofs());
    data_out.add_data_vector(u, fields);
    data_out.add_data_vector(contact, contact_fields);
    data_out.add_data_vector(body, "body", DataOut<2>::type_cell_data);
    // straight cells: the quadratic field on 2 x 2 subcells
    data_out.build_patches(model.mapping(), 2);

    std::ostringstream file;
    file << series << "_" << std::setw(4) << std::setfill('0') << index << ".vtu";
    DataOutBase::VtkFlags flags;
    flags.compression_level = DataOutBase::VtkFlags::default_compression;
    data_out.set_flags(flags);
    std::ofstream out(directory + "/" + file.str());
    data_out.write_vtu(out);
    record(series, state.rpm, file.str());
  }

  void
  MeridianOutput::write_modes(const std::vector<Shape> &shapes,
                              const double              rpm,
                              const std::string        &series,
                              const unsigned int        index) const
  {
    // names and vector ranges: per shape re and im, three components each
    std::vector<std::string> names;
    std::vector<std::tuple<unsigned int, unsigned int, std::string, Interpretation>> vectors;
    for (const auto &s : shapes)
      for (const char *part : {"_re", "_im"})
        {
          std::ostringstream name;
          name << "h" << s.harmonic << "_mode_" << std::setw(2) << std::setfill('0') << s.index
               << part;
          vectors.emplace_back(names.size(),
                               names.size() + 2,
                               name.str(),
                               DataComponentInterpretation::component_is_part_of_vector);
          names.insert(names.end(), 3, name.str());
        }

    // one hexahedron per cell and sector: the cell's vertices (deal.II's
    // lexicographic order) at the sector's two angles; vertices on the axis
    // make it a wedge
    std::vector<DataOutBase::Patch<3, 3>> patches;
    patches.reserve(model.triangulation().n_active_cells() * sectors);
    const double d_theta = 2 * M_PI / sectors;
    for (const auto &cell : model.dofs().active_cell_iterators())
      for (unsigned int k = 0; k < sectors; ++k)
        {
          DataOutBase::Patch<3, 3> patch;
          patch.n_subdivisions = 1;
          patch.reference_cell = ReferenceCells::Hexahedron;
          patch.patch_index    = patches.size();
          patch.data.reinit(names.size(), 8);
          for (unsigned int v = 0; v < 8; ++v)
            {
              const Point<2> &p     = cell->vertex(v % 4);
              const double    theta = (k + v / 4) * d_theta;
              const double    cs = std::cos(theta), sn = std::sin(theta);
              patch.vertices[v]     = Point<3>(p[0] * cs, p[0] * sn, p[1]);
              const auto &node      = model.nodes()[model.node_of(cell->vertex_dof_index(v % 4, 0))];
              for (unsigned int m = 0; m < shapes.size(); ++m)
                {
                  const auto  &x  = shapes[m].value;
                  const double nt = shapes[m].harmonic * theta;
                  const double c = std::cos(nt), s = std::sin(nt);
                  // doc/theory.md 14.1: u_r = a cos + b sin, u_t = c cos - d sin,
                  // u_z = e cos + f sin
                  const std::complex<double> u_r =
                    x[node[FourierBasis::a]] * c + x[node[FourierBasis::b]] * s;
                  const std::complex<double> u_t =
                    x[node[FourierBasis::c]] * c - x[node[FourierBasis::d]] * s;
                  const std::complex<double> u_z =
                    x[node[FourierBasis::e]] * c + x[node[FourierBasis::f]] * s;
                  const std::complex<double> u[3] = {u_r * cs - u_t * sn, u_r * sn + u_t * cs, u_z};
                  for (unsigned int j = 0; j < 3; ++j)
                    {
                      patch.data(6 * m + j, v)     = u[j].real();
                      patch.data(6 * m + 3 + j, v) = u[j].imag();
                    }
                }
            }
          patches.push_back(std::move(patch));
        }

    std::ostringstream file;
    file << series << "_" << std::setw(4) << std::setfill('0') << index << ".vtu";
    DataOutBase::VtkFlags flags;
    flags.compression_level = DataOutBase::VtkFlags::default_compression;
    std::ofstream out(directory + "/" + file.str());
    DataOutBase::write_vtu(patches, names, vectors, flags, out);
    record(series, rpm, file.str());
  }

  void
  MeridianOutput::record(const std::string &series, const double rpm, const std::string &file) const
  {
    auto &list = records[series];
    list.emplace_back(rpm, file);
    std::ofstream pvd(directory + "/" + series + ".pvd");
    DataOutBase::write_pvd_record(pvd, list);
  }
} // namespace rotorfit
