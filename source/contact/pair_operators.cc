#include <rotorfit/contact/pair_operators.h>

#include <map>
#include <stdexcept>
#include <string>

namespace rotorfit
{
  using namespace dealii;

  void
  check_petsc(const PetscErrorCode code, const char *what)
  {
    if (code != 0)
      throw std::runtime_error(std::string("PETSc failed in ") + what + " (error " +
                               std::to_string(code) + ")");
  }

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

  void
  PairOperators::initialize(const ContactPairs              &pairs,
                            const AffineConstraints<double> &constraints,
                            const Vector<double>            &stiffness_diagonal,
                            const IndexSet                  &owned,
                            const MPI_Comm                   comm_,
                            const double                     penalty_scale)
  {
    comm = comm_;
    make_penalties(pairs, stiffness_diagonal, owned, penalty_scale);
    make_projection(pairs, constraints);
    AssertThrow(owned.is_contiguous(), ExcMessage("PETSc needs contiguous DoF ownership"));
    first_owned = owned.n_elements() > 0 ? owned.nth_index_in_set(0) : 0;
    end_owned   = first_owned + owned.n_elements();
  }

  void
  PairOperators::make_penalties(const ContactPairs   &pairs,
                                const Vector<double> &diagonal,
                                const IndexSet       &owned,
                                const double          alpha)
  {
    const auto &list = pairs.pairs();
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
  }

  void
  PairOperators::make_projection(const ContactPairs              &pairs,
                                 const AffineConstraints<double> &constraints)
  {
    // b_i = +n on the hub node, -n on the shaft node, condensed by the
    // (homogeneous, replicated) static constraints
    const auto &list = pairs.pairs();
    projection.assign(list.size(), {});
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        const auto &p = list[i];
        std::map<types::global_dof_index, double> b;
        const Entry raw[4] = {{p.hub_dofs[0], p.normal[0]},
                              {p.hub_dofs[1], p.normal[1]},
                              {p.shaft_dofs[0], -p.normal[0]},
                              {p.shaft_dofs[1], -p.normal[1]}};
        for (const auto &[dof, a] : raw)
          if (constraints.is_constrained(dof))
            {
              // the pair-space algebra assumes u = C u_free (no offsets)
              AssertThrow(!constraints.is_inhomogeneously_constrained(dof),
                          ExcMessage("contact DoF with an inhomogeneous constraint"));
              if (const auto *entries = constraints.get_constraint_entries(dof))
                for (const auto &[j, cj] : *entries)
                  b[j] += a * cj;
            }
          else
            b[dof] += a;
        projection[i].assign(b.begin(), b.end());
      }
  }

  std::vector<double>
  PairOperators::project(const PETScWrappers::MPI::Vector &x) const
  {
    std::vector<double> t(projection.size(), 0.);
    const PetscScalar  *a;
    check_petsc(VecGetArrayRead(x, &a), "VecGetArrayRead");
    for (unsigned int i = 0; i < projection.size(); ++i)
      for (const auto &[dof, b] : projection[i])
        if (owns(dof))
          t[i] += b * a[dof - first_owned];
    check_petsc(VecRestoreArrayRead(x, &a), "VecRestoreArrayRead");
    sum_replicated(t, comm);
    return t;
  }

  void
  PairOperators::add_pair_forces(const std::vector<double>  &f,
                                 PETScWrappers::MPI::Vector &rhs) const
  {
    PetscScalar *a;
    check_petsc(VecGetArray(rhs, &a), "VecGetArray");
    for (unsigned int i = 0; i < projection.size(); ++i)
      if (f[i] != 0)
        for (const auto &[dof, b] : projection[i])
          if (owns(dof))
            a[dof - first_owned] += b * f[i];
    check_petsc(VecRestoreArray(rhs, &a), "VecRestoreArray");
  }
} // namespace rotorfit
