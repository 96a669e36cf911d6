#include <rotorfit/contact/pair_space_law.h>
#include <rotorfit/linear_algebra/blas.h>

#include <deal.II/lac/lapack_full_matrix.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    constexpr double infinity = std::numeric_limits<double>::infinity();

    /// C = A B (@p transpose_a: A^T B) for a row-major n x n A; B and C are
    /// n x 2, column-major (the two load cases).
    void
    times_two(const std::vector<double> &a, const bool transpose_a, const double *b, double *c,
              const int n)
    {
      // row-major A is column-major A^T
      const char   t = transpose_a ? 'N' : 'T', nt = 'N';
      const int    two = 2;
      const double one = 1, zero = 0;
      dgemm_(&t, &nt, &n, &two, &n, &one, a.data(), &n, b, &n, &zero, c, &n);
    }
  } // namespace

  void
  PairSpaceLaw::initialize(const ContactParameters &parameters_,
                           const ContactPairs      &pairs_,
                           const PairOperators     &operators,
                           const MPI_Comm           comm_,
                           const double             w_max_)
  {
    parameters          = &parameters_;
    pairs               = &pairs_;
    ops                 = &operators;
    comm                = comm_;
    w_max               = w_max_;
    worst_pair_residual = 0;
    low_rank_updates    = 0;
    inverse_active.clear();
  }

  void
  PairSpaceLaw::set_flexibility(const std::vector<std::vector<double>> &column,
                                const std::vector<bool>                &base_active)
  {
    const unsigned int n = column.size();
    flexibility.resize(std::size_t(n) * n);
    for (unsigned int j = 0; j < n; ++j)
      for (unsigned int i = 0; i < n; ++i)
        flexibility[std::size_t(i) * n + j] = column[j][i];
    base_spring.assign(n, 0.);
    for (unsigned int i = 0; i < n; ++i)
      base_spring[i] = base_active[i] ? ops->penalty(i) : 0.;
    inverse_active.clear();
  }

  void
  PairSpaceLaw::set_centrifugal_load(std::vector<double> &&t)
  {
    t_C = std::move(t);
  }

  void
  PairSpaceLaw::clear()
  {
    // (n_pairs^2 each, 15 MB on TS's benchmark mesh)
    for (auto *v : {&flexibility, &inverse, &t_C, &base_spring})
      std::vector<double>().swap(*v);
  }

  void
  PairSpaceLaw::row(const unsigned int   i,
                    const bool           closed,
                    std::vector<double> &values,
                    double              &rhs_I,
                    double              &rhs_C) const
  {
    // u = K_base^-1 (F + B q), g = t + F q - delta, and the contact force
    // N = q - e (g + delta) with e the base springs. Closed (augmented
    // Lagrangian): g_i = 0, scaled by eps_i. Closed (penalty): N_i = -eps_i
    // g_i. Open: N_i = 0.
    const unsigned int n   = ops->size();
    const double      *f   = &flexibility[std::size_t(i) * n];
    const double       eps = ops->penalty(i);
    values.resize(n);
    rhs(i, closed, rhs_I, rhs_C);
    if (closed && parameters->method == ContactParameters::Method::augmented_lagrangian)
      {
        for (unsigned int j = 0; j < n; ++j)
          values[j] = eps * f[j];
        return;
      }
    const double c = closed ? base_spring[i] - eps : base_spring[i];
    for (unsigned int j = 0; j < n; ++j)
      values[j] = -c * f[j];
    values[i] += 1.;
  }

  void
  PairSpaceLaw::rhs(const unsigned int i, const bool closed, double &rhs_I, double &rhs_C) const
  {
    const double delta = pairs->pairs()[i].interference;
    const double eps   = ops->penalty(i);
    if (closed && parameters->method == ContactParameters::Method::augmented_lagrangian)
      {
        rhs_I = eps * delta;
        rhs_C = -eps * t_C[i];
        return;
      }
    rhs_I = closed ? eps * delta : 0.;
    rhs_C = (closed ? base_spring[i] - eps : base_spring[i]) * t_C[i];
  }

  void
  PairSpaceLaw::invert(const std::vector<bool> &active)
  {
    const unsigned int       n = active.size();
    LAPACKFullMatrix<double> a(n, n);
    std::vector<double>      r;
    double                   r_I, r_C;
    for (unsigned int i = 0; i < n; ++i)
      {
        row(i, active[i], r, r_I, r_C);
        for (unsigned int j = 0; j < n; ++j)
          a(i, j) = r[j];
      }
    a.invert();
    inverse.resize(std::size_t(n) * n);
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = 0; j < n; ++j)
        inverse[std::size_t(i) * n + j] = a(i, j);
    inverse_active = active;
  }

  void
  PairSpaceLaw::update_inverse(const std::vector<bool> &active)
  {
    const unsigned int        n = active.size();
    std::vector<unsigned int> changed;
    for (unsigned int i = 0; i < n && inverse_active.size() == n; ++i)
      if (active[i] != inverse_active[i])
        changed.push_back(i);
    // few changed rows: Sherman-Morrison on the inverse, O(n^2) each; many:
    // invert anew, O(n^3)
    if (inverse_active.size() != n || changed.size() > 32)
      invert(active);
    else
      for (const unsigned int k : changed)
        if (!update_row(k, active))
          break;
    if (!changed.empty())
      ++low_rank_updates;
  }

  bool
  PairSpaceLaw::update_row(const unsigned int k, const std::vector<bool> &active)
  {
    // row k changes by v: Z' = Z - (Z e_k)(v^T Z) / (1 + v^T Z e_k);
    // Z row-major is Z^T column-major for BLAS: y = Z^T v, Z^T -= y z_k^T / d
    const unsigned int  n = active.size();
    std::vector<double> new_row, old_row;
    double              r_I, r_C;
    row(k, inverse_active[k], old_row, r_I, r_C);
    row(k, active[k], new_row, r_I, r_C);
    std::vector<double> y(n), z_k(n);
    for (unsigned int j = 0; j < n; ++j)
      new_row[j] -= old_row[j];
    const int    nn = n, inc = 1;
    const double one = 1, zero = 0;
    const char   no = 'N';
    dgemv_(&no, &nn, &nn, &one, inverse.data(), &nn, new_row.data(), &inc, &zero, y.data(), &inc);
    for (unsigned int i = 0; i < n; ++i)
      z_k[i] = inverse[std::size_t(i) * n + k];
    const double denominator = 1. + y[k];
    if (!(std::abs(denominator) > 1e-12))
      {
        invert(active); // near-singular update: start afresh
        return false;
      }
    const double factor = -1. / denominator;
    dger_(&nn, &nn, &factor, y.data(), &inc, z_k.data(), &inc, inverse.data(), &nn);
    inverse_active[k] = active[k];
    return true;
  }

  double
  PairSpaceLaw::solve_rows(const std::vector<bool>   &active,
                           const std::vector<double> &rhs,
                           ContactDecomposition      &next) const
  {
    // q = Z rhs and F q for both load cases (n x 2, column-major)
    const unsigned int  n = active.size();
    std::vector<double> q(2 * n), fq(2 * n);
    times_two(inverse, false, rhs.data(), q.data(), n);
    times_two(flexibility, false, q.data(), fq.data(), n);
    next.q_I.assign(q.begin(), q.begin() + n);
    next.q_C.assign(q.begin() + n, q.end());
    // g = t + F q - delta, N = q - e (g + delta)
    next.gap_I.resize(n);
    next.gap_C.resize(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        next.gap_I[i] = fq[i] - pairs->pairs()[i].interference;
        next.gap_C[i] = t_C[i] + fq[n + i];
      }
    next.force_I.assign(n, 0.);
    next.force_C.assign(n, 0.);
    double residual = 0, scale = 0;
    for (unsigned int i = 0; i < n; ++i)
      {
        const double delta = pairs->pairs()[i].interference;
        const double eps   = ops->penalty(i);
        const double e     = base_spring[i];
        const double n_I   = next.q_I[i] - e * (next.gap_I[i] + delta);
        const double n_C   = next.q_C[i] - e * next.gap_C[i];
        // the row equations, in forces (w_max scales the unit load case)
        double r_I, r_C;
        if (!active[i])
          r_I = n_I, r_C = n_C;
        else if (parameters->method == ContactParameters::Method::augmented_lagrangian)
          r_I = eps * next.gap_I[i], r_C = eps * next.gap_C[i];
        else
          r_I = n_I + eps * next.gap_I[i], r_C = n_C + eps * next.gap_C[i];
        residual = std::max({residual, std::abs(r_I), std::abs(w_max * r_C)});
        if (!(residual == residual))
          residual = infinity; // NaN
        scale = std::max({scale, std::abs(eps * delta), std::abs(w_max * n_C)});
        if (active[i])
          {
            next.force_I[i] = n_I;
            next.force_C[i] = n_C;
          }
      }
    return scale > 0 ? residual / scale : residual;
  }

  ContactDecomposition
  PairSpaceLaw::decompose(const std::vector<bool> &active)
  {
    const unsigned int n = active.size();
    update_inverse(active);

    ContactDecomposition next;
    next.active  = active;
    next.affine  = true;
    next.w_fixed = 0;
    // q = Z rhs, checked against the rows themselves (a drifting inverse
    // is rebuilt once)
    std::vector<double> rhs(2 * n);
    for (unsigned int i = 0; i < n; ++i)
      this->rhs(i, active[i], rhs[i], rhs[n + i]);
    for (unsigned int attempt = 0; attempt < 2; ++attempt)
      {
        const double relative = solve_rows(active, rhs, next);
        if (relative <= 1e-10 || attempt == 1)
          {
            worst_pair_residual  = std::max(worst_pair_residual, relative);
            next.uzawa_converged = relative <= 1e-8;
            break;
          }
        invert(active);
      }
    // every rank takes rank 0's numbers: the active-set decisions must be
    // bitwise identical, and a threaded BLAS need not be
    for (auto *v : {&next.q_I, &next.q_C, &next.gap_I, &next.gap_C, &next.force_I, &next.force_C})
      MPI_Bcast(v->data(), n, MPI_DOUBLE, 0, comm);
    int ok = next.uzawa_converged;
    MPI_Bcast(&ok, 1, MPI_INT, 0, comm);
    next.uzawa_converged = ok;
    next.pressure_I      = pairs->pressure(next.force_I);
    next.pressure_C      = pairs->pressure(next.force_C);
    next.valid           = true;
    return next;
  }
} // namespace rotorfit
