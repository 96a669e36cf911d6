#include <rotorfit/base/resources.h>
#include <rotorfit/eigen/reduced_model.h>

#include <algorithm>

namespace rotorfit
{
  using namespace dealii;

  ReducedModel::ReducedModel(const SpeedTangent &operators, const Bearings &bearings)
    : operators(operators)
    , bearings(bearings)
  {}

  void
  ReducedModel::drop_projections()
  {
    for (auto *av : {&p.av_mass, &p.av_gyro, &p.av_tangent, &p.av_tangent2, &p.av_bearing_c})
      av->clear();
    basis_projected = false;
    key_tangent.reset();
    key_bearing.reset();
    check.reset();
    lasting_basis = false;
  }

  void
  ReducedModel::clear()
  {
    reduced.clear();
    drop_projections();
  }

  unsigned int
  ReducedModel::add(const std::vector<const Vector<double> *> &x,
                    const PETScWrappers::MPI::SparseMatrix    &M)
  {
    const unsigned int added = reduced.add(x, M);
    if (added > 0)
      drop_projections();
    return added;
  }

  void
  ReducedModel::free_products()
  {
    for (auto *av : {&p.av_mass, &p.av_gyro, &p.av_tangent, &p.av_tangent2, &p.av_bearing_c})
      av->clear();
    basis_projected = false;
    key_tangent.reset();
    key_bearing.reset();
    resources::give_back_free_memory();
  }

  void
  ReducedModel::update_projections(const StaticState &state)
  {
    if (!basis_projected)
      {
        p.mass          = reduced.project(operators.mass(), &p.av_mass);
        p.gyro          = reduced.project(operators.speed_independent().gyroscopic, &p.av_gyro);
        basis_projected = true;
      }
    // K_t = K_t0 + w K_t2 on an active set's affine law (doc/theory.md B):
    // one projection per segment; otherwise (spin softening, bearing
    // coefficients that change with speed) one per speed
    const auto stiffening = operators.settings.stiffening;
    const bool affine  = state.decomposition().affine || stiffening == SpeedTangent::StressStiffening::off;
    const bool per_rpm = !affine || bearings.speed_dependent();
    const ProjectionKey tangent{stiffening == SpeedTangent::StressStiffening::off ?
                                  0 :
                                  operators.k_sigma_serial(),
                                per_rpm ? state.rpm : -1};
    if (!(key_tangent == tangent))
      {
        project_tangent(state);
        key_tangent = tangent;
      }
    const ProjectionKey bearing{0, bearings.speed_dependent() ? state.rpm : -1};
    if (!(key_bearing == bearing))
      {
        p.bearing_c = reduced.project(operators.bearing_damping(), &p.av_bearing_c);
        key_bearing = bearing;
      }
  }

  void
  ReducedModel::project_tangent(const StaticState &state)
  {
    const unsigned int m = reduced.size();
    p.tangent2.reinit(m, m);
    p.av_tangent2.clear();
    if (operators.stiffening_moves() && state.decomposition().affine)
      {
        p.tangent2 = reduced.project(operators.centrifugal_stiffness(), &p.av_tangent2);
        if (operators.settings.convective_term && !operators.folded()) // (folded: in k_sigma_C)
          {
            RowBlock convective;
            p.tangent2.add(-1., reduced.project(operators.speed_independent().convective, &convective));
            p.av_tangent2.add(-1., convective);
          }
      }
    p.tangent0       = reduced.project(operators.stiffness(), &p.av_tangent);
    p.tangent_serial = operators.serial();
    p.tangent0.add(-state.w(), p.tangent2);
    p.w_tangent = state.w();
  }

  ReducedModel::Expanded
  ReducedModel::expanded(const std::vector<std::vector<std::complex<double>>> &y,
                         const double                                          omega,
                         const double                                          w,
                         const bool                                            transpose) const
  {
    const std::size_t n = operators.mass().m();
    Expanded          e;
    for (auto *list : {&e.v, &e.m, &e.c, &e.k})
      list->assign(y.size(), ComplexVector{Vector<double>(n), Vector<double>(n)});
    reduced.multiply(nullptr, y, 1., column_pointers(e.v));
    reduced.multiply(&p.av_mass, y, 1., column_pointers(e.m));
    reduced.multiply(&p.av_bearing_c, y, 1., column_pointers(e.c));
    reduced.multiply(&p.av_gyro, y, transpose ? -omega : omega, column_pointers(e.c)); // G^T = -G
    reduced.multiply(&p.av_tangent, y, 1., column_pointers(e.k));
    reduced.multiply(&p.av_tangent2, y, w - p.w_tangent, column_pointers(e.k));
    return e;
  }

  double
  ReducedModel::Expanded::mismatch(const BackwardError &backward_error, const bool transpose) const
  {
    ComplexVector sum[4];
    const std::vector<ComplexVector> *part[4] = {&v, &m, &c, &k};
    for (unsigned int j = 0; j < 4; ++j)
      for (const auto &z : *part[j])
        if (sum[j].re.size() == 0)
          sum[j] = z;
        else
          sum[j].re += z.re, sum[j].im += z.im;
    return v.empty() ? 0. : backward_error.mismatch(sum[0], sum[1], sum[2], sum[3], transpose);
  }

