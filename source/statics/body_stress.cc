#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/body_stress.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature.h>
#include <deal.II/base/symmetric_tensor.h>

#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    constexpr unsigned int n_angles = 8;

    SymmetricTensor<2, 3>
    stress(const Tensor<2, 3> &grad, const Body &body)
    {
      const SymmetricTensor<2, 3> eps = symmetrize(grad);
      return body.lambda() * trace(eps) * unit_symmetric_tensor<3>() + 2 * body.mu() * eps;
    }

    double
    von_mises(const SymmetricTensor<2, 3> &sigma)
    {
      const SymmetricTensor<2, 3> s = deviator(sigma);
      return std::sqrt(1.5 * scalar_product(s, s));
    }

    /// The point of the reference cell nearest to @p x (Euclidean, unit
    /// coordinates): a clamp on hexahedra; on the tetrahedron {x >= 0,
    /// x0 + x1 + x2 <= 1} max(x - tau, 0) with the least tau >= 0 that
    /// meets the sum.
    Point<3>
    into_reference_cell(const Point<3> &x, const ReferenceCell &reference)
    {
      Point<3> y;
      if (!reference.is_simplex())
        {
          for (unsigned int d = 0; d < 3; ++d)
            y[d] = std::clamp(x[d], 0., 1.);
          return y;
        }
      const auto clip = [&](const double tau) {
        double s = 0;
        for (unsigned int d = 0; d < 3; ++d)
          s += (y[d] = std::max(x[d] - tau, 0.));
        return s;
      };
      if (clip(0) <= 1)
        return y;
      // sum max(x - tau, 0) = 1: the pieces between the sorted coordinates
      std::array<double, 3> v = {{x[0], x[1], x[2]}};
      std::sort(v.begin(), v.end(), std::greater<double>());
      double tau = 0, partial = 0;
      for (unsigned int k = 0; k < 3; ++k)
        {
          partial += v[k];
          const double t = (partial - 1) / (k + 1);
          if (k == 2 || v[k + 1] <= t)
            {
              tau = t;
              break;
            }
        }
      clip(tau);
      return y;
    }

  } // namespace

  BodyStress::BodyStress(const Discretization &model)
    : model(model)
  {
    find_fits(model.pairs());
    for (unsigned int f = 0; f < fit_list.size(); ++f)
      {
        Fit         &fit = fit_list[f];
        const double z   = fit.z_mid();
        // shaft: solid if the axis at z_mid is inside it; else its bore is
        // the smallest vertex radius of its cells that span z_mid
        double distance = 0;
        locate(Point<3>(0, 0, z), fit.shaft_body, distance);
        if (distance > 1e-6)
          {
            fit.shaft_bore = std::numeric_limits<double>::max();
            for (const auto &cell : model.dofs().active_cell_iterators())
              if (cell->material_id() == fit.shaft_body)
                {
                  double lo = std::numeric_limits<double>::max(), hi = -lo, r = lo;
                  for (const unsigned int v : cell->vertex_indices())
                    {
                      const Point<3> &x = cell->vertex(v);
                      lo                = std::min(lo, x[2]);
                      hi                = std::max(hi, x[2]);
                      r                 = std::min(r, std::hypot(x[0], x[1]));
                    }
                  if (lo <= z && z <= hi)
                    fit.shaft_bore = std::min(fit.shaft_bore, r);
                }
          }

        std::array<std::vector<BorePoint>, 2> bore_points;
        for (unsigned int side = 0; side < 2; ++side)
          {
            const unsigned int body = side == 0 ? fit.hub_body : fit.shaft_body;
            const double       r    = side == 0          ? fit.radius * (1 + nudge) :
                                      fit.shaft_bore > 0 ? fit.shaft_bore * (1 + nudge) :
                                                           fit.radius * nudge;
            for (unsigned int k = 0; k < n_angles; ++k)
              {
                // half a step off 0: away from the seam of a meshed cylinder
                const double phi = 2 * numbers::PI * (k + 0.5) / n_angles;
                BorePoint    b   = locate(Point<3>(r * std::cos(phi), r * std::sin(phi), z), body, distance);
                AssertThrow(distance < 1e-3,
                            ExcMessage("BodyStress: the bore point at r = " + std::to_string(r) +
                                       " m, z = " + std::to_string(z) + " m of interface " +
                                       model.interfaces().list()[f].name + " is in no cell of body " +
                                       model.bodies()[body].name));
                b.angle   = phi;
                b.surface = side == 0 || fit.shaft_bore > 0;
                b.pair    = side == 0 ? 0 : -1; // the hub's bore carries the fit's pressure
                bore_points[side].push_back(b);
              }
          }
        points.push_back(bore_points);
      }
  }

  BodyStress::BorePoint
  BodyStress::locate(const Point<3> &p, const unsigned int body, double &distance) const
  {
    const Mapping<3> &mapping = model.mesh().mapping();
    BorePoint         best;
    distance              = std::numeric_limits<double>::max();
    unsigned int best_index = numbers::invalid_unsigned_int;
    for (const auto &cell : model.dofs().active_cell_iterators())
      {
        if (cell->material_id() != body)
          continue;
        // vertex box, widened for curved cells
        Point<3> lo = cell->vertex(0), hi = lo;
        for (const unsigned int v : cell->vertex_indices())
          for (unsigned int d = 0; d < 3; ++d)
            {
              lo[d] = std::min(lo[d], cell->vertex(v)[d]);
              hi[d] = std::max(hi[d], cell->vertex(v)[d]);
            }
        const double margin = 0.25 * lo.distance(hi);
        bool         inside = true;
        for (unsigned int d = 0; d < 3; ++d)
          inside = inside && p[d] >= lo[d] - margin && p[d] <= hi[d] + margin;
        if (!inside)
          continue;
        Point<3> unit;
        try
          {
            unit = mapping.transform_real_to_unit_cell(cell, p);
          }
        catch (const Mapping<3>::ExcTransformationFailed &)
          {
            continue;
          }
        const Point<3> y = into_reference_cell(unit, cell->reference_cell());
        const double   d = y.distance(unit);
        // ties (a point on a face between two cells of the body): lower index
        if (d < distance - 1e-12 || (d <= distance + 1e-12 && cell->active_cell_index() < best_index))
          {
            distance   = std::min(d, distance);
            best_index = cell->active_cell_index();
            best.cell  = cell;
            best.unit  = y;
          }
      }
    return best;
  }

  void
  BodyStress::evaluate(const std::vector<BorePoint>   &bore_points,
                       const PETScWrappers::MPI::Vector &u,
                       const double                      ring_pressure,
                       std::vector<double>              &values) const
  {
    const FEValuesExtractors::Vector displacement(0);
    std::vector<Tensor<2, 3>>        grad(1);
    for (const auto &b : bore_points)
      {
        std::array<double, 4> v = {{0, 0, 0, 0}};
        if (b.cell->is_locally_owned())
          {
            FEValues<3> fe_values(model.mesh().mapping(), model.dofs().get_fe(),
                                  Quadrature<3>(std::vector<Point<3>>(1, b.unit)), update_gradients);
            fe_values.reinit(b.cell);
            fe_values[displacement].get_function_gradients(u, grad);
            const Body                 &body  = model.bodies()[b.cell->material_id()];
            const SymmetricTensor<2, 3> sigma = stress(grad[0], body);
            const Tensor<1, 3> e_r({std::cos(b.angle), std::sin(b.angle), 0.});
            const Tensor<1, 3> e_t({-std::sin(b.angle), std::cos(b.angle), 0.});
            const Tensor<1, 3> e_z({0., 0., 1.});
            if (!b.surface)
              v = {{e_r * (sigma * e_r), e_t * (sigma * e_t), sigma[2][2], von_mises(sigma)}};
            else
              {
                // the strains along the surface and its traction (see bore())
                const SymmetricTensor<2, 3> eps = symmetrize(grad[0]);
                const BoreStress            s   = surface_stress(
                  e_t * (eps * e_t), e_z * (eps * e_z), e_t * (eps * e_z),
                  b.pair >= 0 ? -ring_pressure : 0., body.lambda(), body.mu());
                v = {{s.sigma_r, s.sigma_t, s.sigma_z, s.von_mises}};
              }
          }
        values.insert(values.end(), v.begin(), v.end());
      }
  }

  std::vector<BodyStress::FitBore>
  BodyStress::bore(const PETScWrappers::MPI::Vector &u,
                   const std::vector<double>        &pair_pressure) const
  {
    // 4 values per point, 8 points per side, hub then shaft, per interface;
    // each point from its owner only, so the sum over the ranks is exact
    std::vector<double> values;
    for (unsigned int f = 0; f < points.size(); ++f)
      {
        const double p = ring_pressure(f, pair_pressure);
        for (const auto &side : points[f])
          evaluate(side, u, p, values);
      }
    const int ierr = MPI_Allreduce(MPI_IN_PLACE, values.data(), values.size(), MPI_DOUBLE, MPI_SUM,
                                   model.mpi_communicator());
    AssertThrowMPI(ierr);

    std::vector<FitBore> result(fit_list.size());
    unsigned int         k = 0;
    for (unsigned int f = 0; f < fit_list.size(); ++f)
      for (unsigned int side = 0; side < 2; ++side)
        {
          BoreStress &b = side == 0 ? result[f].hub : result[f].shaft;
          b.radius      = side == 0 ? fit_list[f].radius : fit_list[f].shaft_bore;
          for (unsigned int i = 0; i < n_angles; ++i, k += 4)
            {
              b.sigma_r += values[k] / n_angles;
              b.sigma_t += values[k + 1] / n_angles;
              b.sigma_z += values[k + 2] / n_angles;
              b.von_mises += values[k + 3] / n_angles;
            }
        }
    return result;
  }

  std::vector<BodyStress::Peak>
  BodyStress::max_von_mises(const PETScWrappers::MPI::Vector &u) const
  {
    const unsigned int n_bodies = model.bodies().size();
    std::vector<Peak>  peak(n_bodies, Peak{-1., Point<3>()});
    const auto        &quadrature = model.mesh().cell_quadrature();
    FEValues<3>        fe_values(model.mesh().mapping(), model.dofs().get_fe(), quadrature,
                                 update_gradients | update_quadrature_points);
    const FEValuesExtractors::Vector displacement(0);
    std::vector<Tensor<2, 3>>        grad(quadrature.size());
    for (const auto &cell : model.dofs().active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          fe_values[displacement].get_function_gradients(u, grad);
          const unsigned int body = cell->material_id();
          for (unsigned int q = 0; q < quadrature.size(); ++q)
            {
              const double s = von_mises(stress(grad[q], model.bodies()[body]));
              if (before(s, fe_values.quadrature_point(q), peak[body].von_mises, peak[body].location))
                peak[body] = Peak{s, fe_values.quadrature_point(q)};
            }
        }

    std::vector<double> mine;
    for (const auto &p : peak)
      mine.insert(mine.end(), {p.von_mises, p.location[0], p.location[1], p.location[2]});
    const auto all = Utilities::MPI::all_gather(model.mpi_communicator(), mine);
    for (unsigned int b = 0; b < n_bodies; ++b)
      {
        peak[b] = Peak{-1., Point<3>()};
        for (const auto &rank : all)
          {
            const Point<3> x(rank[4 * b + 1], rank[4 * b + 2], rank[4 * b + 3]);
            if (before(rank[4 * b], x, peak[b].von_mises, peak[b].location))
              peak[b] = Peak{rank[4 * b], x};
          }
        if (peak[b].von_mises < 0) // no cells
          peak[b] = Peak();
      }
    return peak;
  }
} // namespace rotorfit
