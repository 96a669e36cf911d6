#include <rotorfit/base/patterns.h>
#include <rotorfit/contact/contact_solver.h>
#include <rotorfit/linear_algebra/matrix_pattern.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/full_matrix.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <algorithm>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    double
    seconds_since(const std::chrono::steady_clock::time_point start)
    {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    void
    check(const PetscErrorCode code, const char *what)
    {
      if (code != 0)
        throw std::runtime_error(std::string("PETSc failed in ") + what + " (error " +
                                 std::to_string(code) + ")");
    }

    // Sum over the ranks, bitwise identical on every rank (an allreduce
    // need not be): the active-set decisions and the choice between update
    // and factorisation must never differ between ranks.
    void
    sum_replicated(std::vector<double> &values, const MPI_Comm comm)
    {
      if (Utilities::MPI::n_mpi_processes(comm) == 1)
        return;
      std::vector<double> total(values.size());
      MPI_Reduce(values.data(), total.data(), values.size(), MPI_DOUBLE, MPI_SUM, 0, comm);
      MPI_Bcast(total.data(), total.size(), MPI_DOUBLE, 0, comm);
      values.swap(total);
    }
  } // namespace

  void
  ContactSolver::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Contact");
    prm.declare_entry("Method",
                      "augmented Lagrangian",
                      Patterns::Selection("augmented Lagrangian|penalty"),
                      "Enforcement of the node-to-node contact constraints: "
                      "'penalty' leaves a penetration of about 1/(1 + Penalty "
                      "scale) of the interference; 'augmented Lagrangian' "
                      "(Uzawa) drives it to Uzawa tolerance on the same "
                      "factorisation.");
    prm.declare_entry("Penalty scale",
                      "10",
                      Patterns::Double(0.01, 1e8),
                      "alpha [-], 0.01 .. 1e8 (0 would switch the contact "
                      "off; 1e8 is measured to work on the thin-disk fit; beyond it the "
                      "penalty springs outweigh the elastic stiffness by more "
                      "than half of double precision's digits): each pair's "
                      "penalty is alpha times the mean "
                      "radial diagonal stiffness of its two nodes. 10..100 for "
                      "the augmented Lagrangian, 1e3..1e4 for pure penalty.");
    prm.declare_entry("Maximum active set iterations",
                      "30",
                      Patterns::Integer(1),
                      "Cap on active-set updates per speed.");
    prm.declare_entry("Maximum Uzawa iterations",
                      "100",
                      Patterns::Integer(1),
                      "Cap on multiplier updates per active set and load case "
                      "(augmented Lagrangian only).");
    prm.declare_entry("Uzawa tolerance",
                      "1e-8",
                      patterns::Positive(),
                      "Uzawa stops when max |gap| of the closed pairs is below "
                      "this times the interference [-].");
    prm.declare_entry("Low-rank update limit",
                      "0.25",
                      Patterns::Double(0., 1.),
                      "A changed active set is solved on the last "
                      "factorisation by a low-rank (Woodbury) update while the "
                      "changed pairs whose influence column is not known yet "
                      "are at most this fraction of all pairs; above it the "
                      "matrix is factorised again [-]. 0: factorise every "
                      "active set.");
    prm.declare_entry("Speed path",
                      "exact",
                      Patterns::Selection("exact|sampled"),
                      "'exact': the contact state follows the speed from event "
                      "to event (each pair's opening or closing speed solved from "
                      "its active set's affine law in Omega^2), so opening speeds "
                      "do not depend on the speed step; every influence column "
                      "is computed once and the factorisation is kept for the "
                      "run (memory: 2 n^2 doubles for n pairs). 'sampled': the "
                      "active set is settled at each requested speed only. With "
                      "Physics/Spin softening the law is not affine and the "
                      "path is sampled.");
    prm.declare_entry("Constraint error limit",
                      "0.01",
                      patterns::Positive(),
                      "Pure penalty: a speed whose constraint error max |gap| / "
                      "interference of the closed pairs exceeds this is flagged "
                      "converged = 0 [-] (the augmented Lagrangian uses 10 x "
                      "Uzawa tolerance).");
    prm.leave_subsection();
  }

  void
  ContactSolver::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Contact");
    contact_method = (prm.get("Method") == "penalty" ?
                        Method::penalty :
                        Method::augmented_lagrangian);
    alpha = prm.get_double("Penalty scale");
    max_active_set_iterations =
      prm.get_integer("Maximum active set iterations");
    max_uzawa_iterations = prm.get_integer("Maximum Uzawa iterations");
    uzawa_tolerance      = prm.get_double("Uzawa tolerance");
    update_limit         = prm.get_double("Low-rank update limit");
    penalty_error_limit  = prm.get_double("Constraint error limit");
    requested_path       = prm.get("Speed path") == "exact" ? Path::exact : Path::sampled;
    prm.leave_subsection();
    solver.parse_parameters(prm);
  }

  void
  ContactSolver::initialize(const StaticSystem &system, const double w_max_)
  {
    const ContactPairs                     &pairs_       = system.pairs;
    const AffineConstraints<double>        &constraints_ = system.constraints;
    const PETScWrappers::MPI::SparseMatrix &stiffness    = system.stiffness;
    const PETScWrappers::MPI::Vector       &unit_load    = system.unit_centrifugal_load;
    const PETScWrappers::MPI::SparseMatrix *m_perp       = system.spin_softening_matrix;
    const Vector<double>                   &diagonal     = system.stiffness_diagonal;
    const IndexSet                         &owned_       = system.owned;
    const MPI_Comm                          comm_        = system.comm;
    pairs       = &pairs_;
    constraints = &constraints_;
    K           = &stiffness;
    F_c         = &unit_load;
    M_perp      = m_perp;
    owned       = owned_;
    comm        = comm_;
    w_max       = w_max_;
    this_rank   = Utilities::MPI::this_mpi_process(comm);
    all_dofs    = complete_index_set(owned.size());

    const auto &list = pairs->pairs();
    epsilon.resize(list.size());
    owner_adds.resize(list.size());
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        const auto &p = list[i];
        const double nx2 = p.normal[0] * p.normal[0], ny2 = p.normal[1] * p.normal[1];
        const double k_s = nx2 * diagonal[p.shaft_dofs[0]] + ny2 * diagonal[p.shaft_dofs[1]];
        const double k_h = nx2 * diagonal[p.hub_dofs[0]] + ny2 * diagonal[p.hub_dofs[1]];
        epsilon[i]    = alpha * 0.5 * (k_s + k_h);
        owner_adds[i] = owned.is_element(p.shaft_dofs[0]);
      }
    // b_i = +n on the hub node, -n on the shaft node, condensed by the
    // (homogeneous, replicated) static constraints
    projection.assign(list.size(), {});
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        const auto &p = list[i];
        std::map<types::global_dof_index, double> b;
        const std::pair<types::global_dof_index, double> raw[4] = {
          {p.hub_dofs[0], p.normal[0]},
          {p.hub_dofs[1], p.normal[1]},
          {p.shaft_dofs[0], -p.normal[0]},
          {p.shaft_dofs[1], -p.normal[1]}};
        for (const auto &[dof, a] : raw)
          if (constraints->is_constrained(dof))
            {
              // the pair-space algebra assumes u = C u_free (no offsets)
              AssertThrow(!constraints->is_inhomogeneously_constrained(dof),
                          ExcMessage("contact DoF with an inhomogeneous constraint"));
              if (const auto *entries = constraints->get_constraint_entries(dof))
                for (const auto &[j, cj] : *entries)
                  b[j] += a * cj;
            }
          else
            b[dof] += a;
        projection[i].assign(b.begin(), b.end());
      }
    AssertThrow(owned.is_contiguous(), ExcMessage("PETSc needs contiguous DoF ownership"));
    first_owned = owned.n_elements() > 0 ? owned.nth_index_in_set(0) : 0;
    end_owned   = first_owned + owned.n_elements();

    reinit_with_pattern_of(system_matrix, stiffness);
    current = Decomposition();
    current.active.assign(list.size(), true); // at rest every pair is closed
    base_valid = false;
    column.assign(list.size(), {});
    n_cached          = 0;
    low_rank_updates  = 0;
    influence_columns = 0;
    times             = Timing();
    path_started      = false;
    path_finished     = false;
    path_w            = 0;
    u_serial          = 0;
    worst_pair_residual = 0;
    path_active.clear();
  }

  std::vector<double>
  ContactSolver::project(const PETScWrappers::MPI::Vector &x) const
  {
    std::vector<double> t(projection.size(), 0.);
    const PetscScalar  *a;
    check(VecGetArrayRead(x, &a), "VecGetArrayRead");
    for (unsigned int i = 0; i < projection.size(); ++i)
      for (const auto &[dof, b] : projection[i])
        if (dof >= first_owned && dof < end_owned)
          t[i] += b * a[dof - first_owned];
    check(VecRestoreArrayRead(x, &a), "VecRestoreArrayRead");
    sum_replicated(t, comm);
    return t;
  }

  void
  ContactSolver::add_pair_forces(const std::vector<double>  &f,
                                 PETScWrappers::MPI::Vector &rhs) const
  {
    PetscScalar *a;
    check(VecGetArray(rhs, &a), "VecGetArray");
    for (unsigned int i = 0; i < projection.size(); ++i)
      if (f[i] != 0)
        for (const auto &[dof, b] : projection[i])
          if (dof >= first_owned && dof < end_owned)
            a[dof - first_owned] += b * f[i];
    check(VecRestoreArray(rhs, &a), "VecRestoreArray");
  }

  void
  ContactSolver::compute_columns(const std::vector<unsigned int> &missing)
  {
    // blocks of right-hand sides: MUMPS passes the factors once per block
    constexpr unsigned int block = 64;
    const auto             start_time = std::chrono::steady_clock::now();
    const PetscInt         n_local = end_owned - first_owned;
    const PetscInt         n       = owned.size();
    for (unsigned int start = 0; start < missing.size(); start += block)
      {
        const unsigned int m = std::min<unsigned int>(block, missing.size() - start);
        Mat                B, X;
        check(MatCreateDense(comm, n_local, PETSC_DECIDE, n, m, nullptr, &X), "MatCreateDense");
        PetscInt ld;
        if (Utilities::MPI::n_mpi_processes(comm) == 1)
          {
            // a pair's column has a few nonzeros: MUMPS's sparse right-hand
            // side skips most of the forward substitution (TS: 3.7 x faster)
            std::vector<PetscInt> nonzeros(m);
            for (unsigned int j = 0; j < m; ++j)
              nonzeros[j] = projection[missing[start + j]].size();
            check(MatCreateSeqAIJ(comm, m, n, 0, nonzeros.data(), &B), "MatCreateSeqAIJ");
            for (unsigned int j = 0; j < m; ++j)
              for (const auto &[dof, v] : projection[missing[start + j]])
                check(MatSetValue(B, j, dof, v, ADD_VALUES), "MatSetValue");
            check(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
            check(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
            solver.solve_sparse(X, B);
          }
        else
          {
            check(MatCreateDense(comm, n_local, PETSC_DECIDE, n, m, nullptr, &B), "MatCreateDense");
            PetscScalar *b;
            check(MatDenseGetLDA(B, &ld), "MatDenseGetLDA");
            check(MatDenseGetArray(B, &b), "MatDenseGetArray");
            std::fill(b, b + ld * m, 0.);
            for (unsigned int j = 0; j < m; ++j)
              for (const auto &[dof, v] : projection[missing[start + j]])
                if (dof >= first_owned && dof < end_owned)
                  b[j * ld + (dof - first_owned)] += v;
            check(MatDenseRestoreArray(B, &b), "MatDenseRestoreArray");
            check(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
            check(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
            solver.solve(X, B);
          }

        const PetscScalar *x;
        check(MatDenseGetLDA(X, &ld), "MatDenseGetLDA");
        check(MatDenseGetArrayRead(X, &x), "MatDenseGetArrayRead");
        std::vector<double> t(projection.size() * m, 0.);
        for (unsigned int j = 0; j < m; ++j)
          for (unsigned int i = 0; i < projection.size(); ++i)
            for (const auto &[dof, v] : projection[i])
              if (dof >= first_owned && dof < end_owned)
                t[j * projection.size() + i] += v * x[j * ld + (dof - first_owned)];
        check(MatDenseRestoreArrayRead(X, &x), "MatDenseRestoreArrayRead");
        MatDestroy(&B);
        MatDestroy(&X);
        sum_replicated(t, comm);
        for (unsigned int j = 0; j < m; ++j)
          column[missing[start + j]].assign(t.begin() + j * projection.size(),
                                            t.begin() + (j + 1) * projection.size());
      }
    n_cached += missing.size();
    influence_columns += missing.size();
    times.columns += seconds_since(start_time);
  }

  void
  ContactSolver::factorize_base(const std::vector<bool> &active, const double w)
  {
    const auto &list = pairs->pairs();
    // K + sum_A eps B B^T (- w M_perp): symmetric
    MatCopy(*K, system_matrix, SAME_NONZERO_PATTERN);
    FullMatrix<double>                   local(4, 4);
    std::vector<types::global_dof_index> dofs(4);
    for (unsigned int i = 0; i < list.size(); ++i)
      if (active[i] && owner_adds[i])
        {
          const auto &p = list[i];
          dofs = {p.hub_dofs[0], p.hub_dofs[1], p.shaft_dofs[0], p.shaft_dofs[1]};
          const double b[4] = {p.normal[0], p.normal[1], -p.normal[0], -p.normal[1]};
          for (unsigned int a = 0; a < 4; ++a)
            for (unsigned int c = 0; c < 4; ++c)
              local(a, c) = epsilon[i] * b[a] * b[c];
          constraints->distribute_local_to_global(local, dofs, system_matrix);
        }
    system_matrix.compress(VectorOperation::add);
    if (M_perp != nullptr)
      {
        MatAXPY(system_matrix, -w, *M_perp, SAME_NONZERO_PATTERN);
        system_matrix.compress(VectorOperation::insert);
      }
    const auto start_time = std::chrono::steady_clock::now();
    solver.factorize(system_matrix);
    times.factorize += seconds_since(start_time);
    clear_update();
    base_active = active;
    base_w      = w;
    base_valid  = true;
  }

  void
  ContactSolver::release_factorization()
  {
    if (exact_path() && path_started)
      return; // the path makes its displacements on this factorisation
    solver.release();
    clear_update();
    base_valid = false;
  }

  void
  ContactSolver::finish_path()
  {
    solver.release();
    clear_update();
    system_matrix.clear();
    // every speed's state is made: the pair-space matrices (n_pairs^2 each,
    // 15 MB on TS's benchmark mesh) are not needed any more
    for (auto *v : {&flexibility, &path_inverse, &t_C, &base_spring})
      std::vector<double>().swap(*v);
    base_valid    = false;
    path_finished = true;
  }

  void
  ContactSolver::clear_update()
  {
    // new empty columns: assigning {} would keep each column's storage
    std::vector<std::vector<double>>(column.size()).swap(column);
    n_cached = 0;
    woodbury.clear();
  }

  bool
  ContactSolver::prepare_update(const std::vector<bool> &active)
  {
    const unsigned int        n = active.size();
    std::vector<unsigned int> d, missing;
    for (unsigned int i = 0; i < n; ++i)
      if (active[i] != base_active[i])
        {
          d.push_back(i);
          if (column[i].empty())
            missing.push_back(i);
        }
    // the capacitance matrix and the cached columns grow with the changed
    // pairs: past the limit a new factorisation is cheaper (and exact)
    const double limit = update_limit * n;
    if (missing.size() > limit || n_cached + missing.size() > 2 * limit ||
        d.size() > 2 * limit)
      return false;
    compute_columns(missing);
    std::vector<double> springs(d.size());
    for (unsigned int a = 0; a < d.size(); ++a)
      springs[a] = (active[d[a]] ? 1. : -1.) * epsilon[d[a]];
    return woodbury.reinit(d, springs, column); // false: singular capacitance, factorise instead
  }

  void
  ContactSolver::check_update(const std::vector<double>  &c,
                              const std::vector<bool>    &active,
                              const std::vector<double>  &force,
                              PETScWrappers::MPI::Vector &rhs,
                              PETScWrappers::MPI::Vector &u)
  {
    const unsigned int  n = pairs->pairs().size();
    std::vector<double> f(n);
    const auto &changed   = woodbury.changed();
    const auto &changed_k = woodbury.springs();
    // u = K_base^-1 (rhs - B_D c); its residual against K_A lives on the
    // changed pairs only: B_D (S B_D^T u - c)
    std::fill(f.begin(), f.end(), 0.);
    for (unsigned int a = 0; a < changed.size(); ++a)
      f[changed[a]] = -c[a];
    add_pair_forces(f, rhs);
    const auto start_time = std::chrono::steady_clock::now();
    solver.solve(u, rhs);
    times.solves += seconds_since(start_time);
    const std::vector<double> t = project(u);
    // written so that a NaN propagates (std::max would drop it)
    double residual = 0, scale = 0;
    for (unsigned int a = 0; a < changed.size(); ++a)
      {
        const double r = std::abs(changed_k[a] * t[changed[a]] - c[a]);
        if (!(r <= residual))
          residual = r;
        scale = std::max(scale, std::abs(c[a]));
      }
    for (unsigned int i = 0; i < n; ++i)
      if (active[i])
        scale = std::max(scale, std::abs(force[i]));
    const double relative = scale > 0 ? residual / scale : residual;
    if (!(relative <= update_residual))
      update_residual = relative;
  }

  unsigned int
  ContactSolver::solve_load_case(const LoadCase          &load,
                                 const std::vector<bool> &active,
                                 std::vector<double>     &force,
                                 std::vector<double>     &gap,
                                 PETScWrappers::MPI::Vector &u)
  {
    const PETScWrappers::MPI::Vector *base_load         = load.load;
    const double                      load_factor       = load.factor;
    const bool                        with_interference = load.with_interference;
    const double                      gap_scale         = load.gap_scale;
    const auto  &list    = pairs->pairs();
    const bool   penalty = (contact_method == Method::penalty);
    const unsigned int n = list.size();
    if (penalty)
      std::fill(force.begin(), force.end(), 0.);
    for (unsigned int i = 0; i < n; ++i)
      if (!active[i])
        force[i] = 0;

    PETScWrappers::MPI::Vector rhs(owned, comm);
    u.reinit(owned, comm);
    std::vector<double> f(n), c;
    unsigned int        iterations = 0;
    for (unsigned int k = 0; k < (penalty ? 1 : max_uzawa_iterations); ++k)
      {
        if (base_load != nullptr)
          {
            rhs = *base_load;
            rhs *= load_factor;
          }
        else
          rhs = 0;
        for (unsigned int i = 0; i < n; ++i)
          f[i] = active[i] ? force[i] + epsilon[i] * (with_interference ? list[i].interference : 0.) : 0.;
        add_pair_forces(f, rhs);
        const auto start_time = std::chrono::steady_clock::now();
        solver.solve(u, rhs);
        times.solves += seconds_since(start_time);
        // B^T K_A^-1 rhs in pair space; u stays K_base^-1 rhs for now
        std::vector<double> t = project(u);
        c                     = woodbury.apply(t, column);

        double worst = 0;
        for (unsigned int i = 0; i < n; ++i)
          {
            gap[i] = t[i] - (with_interference ? list[i].interference : 0.);
            if (active[i])
              {
                force[i] -= epsilon[i] * gap[i];
                worst = std::max(worst, gap_scale * std::abs(gap[i]) / list[i].interference);
              }
          }
        if (!penalty)
          ++iterations;
        if (penalty || worst <= uzawa_tolerance)
          break;
        if (k + 1 == max_uzawa_iterations)
          uzawa_capped = true;
      }
    if (!woodbury.empty())
      check_update(c, active, force, rhs, u);
    constraints->distribute(u);
    return iterations;
  }

  void
  ContactSolver::compute_decomposition(const std::vector<bool> &active,
                                       const double             w)
  {
    if (exact_path())
      {
        pair_space_decomposition(active);
        return;
      }
    const auto &list   = pairs->pairs();
    const bool  affine = (M_perp == nullptr);
    // a low-rank update of the base factorisation where it is cheaper than
    // a new one; a failed residual check falls back to the factorisation
    for (bool update = base_valid && (affine || base_w == w) && update_limit > 0;;
         update      = false)
      {
        if (!(update && prepare_update(active)))
          factorize_base(active, w);

        // continue from the previous multipliers (augmented Lagrangian)
        Decomposition next;
        next.active  = active;
        next.affine  = affine;
        next.w_fixed = w;
        const unsigned int n = list.size();
        next.force_I.assign(n, 0.);
        next.force_C.assign(n, 0.);
        next.gap_I.assign(n, 0.);
        next.gap_C.assign(n, 0.);
        if (current.valid)
          for (unsigned int i = 0; i < n; ++i)
            {
              next.force_I[i] = current.force_I[i] + (affine ? 0. : w * current.force_C[i]);
              next.force_C[i] = current.force_C[i];
            }
        update_residual = 0;
        uzawa_capped    = false;
        if (affine)
          {
            uzawa_count += solve_load_case(LoadCase::interference(), active, next.force_I, next.gap_I, next.u_I);
            if (w_max > 0)
              uzawa_count += solve_load_case(LoadCase::per_unit_w(*F_c, w_max), active, next.force_C, next.gap_C, next.u_C);
            else
              next.u_C.reinit(owned, comm);
          }
        else
          {
            // the solution X(w) and its derivative X'(w) for this active set
            // ((K_A - w M) u' = F_c + M u, same factorisation), stored as the
            // tangent X_I + w' X_C, X_I = X(w) - w X'(w): exact at w, and it
            // predicts the openings up to the next speed to first order
            uzawa_count += solve_load_case(LoadCase::at_speed(*F_c, w), active, next.force_I, next.gap_I, next.u_I);
            PETScWrappers::MPI::Vector u_free = next.u_I, load(owned, comm);
            constraints->set_zero(u_free); // M_perp acts on the condensed u
            M_perp->vmult(load, u_free);
            load += *F_c;
            uzawa_count += solve_load_case(LoadCase::per_unit_w(load, w_max), active, next.force_C, next.gap_C, next.u_C);
            for (unsigned int i = 0; i < n; ++i)
              {
                next.force_I[i] -= w * next.force_C[i];
                next.gap_I[i] -= w * next.gap_C[i];
              }
            next.u_I.add(-w, next.u_C);
          }
        if (!woodbury.empty() && !(update_residual <= 1e-8)) // NaN included
          continue; // the update lost accuracy: factorise this active set
        if (!woodbury.empty())
          ++low_rank_updates;
        // P2 vertex pairs carry almost no force (int psi_i dA = 0), so the
        // sign of their multiplier is noise; the pressure field p = M^-1 N
        // is smooth and decides which pairs are open
        next.pressure_I = pairs->pressure(next.force_I);
        next.pressure_C = pairs->pressure(next.force_C);
        next.valid      = true;
        next.uzawa_converged = !uzawa_capped;
        next.serial     = ++decompositions;
        current         = std::move(next);
        return;
      }
  }

  void
  ContactSolver::displacement(const Decomposition &d, const double w, PETScWrappers::MPI::Vector &u) const
  {
    PETScWrappers::MPI::Vector tmp(owned, comm);
    tmp = d.u_I;
    tmp.add(w, d.u_C);
    u.reinit(owned, all_dofs, comm);
    u = tmp;
  }
} // namespace rotorfit
