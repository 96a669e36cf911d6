#include <rotorfit/linear_algebra/blas.h>
#include <rotorfit/contact/contact_solver.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/lapack_full_matrix.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

// ContactSolver, part 3: the exact path in Omega^2 (doc/theory.md 7.8).
// With every influence column of the base factorisation known, the law of
// any active set is a dense problem in pair space: the pair loads q with
// u = K_base^-1 (F + B q). Following the speed from event to event then
// costs a rank-one update of the pair-space inverse per changed pair and no
// sparse solve; the displacement is made only at the requested speeds.


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

    /// Where a + b w <= 0 on the w axis: [lo, hi].
    void
    nonpositive_range(const double a, const double b, double &lo, double &hi)
    {
      if (b > 0)
        hi = std::min(hi, -a / b);
      else if (b < 0)
        lo = std::max(lo, -a / b);
      else if (a > 0)
        hi = -infinity;
    }
  } // namespace

  void
  ContactSolver::start_path()
  {
    const unsigned int n = pairs->pairs().size();
    factorize_base(current.active, 0.);
    std::vector<unsigned int> all(n);
    for (unsigned int i = 0; i < n; ++i)
      all[i] = i;
    compute_columns(all);
    flexibility.resize(std::size_t(n) * n);
    for (unsigned int j = 0; j < n; ++j)
      for (unsigned int i = 0; i < n; ++i)
        flexibility[std::size_t(i) * n + j] = column[j][i];
    // the dense copy replaces the cache (a new vector of empty columns:
    // assigning {} to a column would keep its storage)
    std::vector<std::vector<double>>(n).swap(column);
    n_cached = 0;

    PETScWrappers::MPI::Vector u(owned, comm), rhs(owned, comm);
    rhs = *F_c;
    solver.solve(u, rhs);
    t_C = project(u);
    base_spring.assign(n, 0.);
    for (unsigned int i = 0; i < n; ++i)
      base_spring[i] = base_active[i] ? epsilon[i] : 0.;
    path_active.clear();
    path_started = true;
  }

  void
  ContactSolver::advance_path(const double w, State &state)
  {
    const unsigned int n     = pairs->pairs().size();
    const std::size_t  limit = 20 * std::size_t(n) + 100;
    for (std::size_t step = 0;; ++step)
      {
        double w_e = infinity;
        for (unsigned int i = 0; i < n; ++i)
          w_e = std::min(w_e, event_w(i, path_w));
        if (!(w_e < w))
          return;
        if (step == limit)
          {
            state.converged = false;
            state.reason += std::string(state.reason.empty() ? "" : "; ") +
                            "more than " + std::to_string(limit) +
                            " contact events before this speed (pairs chattering)";
            return;
          }
        // the new set just past the event: pairs whose roots coincide to
        // rounding (a ring of a symmetric mesh) change together, and pairs
        // pulled along by the change follow in the active-set iteration
        const double w_s = std::min(w_e + 1e-10 * std::max(w_e, w), 0.5 * (w_e + w));
        const std::vector<bool> before = current.active;
        settle(w_s, state);
        for (unsigned int i = 0; i < n; ++i)
          if (before[i] != current.active[i])
            state.events.push_back({w_e, i, before[i]});
        path_w = w_s;
      }
  }

  double
  ContactSolver::event_w(const unsigned int i, const double w) const
  {
    double lo = -infinity, hi = infinity;
    if (current.active[i])
      {
        // opens where both its pressure and its own force are tensile
        nonpositive_range(current.pressure_I[i], current.pressure_C[i], lo, hi);
        nonpositive_range(current.force_I[i], current.force_C[i], lo, hi);
        return (lo > w && lo <= hi) ? lo : infinity;
      }
    // closes where it penetrates
    if (current.gap_C[i] < 0)
      {
        const double root = -current.gap_I[i] / current.gap_C[i];
        if (root > w)
          return root;
      }
    return infinity;
  }

  void
  ContactSolver::pair_space_row(const unsigned int   i,
                                const bool           closed,
                                std::vector<double> &row,
                                double              &rhs_I,
                                double              &rhs_C) const
  {
    // u = K_base^-1 (F + B q), g = t + F q - delta, and the contact force
    // N = q - e (g + delta) with e the base springs. Closed (augmented
    // Lagrangian): g_i = 0, scaled by eps_i. Closed (penalty): N_i = -eps_i
    // g_i. Open: N_i = 0.
    const unsigned int n   = pairs->pairs().size();
    const double      *f   = &flexibility[std::size_t(i) * n];
    const double       eps = epsilon[i];
    row.resize(n);
    pair_space_rhs(i, closed, rhs_I, rhs_C);
    if (closed && contact_method == Method::augmented_lagrangian)
      {
        for (unsigned int j = 0; j < n; ++j)
          row[j] = eps * f[j];
        return;
      }
    const double c = closed ? base_spring[i] - eps : base_spring[i];
    for (unsigned int j = 0; j < n; ++j)
      row[j] = -c * f[j];
    row[i] += 1.;
  }

  void
  ContactSolver::pair_space_rhs(const unsigned int i, const bool closed, double &rhs_I,
                                double &rhs_C) const
  {
    const double delta = pairs->pairs()[i].interference;
    const double eps   = epsilon[i];
    if (closed && contact_method == Method::augmented_lagrangian)
      {
        rhs_I = eps * delta;
        rhs_C = -eps * t_C[i];
        return;
      }
    rhs_I = closed ? eps * delta : 0.;
    rhs_C = (closed ? base_spring[i] - eps : base_spring[i]) * t_C[i];
  }

  void
  ContactSolver::invert_pair_space(const std::vector<bool> &active)
  {
    const unsigned int         n = active.size();
    LAPACKFullMatrix<double>   a(n, n);
    std::vector<double>        row;
    double                     r_I, r_C;
    for (unsigned int i = 0; i < n; ++i)
      {
        pair_space_row(i, active[i], row, r_I, r_C);
        for (unsigned int j = 0; j < n; ++j)
          a(i, j) = row[j];
      }
    a.invert();
    path_inverse.resize(std::size_t(n) * n);
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = 0; j < n; ++j)
        path_inverse[std::size_t(i) * n + j] = a(i, j);
    path_active = active;
  }

  void
  ContactSolver::pair_space_decomposition(const std::vector<bool> &active)
  {
    const unsigned int n = active.size();
    std::vector<unsigned int> changed;
    for (unsigned int i = 0; i < n && path_active.size() == n; ++i)
      if (active[i] != path_active[i])
        changed.push_back(i);
    std::vector<double> row, old_row, rhs(2 * n);
    double              r_I, r_C;
    // few changed rows: Sherman-Morrison on the inverse, O(n^2) each; many:
    // invert anew, O(n^3)
    if (path_active.size() != n || changed.size() > 32)
      invert_pair_space(active);
    else
      for (const unsigned int k : changed)
        {
          // row k changes by v: Z' = Z - (Z e_k)(v^T Z) / (1 + v^T Z e_k);
          // Z row-major is Z^T column-major for BLAS: y = Z^T v, Z^T -= y z_k^T / d
          pair_space_row(k, path_active[k], old_row, r_I, r_C);
          pair_space_row(k, active[k], row, r_I, r_C);
          std::vector<double> y(n), z_k(n);
          for (unsigned int j = 0; j < n; ++j)
            row[j] -= old_row[j];
          const int    nn = n, inc = 1;
          const double one = 1, zero = 0;
          const char   no = 'N';
          dgemv_(&no, &nn, &nn, &one, path_inverse.data(), &nn, row.data(), &inc, &zero, y.data(),
                 &inc);
          for (unsigned int i = 0; i < n; ++i)
            z_k[i] = path_inverse[std::size_t(i) * n + k];
          const double denominator = 1. + y[k];
          if (!(std::abs(denominator) > 1e-12))
            {
              invert_pair_space(active); // near-singular update: start afresh
              break;
            }
          const double factor = -1. / denominator;
          dger_(&nn, &nn, &factor, y.data(), &inc, z_k.data(), &inc, path_inverse.data(), &nn);
          path_active[k] = active[k];
        }
    if (!changed.empty())
      ++low_rank_updates;

    Decomposition next;
    next.active  = active;
    next.affine  = true;
    next.w_fixed = 0;
    // q = Z rhs, checked against the rows themselves (a drifting inverse
    // is rebuilt once)
    for (unsigned int i = 0; i < n; ++i)
      pair_space_rhs(i, active[i], rhs[i], rhs[n + i]);
    for (unsigned int attempt = 0; attempt < 2; ++attempt)
      {
        // q = Z rhs and F q for both load cases (n x 2, column-major)
        std::vector<double> q(2 * n), fq(2 * n);
        times_two(path_inverse, false, rhs.data(), q.data(), n);
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
            const double e     = base_spring[i];
            const double n_I   = next.q_I[i] - e * (next.gap_I[i] + delta);
            const double n_C   = next.q_C[i] - e * next.gap_C[i];
            // the row equations, in forces (w_max scales the unit load case)
            double r_I, r_C;
            if (!active[i])
              r_I = n_I, r_C = n_C;
            else if (contact_method == Method::augmented_lagrangian)
              r_I = epsilon[i] * next.gap_I[i], r_C = epsilon[i] * next.gap_C[i];
            else
              r_I = n_I + epsilon[i] * next.gap_I[i], r_C = n_C + epsilon[i] * next.gap_C[i];
            residual = std::max({residual, std::abs(r_I), std::abs(w_max * r_C)});
            if (!(residual == residual))
              residual = infinity; // NaN
            scale = std::max({scale, std::abs(epsilon[i] * delta), std::abs(w_max * n_C)});
            if (active[i])
              {
                next.force_I[i] = n_I;
                next.force_C[i] = n_C;
              }
          }
        const double relative = scale > 0 ? residual / scale : residual;
        if (relative <= 1e-10 || attempt == 1)
          {
            worst_pair_residual = std::max(worst_pair_residual, relative);
            next.uzawa_converged = relative <= 1e-8;
            break;
          }
        invert_pair_space(active);
      }
    // every rank takes rank 0's numbers: the active-set decisions must be
    // bitwise identical, and a threaded BLAS need not be
    for (auto *v : {&next.q_I, &next.q_C, &next.gap_I, &next.gap_C, &next.force_I, &next.force_C})
      MPI_Bcast(v->data(), n, MPI_DOUBLE, 0, comm);
    int ok = next.uzawa_converged;
    MPI_Bcast(&ok, 1, MPI_INT, 0, comm);
    next.uzawa_converged = ok;
    next.pressure_I = pairs->pressure(next.force_I);
    next.pressure_C = pairs->pressure(next.force_C);
    next.valid      = true;
    next.serial     = ++decompositions;
    current         = std::move(next);
  }

  void
  ContactSolver::ensure_displacements()
  {
    if (u_serial == current.serial)
      return;
    const auto start_time = std::chrono::steady_clock::now();
    PETScWrappers::MPI::Vector rhs(owned, comm);
    current.u_I.reinit(owned, comm);
    add_pair_forces(current.q_I, rhs);
    solver.solve(current.u_I, rhs);
    constraints->distribute(current.u_I);
    rhs = *F_c;
    add_pair_forces(current.q_C, rhs);
    current.u_C.reinit(owned, comm);
    solver.solve(current.u_C, rhs);
    constraints->distribute(current.u_C);
    u_serial = current.serial;
    times.solves += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  }
} // namespace rotorfit
