#include <algorithm>
#include <rotorfit/harmonic/harmonic_assembler.h>
#include <rotorfit/linear_algebra/skew_part.h>

#include <deal.II/base/index_set.h>

#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <map>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// The Fourier fields of one cell's shape functions at every (quadrature
    /// point, angle point), with the volume weight r JxW 2 pi / N_theta.
    class CellSamples
    {
    public:
      CellSamples(const MeridianModel &model, const FourierBasis &basis,
                  const std::vector<bool> &fields)
        : basis(basis)
        , quadrature(model.cell_quadrature())
        , fe_values(model.mapping(), model.dofs().get_fe(), quadrature,
                    update_values | update_gradients | update_quadrature_points |
                      update_JxW_values)
      {
        const auto &fe = model.dofs().get_fe();
        for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
          {
            const unsigned int c = fe.system_to_component_index(i).first;
            if (basis.active(c) && fields[c])
              {
                local.push_back(i);
                field.push_back(c);
              }
          }
      }

      void
      reinit(const DoFHandler<2>::active_cell_iterator &cell)
      {
        fe_values.reinit(cell);
        const unsigned int nq = quadrature.size(), nt = basis.n_angles(), nl = local.size();
        samples.resize(nq * nt * nl);
        weight.resize(nq * nt);
        radius.resize(nq);
        for (unsigned int q = 0; q < nq; ++q)
          {
            const double r = fe_values.quadrature_point(q)[0];
            radius[q]      = r;
            for (unsigned int m = 0; m < nt; ++m)
              {
                weight[q * nt + m] = r * fe_values.JxW(q) * basis.angle_weight();
                for (unsigned int i = 0; i < nl; ++i)
                  basis.evaluate(field[i],
                                 fe_values.shape_value(local[i], q),
                                 fe_values.shape_grad(local[i], q),
                                 r,
                                 m,
                                 samples[(q * nt + m) * nl + i]);
              }
          }
      }

      unsigned int
      n_points() const
      {
        return weight.size();
      }
      /// Sample of local function i at point p = q * N_theta + m.
      const FourierBasis::Sample &
      operator()(const unsigned int p, const unsigned int i) const
      {
        return samples[p * local.size() + i];
      }

      const FourierBasis         &basis;
      const QGauss<2>             quadrature;
      FEValues<2>                 fe_values;
      std::vector<unsigned int>   local, field; ///< cell dofs used, their fields
      std::vector<FourierBasis::Sample> samples;
      std::vector<double>         weight, radius;
    };

    std::vector<bool>
    all_fields()
    {
      return std::vector<bool>(FourierBasis::n_fields, true);
    }

    /// sigma = lambda tr(eps) I + 2 mu eps of the gradient @p g.
    Tensor<2, 3>
    stress(const Tensor<2, 3> &g, const double lambda, const double mu)
    {
      Tensor<2, 3> s;
      const double tr = trace(g);
      for (unsigned int i = 0; i < 3; ++i)
        {
          for (unsigned int j = 0; j < 3; ++j)
            s[i][j] = mu * (g[i][j] + g[j][i]);
          s[i][i] += lambda * tr;
        }
      return s;
    }

    /// Add the local matrix @p a (rows and columns: the cell's used dofs)
    /// through the expansions of @p free into @p m.
    void
    distribute(const FullMatrix<double>                     &a,
               const std::vector<types::global_dof_index>   &dofs,
               const std::vector<unsigned int>              &local,
               const MeridianModel::FreeDofs                &free,
               SparseMatrix<double>                         &m)
    {
      for (unsigned int i = 0; i < local.size(); ++i)
        for (const auto &[I, wi] : free.expansion[dofs[local[i]]])
          for (unsigned int j = 0; j < local.size(); ++j)
            if (a(i, j) != 0)
              for (const auto &[J, wj] : free.expansion[dofs[local[j]]])
                m.add(I, J, wi * wj * a(i, j));
    }
  } // namespace

  HarmonicAssembler::HarmonicAssembler(const MeridianModel &model)
    : model(model)
  {}

  void
  HarmonicAssembler::assemble_static(StaticSystem  &s,
                                     const bool     spin_softening,
                                     const MPI_Comm comm) const
  {
    const auto        &dof_handler = model.dofs();
    const auto        &constraints = model.static_constraints();
    const IndexSet     all         = complete_index_set(dof_handler.n_dofs());
    const FourierBasis basis(0);
    std::vector<bool>  fields(FourierBasis::n_fields, false);
    fields[FourierBasis::a] = fields[FourierBasis::e] = true;
    CellSamples samples(model, basis, fields);

    DynamicSparsityPattern               dsp(dof_handler.n_dofs());
    std::vector<types::global_dof_index> dofs(dof_handler.get_fe().n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        constraints.add_entries_local_to_global(dofs, dsp, false);
      }
    for (const auto &p : model.pairs().pairs())
      {
        std::vector<types::global_dof_index> d = {p.hub_dofs[0], p.shaft_dofs[0]};
        constraints.add_entries_local_to_global(d, dsp, false);
      }
    s.stiffness.reinit(all, all, dsp, comm);
    if (spin_softening)
      s.spin_softening.reinit(all, all, dsp, comm);
    s.unit_centrifugal_load.reinit(all, comm);
    s.stiffness_diagonal.reinit(dof_handler.n_dofs());
    s.mass.assign(model.bodies().size(), 0.);
    s.polar.assign(model.bodies().size(), 0.);

    const unsigned int nd = dofs.size(), nl = samples.local.size();
    FullMatrix<double> cell_k(nd, nd), cell_m(nd, nd);
    Vector<double>     cell_f(nd);
    std::vector<Tensor<2, 3>> sig(nl);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        samples.reinit(cell);
        const Body  &body   = model.bodies()[cell->material_id()];
        const double lambda = body.lambda(), mu = body.mu(), rho = body.density;
        cell_k = 0;
        cell_m = 0;
        cell_f = 0;
        const unsigned int nt = basis.n_angles();
        for (unsigned int p = 0; p < samples.n_points(); ++p)
          {
            const double       dV = samples.weight[p];
            const double       r  = samples.radius[p / nt];
            const Tensor<1, 3> px = r * basis.value(FourierBasis::a, 1., p % nt); // r e_r
            s.mass[cell->material_id()] += rho * dV;
            s.polar[cell->material_id()] += rho * r * r * dV;
            for (unsigned int i = 0; i < nl; ++i)
              sig[i] = stress(samples(p, i).grad, lambda, mu);
            for (unsigned int i = 0; i < nl; ++i)
              {
                const auto        &si = samples(p, i);
                const unsigned int li = samples.local[i];
                cell_f(li) += rho * (si.value * px) * dV;
                for (unsigned int j = 0; j < nl; ++j)
                  {
                    const auto &sj = samples(p, j);
                    cell_k(li, samples.local[j]) += scalar_product(sig[i], sj.grad) * dV;
                    if (spin_softening)
                      cell_m(li, samples.local[j]) +=
                        rho * (si.value[0] * sj.value[0] + si.value[1] * sj.value[1]) * dV;
                  }
              }
          }
        for (unsigned int i = 0; i < nd; ++i)
          s.stiffness_diagonal[dofs[i]] += cell_k(i, i);
        constraints.distribute_local_to_global(cell_k, cell_f, dofs, s.stiffness,
                                               s.unit_centrifugal_load);
        if (spin_softening)
          constraints.distribute_local_to_global(cell_m, dofs, s.spin_softening);
      }
    s.stiffness.compress(VectorOperation::add);
    s.unit_centrifugal_load.compress(VectorOperation::add);
    if (spin_softening)
      s.spin_softening.compress(VectorOperation::add);
  }

  void
  HarmonicAssembler::assemble_harmonic(const unsigned int          n,
                                       const std::vector<Station> &stations,
                                       Harmonic                   &h) const
  {
    const auto        &dof_handler = model.dofs();
    const FourierBasis basis(n);
    CellSamples        samples(model, basis, all_fields());
    h.n    = n;
    h.free = model.free_dofs(n);
    const auto &free = h.free;

    // pattern: cells, ring ties, stations (dense blocks)
    DynamicSparsityPattern               dsp(free.n_free);
    std::vector<types::global_dof_index> dofs(dof_handler.get_fe().n_dofs_per_cell());
    const auto couple = [&](const std::vector<types::global_dof_index> &list) {
      std::vector<types::global_dof_index> idx;
      for (const auto dof : list)
        for (const auto &[I, w] : free.expansion[dof])
          idx.push_back(I);
      std::sort(idx.begin(), idx.end());
      idx.erase(std::unique(idx.begin(), idx.end()), idx.end());
      for (const auto I : idx)
        dsp.add_entries(I, idx.begin(), idx.end(), true);
    };
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        couple(dofs);
      }
    for (const auto &p : model.pairs().pairs())
      {
        std::vector<types::global_dof_index> list;
        for (const auto node : {model.node_of(p.shaft_dofs[0]), model.node_of(p.hub_dofs[0])})
          list.insert(list.end(), model.nodes()[node].begin(), model.nodes()[node].end());
        couple(list);
      }
    h.station_x.clear();
    h.station_y.clear();
    for (const auto &s : stations)
      {
        std::map<unsigned int, double> ax, ay;
        if (n == 1)
          for (unsigned int k = 0; k < s.weight.size(); ++k)
            {
              for (const auto &[I, w] : free.expansion[s.dof_x[k]])
                ax[I] += s.weight[k] * w;
              for (const auto &[I, w] : free.expansion[s.dof_y[k]])
                ay[I] += s.weight[k] * w;
            }
        h.station_x.emplace_back(ax.begin(), ax.end());
        h.station_y.emplace_back(ay.begin(), ay.end());
        std::vector<types::global_dof_index> list;
        for (const auto *a : {&h.station_x.back(), &h.station_y.back()})
          for (const auto &[I, w] : *a)
            list.push_back(free.dof[I]);
        couple(list);
      }
    h.pattern.copy_from(dsp);
    for (auto *m : {&h.K, &h.M, &h.G, &h.K_theta})
      m->reinit(h.pattern);

    const unsigned int nl = samples.local.size();
    FullMatrix<double> k(nl, nl), m(nl, nl), g(nl, nl), kt(nl, nl);
    std::vector<Tensor<2, 3>> sig(nl);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        samples.reinit(cell);
        const Body  &body   = model.bodies()[cell->material_id()];
        const double lambda = body.lambda(), mu = body.mu(), rho = body.density;
        k  = 0;
        m  = 0;
        g  = 0;
        kt = 0;
        for (unsigned int p = 0; p < samples.n_points(); ++p)
          {
            const double dV = samples.weight[p];
            for (unsigned int i = 0; i < nl; ++i)
              sig[i] = stress(samples(p, i).grad, lambda, mu);
            for (unsigned int i = 0; i < nl; ++i)
              {
                const auto &si = samples(p, i);
                for (unsigned int j = 0; j < nl; ++j)
                  {
                    const auto &sj = samples(p, j);
                    k(i, j) += scalar_product(sig[i], sj.grad) * dV;
                    m(i, j) += rho * (si.value * sj.value) * dV;
                    g(i, j) += 2 * rho * (si.value * sj.d_theta) * dV;
                    kt(i, j) += rho * (si.d_theta * sj.d_theta) * dV;
                  }
              }
          }
        // (a meridian's boundary has t . n = 0: only round-off is removed)
        keep_skew_part(g);
        distribute(k, dofs, samples.local, free, h.K);
        distribute(m, dofs, samples.local, free, h.M);
        distribute(g, dofs, samples.local, free, h.G);
        distribute(kt, dofs, samples.local, free, h.K_theta);
      }

    // ring tie per unit penalty: the mean over the angle of phi_k . phi_l
    h.tie.reinit(FourierBasis::n_fields, FourierBasis::n_fields);
    for (unsigned int a = 0; a < FourierBasis::n_fields; ++a)
      for (unsigned int b = 0; b < FourierBasis::n_fields; ++b)
        if (basis.active(a) && basis.active(b))
          for (unsigned int t = 0; t < basis.n_angles(); ++t)
            h.tie(a, b) += basis.value(a, 1., t) * basis.value(b, 1., t) / basis.n_angles();
  }

  void
  HarmonicAssembler::assemble_prestress(const Harmonic       &h,
                                        const Vector<double> &u,
                                        SparseMatrix<double> &k_sigma) const
  {
    const auto        &dof_handler = model.dofs();
    const FourierBasis basis(h.n);
    // the static field (harmonic 0, fields a and e) on the same angle points
    const FourierBasis basis0(0, basis);
    std::vector<bool>  static_fields(FourierBasis::n_fields, false);
    static_fields[FourierBasis::a] = static_fields[FourierBasis::e] = true;
    CellSamples samples(model, basis, all_fields());
    CellSamples statics(model, basis0, static_fields);
    k_sigma.reinit(h.pattern);
    std::vector<types::global_dof_index> dofs(dof_handler.get_fe().n_dofs_per_cell());
    const unsigned int                   nl = samples.local.size();
    FullMatrix<double>                   ks(nl, nl);
    std::vector<Tensor<2, 3>>            g_sigma(nl);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        samples.reinit(cell);
        statics.reinit(cell);
        const Body &body = model.bodies()[cell->material_id()];
        ks               = 0;
        for (unsigned int p = 0; p < samples.n_points(); ++p)
          {
            Tensor<2, 3> grad_u;
            for (unsigned int i = 0; i < statics.local.size(); ++i)
              grad_u += u[dofs[statics.local[i]]] * statics(p, i).grad;
            const Tensor<2, 3> sigma0 = stress(grad_u, body.lambda(), body.mu());
            const double       dV     = samples.weight[p];
            for (unsigned int i = 0; i < nl; ++i)
              g_sigma[i] = samples(p, i).grad * sigma0;
            for (unsigned int i = 0; i < nl; ++i)
              for (unsigned int j = 0; j < nl; ++j)
                ks(i, j) += scalar_product(g_sigma[i], samples(p, j).grad) * dV;
          }
        distribute(ks, dofs, samples.local, h.free, k_sigma);
      }
  }

  void
  HarmonicAssembler::add_ties(const Harmonic            &h,
                              const std::vector<bool>   &closed,
                              const std::vector<double> &penalty,
                              SparseMatrix<double>      &k) const
  {
    const auto &pairs = model.pairs().pairs();
    for (unsigned int i = 0; i < pairs.size(); ++i)
      {
        if (!closed[i])
          continue;
        const auto &shaft = model.nodes()[model.node_of(pairs[i].shaft_dofs[0])];
        const auto &hub   = model.nodes()[model.node_of(pairs[i].hub_dofs[0])];
        for (unsigned int a = 0; a < FourierBasis::n_fields; ++a)
          for (unsigned int b = 0; b < FourierBasis::n_fields; ++b)
            {
              const double t = penalty[i] * h.tie(a, b);
              if (t == 0)
                continue;
              for (const auto &[row, sr] : {std::pair{hub[a], 1.}, std::pair{shaft[a], -1.}})
                for (const auto &[col, sc] : {std::pair{hub[b], 1.}, std::pair{shaft[b], -1.}})
                  for (const auto &[I, wi] : h.free.expansion[row])
                    for (const auto &[J, wj] : h.free.expansion[col])
                      k.add(I, J, sr * sc * wi * wj * t);
            }
      }
  }

  void
  copy_to_petsc(const SparseMatrix<double>                              &a,
                const std::vector<PETScWrappers::MPI::SparseMatrix *> &targets,
                const MPI_Comm                                         comm)
  {
    const IndexSet         all = complete_index_set(a.m());
    DynamicSparsityPattern dsp(a.m());
    std::vector<types::global_dof_index> cols;
    for (unsigned int i = 0; i < a.m(); ++i)
      {
        cols.clear();
        for (auto it = a.begin(i); it != a.end(i); ++it)
          cols.push_back(it->column());
        std::sort(cols.begin(), cols.end());
        dsp.add_entries(i, cols.begin(), cols.end(), true);
      }
    for (auto *p : targets)
      {
        p->reinit(all, all, dsp, comm);
        copy_values(a, *p);
      }
  }

  void
  copy_values(const SparseMatrix<double> &a, PETScWrappers::MPI::SparseMatrix &p)
  {
    std::vector<types::global_dof_index> cols;
    std::vector<PetscScalar>             vals;
    for (unsigned int i = 0; i < a.m(); ++i)
      {
        cols.clear();
        vals.clear();
        for (auto it = a.begin(i); it != a.end(i); ++it)
          {
            cols.push_back(it->column());
            vals.push_back(it->value());
          }
        p.set(i, cols.size(), cols.data(), vals.data(), false);
      }
    p.compress(VectorOperation::insert);
  }
} // namespace rotorfit