  std::vector<const RowBlock *>
  ReducedModel::residual_blocks() const
  {
    // those kept by their rows last: the Gram matrix back-substitutes them
    // as sparse right-hand sides, the others in blocks across them
    std::vector<const RowBlock *> blocks;
    for (const bool dense : {true, false})
      for (const auto *P : {&p.av_mass, &p.av_bearing_c, &p.av_gyro, &p.av_tangent, &p.av_tangent2})
        if (!P->empty() && P->dense() == dense) // (a product zero everywhere keeps nothing)
          blocks.push_back(P);
    return blocks;
  }

  namespace
  {
    /// The factors of the kept products [M V, C_b V, G V, K_t V, K_t2 V] in
    /// Q(lambda) V y (Q(lambda)^H V y with @p transpose: conj(lambda) and
    /// G^T = -G), as expanded() combines them.
    std::array<std::complex<double>, 5>
    residual_factors(const std::complex<double> lambda,
                     const double               omega,
                     const double               dw,
                     const bool                 transpose)
    {
      const std::complex<double> l = transpose ? std::conj(lambda) : lambda;
      return {l * l, l, (transpose ? -omega : omega) * l, 1., dw};
    }
  } // namespace

  std::vector<ComplexVector>
  ReducedModel::residuals(const std::vector<std::vector<std::complex<double>>> &y,
                          const std::vector<std::complex<double>>              &lambda,
                          const double                                          omega,
                          const double                                          w,
                          const bool                                            transpose) const
  {
    const std::size_t          n = operators.mass().m();
    std::vector<ComplexVector> r(y.size(), ComplexVector{Vector<double>(n), Vector<double>(n)});
    const auto      z    = column_pointers(r);
    const RowBlock *P[5] = {&p.av_mass, &p.av_bearing_c, &p.av_gyro, &p.av_tangent, &p.av_tangent2};
    std::vector<std::vector<std::complex<double>>> scaled(y);
    for (unsigned int k = 0; k < 5; ++k)
      {
        for (std::size_t c = 0; c < y.size(); ++c)
          {
            const auto a = residual_factors(lambda[c], omega, w - p.w_tangent, transpose)[k];
            for (std::size_t j = 0; j < y[c].size(); ++j)
              scaled[c][j] = a * y[c][j];
          }
        reduced.multiply(P[k], scaled, 1., z);
      }
    return r;
  }

  std::vector<std::complex<double>>
  ReducedModel::residual_coefficients(const std::vector<std::complex<double>> &y,
                                      const std::complex<double>               lambda,
                                      const double                             omega,
                                      const double                             w,
                                      const bool                               transpose,
                                      const std::vector<const RowBlock *>     &blocks) const
  {
    // Q(lambda) V y = lambda^2 M V y + lambda (C_b V + omega G V) y +
    // (K_t V + (w - w_tangent) K_t2 V) y, as expanded() makes it; its
    // transpose with conj(lambda) and C_b - omega G
    const auto      a    = residual_factors(lambda, omega, w - p.w_tangent, transpose);
    const RowBlock *P[5] = {&p.av_mass, &p.av_bearing_c, &p.av_gyro, &p.av_tangent, &p.av_tangent2};
    std::vector<std::complex<double>> x;
    for (const auto *block : blocks) // (in the blocks' order, as the Gram matrix's)
      {
        const auto k = std::find(P, P + 5, block) - P;
        for (const auto &c : y)
          x.push_back(a[k] * c);
      }
    return x;
  }

  void
  ReducedModel::row_parts(const std::vector<const Vector<double> *> &x,
                          std::array<std::vector<double>, 5>        &parts) const
  {
    const std::size_t   n = operators.mass().m();
    std::vector<double> X(n * x.size());
    for (std::size_t j = 0; j < x.size(); ++j)
      std::copy(x[j]->begin(), x[j]->end(), X.begin() + j * n);
    const RowBlock *blocks[5] = {&p.av_mass, &p.av_bearing_c, &p.av_gyro, &p.av_tangent,
                                 &p.av_tangent2};
    for (unsigned int b = 0; b < 5; ++b)
      {
        parts[b].assign(reduced.size() * x.size(), 0.);
        if (!blocks[b]->empty())
          reduced.apply_transpose(*blocks[b], X, 1., parts[b]);
      }
  }

  bool
  ReducedModel::product_check_due(const double rpm)
  {
    if (!check || !(check->tangent == *key_tangent) || !(check->bearing == *key_bearing) ||
        check->segment != operators.segment())
      {
        check = ProductCheck{*key_tangent, *key_bearing, operators.segment(), 0, 0., rpm,
                             false, false, true};
        return true;
      }
    // also at the key's second speed: at its first the projections were
    // just made there (w = w_tangent), so the K_t2 share went unchecked
    ++check->speeds;
    check->due = check->speeds == 1 || check->speeds % check_interval == 0;
    return check->due;
  }
} // namespace rotorfit
