#include <rotorfit/base/input_error.h>
#include <rotorfit/harmonic/fourier_basis.h>
#include <rotorfit/harmonic/meridian_model.h>
#include <rotorfit/harmonic/meridian_stress.h>

#include <deal.II/base/quadrature.h>

#include <deal.II/fe/fe_values.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// (rr, tt, zz, rz) of harmonic 0's u_r = a, u_z = e at radius r.
    std::array<double, 4>
    strain_of(const double a, const Tensor<1, 2> &grad_a, const Tensor<1, 2> &grad_e, const double r)
    {
      return {{grad_a[0], a / r, grad_e[1], 0.5 * (grad_a[1] + grad_e[0])}};
    }

    /// sigma_r, sigma_t, sigma_z, von Mises of the strains @p e.
    StressField::BoreStress
    full_stress(const std::array<double, 4> &e, const Body &body)
    {
      const double lambda = body.lambda(), mu = body.mu();
      const double tr = e[0] + e[1] + e[2];
      StressField::BoreStress s;
      s.sigma_r        = lambda * tr + 2 * mu * e[0];
      s.sigma_t        = lambda * tr + 2 * mu * e[1];
      s.sigma_z        = lambda * tr + 2 * mu * e[2];
      const double rz  = 2 * mu * e[3];
      s.von_mises      = std::sqrt(0.5 * ((s.sigma_r - s.sigma_t) * (s.sigma_r - s.sigma_t) +
                                     (s.sigma_t - s.sigma_z) * (s.sigma_t - s.sigma_z) +
                                     (s.sigma_z - s.sigma_r) * (s.sigma_z - s.sigma_r)) +
                                3 * rz * rz);
      return s;
    }
  } // namespace

  MeridianStress::MeridianStress(const MeridianModel &model)
    : model(model)
  {
    find_fits(model.pairs());
    for (unsigned int f = 0; f < fit_list.size(); ++f)
      {
        Fit         &fit = fit_list[f];
        const double z   = fit.z_mid();
        // the shaft's bore: its smallest vertex radius among its cells that
        // span the mid-plane; on the axis: solid
        double bore = std::numeric_limits<double>::max();
        for (const auto &cell : model.dofs().active_cell_iterators())
          if (cell->material_id() == fit.shaft_body)
            {
              double lo = std::numeric_limits<double>::max(), hi = -lo, r = lo;
              for (const unsigned int v : cell->vertex_indices())
                {
                  lo = std::min(lo, cell->vertex(v)[1]);
                  hi = std::max(hi, cell->vertex(v)[1]);
                  r  = std::min(r, cell->vertex(v)[0]);
                }
              if (lo <= z && z <= hi)
                bore = std::min(bore, r);
            }
        fit.shaft_bore = bore <= model.axis_tolerance() ? 0. : bore;

        std::array<BorePoint, 2> ends;
        for (unsigned int side = 0; side < 2; ++side)
          {
            const unsigned int body = side == 0 ? fit.hub_body : fit.shaft_body;
            const double       r    = side == 0          ? fit.radius * (1 + nudge) :
                                      fit.shaft_bore > 0 ? fit.shaft_bore * (1 + nudge) :
                                                           fit.radius * nudge;
            double distance = 0;
            ends[side]      = locate(Point<2>(r, z), body, distance);
            if (!(distance < 1e-3))
              throw InputError("The bore point at r = " + std::to_string(r) + " m, z = " +
                               std::to_string(z) + " m of interface " + std::to_string(f) +
                               " is in no meridian cell of body " + model.bodies()[body].name +
                               ": the fit's bodies do not reach its mid-plane.");
            ends[side].surface = side == 0 || fit.shaft_bore > 0;
            ends[side].on_fit  = side == 0; // the hub's bore carries the fit's pressure
          }
        points.push_back(ends);
      }
  }

  MeridianStress::BorePoint
  MeridianStress::locate(const Point<2> &p, const unsigned int body, double &distance) const
  {
    BorePoint best;
    distance = std::numeric_limits<double>::max();
    for (const auto &cell : model.dofs().active_cell_iterators())
      {
        if (cell->material_id() != body)
          continue;
        Point<2> unit;
        try
          {
            unit = model.mapping().transform_real_to_unit_cell(cell, p);
          }
        catch (const Mapping<2>::ExcTransformationFailed &)
          {
            continue;
          }
        Point<2> y;
        for (unsigned int d = 0; d < 2; ++d)
          y[d] = std::clamp(unit[d], 0., 1.);
        const double d = y.distance(unit);
        // ties (a point on an edge between two cells): the first cell
        if (d < distance - 1e-12)
          {
            distance  = d;
            best.cell = cell;
            best.unit = y;
          }
      }
    return best;
  }

  std::array<double, 4>
  MeridianStress::strains(const DoFHandler<2>::active_cell_iterator &cell,
                          const Point<2>                            &unit,
                          const Vector<double>                      &u) const
  {
    FEValues<2> fe_values(model.mapping(), model.dofs().get_fe(),
                          Quadrature<2>(std::vector<Point<2>>(1, unit)),
                          update_values | update_gradients | update_quadrature_points);
    fe_values.reinit(cell);
    std::vector<double>       a(1);
    std::vector<Tensor<1, 2>> ga(1), ge(1);
    fe_values[FEValuesExtractors::Scalar(FourierBasis::a)].get_function_values(u, a);
    fe_values[FEValuesExtractors::Scalar(FourierBasis::a)].get_function_gradients(u, ga);
    fe_values[FEValuesExtractors::Scalar(FourierBasis::e)].get_function_gradients(u, ge);
    return strain_of(a[0], ga[0], ge[0], fe_values.quadrature_point(0)[0]);
  }

  std::vector<StressField::FitBore>
  MeridianStress::bore(const PETScWrappers::MPI::Vector &u_petsc,
                       const std::vector<double>        &pair_pressure) const
  {
    const Vector<double> u(u_petsc);
    std::vector<FitBore> result(fit_list.size());
    for (unsigned int f = 0; f < fit_list.size(); ++f)
      for (unsigned int side = 0; side < 2; ++side)
        {
          const BorePoint &b    = points[f][side];
          const Body      &body = model.bodies()[b.cell->material_id()];
          const auto       e    = strains(b.cell, b.unit, u);
          BoreStress       s =
            b.surface ? surface_stress(e[1], e[2], 0., b.on_fit ? -ring_pressure(f, pair_pressure) : 0.,
                                       body.lambda(), body.mu()) :
                        full_stress(e, body);
          s.radius                                   = side == 0 ? fit_list[f].radius : fit_list[f].shaft_bore;
          (side == 0 ? result[f].hub : result[f].shaft) = s;
        }
    return result;
  }

  std::vector<StressField::Peak>
  MeridianStress::max_von_mises(const PETScWrappers::MPI::Vector &u_petsc) const
  {
    const Vector<double> u(u_petsc);
    std::vector<Peak>    peak(model.bodies().size(), Peak{-1., Point<3>()});
    const auto           quadrature = model.cell_quadrature();
    FEValues<2>          fe_values(model.mapping(), model.dofs().get_fe(), quadrature,
                                   update_values | update_gradients | update_quadrature_points);
    const unsigned int        nq = quadrature.size();
    std::vector<double>       a(nq);
    std::vector<Tensor<1, 2>> ga(nq), ge(nq);
    for (const auto &cell : model.dofs().active_cell_iterators())
      {
        fe_values.reinit(cell);
        fe_values[FEValuesExtractors::Scalar(FourierBasis::a)].get_function_values(u, a);
        fe_values[FEValuesExtractors::Scalar(FourierBasis::a)].get_function_gradients(u, ga);
        fe_values[FEValuesExtractors::Scalar(FourierBasis::e)].get_function_gradients(u, ge);
        const unsigned int b = cell->material_id();
        for (unsigned int q = 0; q < nq; ++q)
          {
            const Point<2> &x = fe_values.quadrature_point(q);
            const double    s = full_stress(strain_of(a[q], ga[q], ge[q], x[0]), model.bodies()[b]).von_mises;
            const Point<3>  at(x[0], 0., x[1]);
            if (before(s, at, peak[b].von_mises, peak[b].location))
              peak[b] = Peak{s, at};
          }
      }
    for (auto &p : peak)
      if (p.von_mises < 0) // no cells
        p = Peak();
    return peak;
  }
} // namespace rotorfit
