#include <rotorfit/contact/sampled_law.h>

#include <algorithm>
#include <cmath>

namespace rotorfit
{
  using namespace dealii;

  void
  SampledLaw::initialize(const System &system, BaseFactorization &base_)
  {
    parameters       = &system.parameters;
    pairs            = &system.pairs;
    ops              = &system.operators;
    constraints      = &system.constraints;
    F_c              = &system.unit_centrifugal_load;
    M_perp           = system.spin_softening_matrix;
    owned            = system.owned;
    comm             = system.comm;
    w_max            = system.w_max;
    base             = &base_;
    low_rank_updates = 0;
  }

  ContactDecomposition
  SampledLaw::decompose(const std::vector<bool>    &active,
                        const double                w,
                        const ContactDecomposition &previous)
  {
    const bool affine = (M_perp == nullptr);
    // a low-rank update of the base factorisation where it is cheaper than
    // a new one; a failed residual check falls back to the factorisation
    for (bool update = base->usable_at(w, affine) && parameters->update_limit > 0;;
         update      = false)
      {
        if (!(update && base->prepare_update(active, parameters->update_limit)))
          base->factorize(active, w);

        ContactDecomposition next = start_from(previous, active, w);
        update_residual           = 0;
        uzawa_capped              = false;
        if (affine)
          solve_affine(next);
        else
          solve_tangent(next, w);
        const bool updated = !base->update().empty();
        if (updated && !(update_residual <= 1e-8)) // NaN included
          continue; // the update lost accuracy: factorise this active set
        if (updated)
          ++low_rank_updates;
        // P2 vertex pairs carry almost no force (int psi_i dA = 0), so the
        // sign of their multiplier is noise; the pressure field p = M^-1 N
        // is smooth and decides which pairs are open
        next.pressure_I      = pairs->pressure(next.force_I);
        next.pressure_C      = pairs->pressure(next.force_C);
        next.valid           = true;
        next.uzawa_converged = !uzawa_capped;
        return next;
      }
  }

  ContactDecomposition
  SampledLaw::start_from(const ContactDecomposition &previous,
                         const std::vector<bool>    &active,
                         const double                w) const
  {
    // continue from the previous multipliers (augmented Lagrangian)
    const bool           affine = (M_perp == nullptr);
    ContactDecomposition next;
    next.active  = active;
    next.affine  = affine;
    next.w_fixed = w;
    const unsigned int n = pairs->pairs().size();
    next.force_I.assign(n, 0.);
    next.force_C.assign(n, 0.);
    next.gap_I.assign(n, 0.);
    next.gap_C.assign(n, 0.);
    if (previous.valid)
      for (unsigned int i = 0; i < n; ++i)
        {
          next.force_I[i] = previous.force_I[i] + (affine ? 0. : w * previous.force_C[i]);
          next.force_C[i] = previous.force_C[i];
        }
    return next;
  }

  void
  SampledLaw::solve_affine(ContactDecomposition &next)
  {
    const auto &active = next.active;
    uzawa_count +=
      solve_load_case(LoadCase::interference(), active, next.force_I, next.gap_I, next.u_I);
    if (w_max > 0)
      uzawa_count += solve_load_case(LoadCase::per_unit_w(*F_c, w_max), active, next.force_C,
                                     next.gap_C, next.u_C);
    else
      next.u_C.reinit(owned, comm);
  }

  void
  SampledLaw::solve_tangent(ContactDecomposition &next, const double w)
  {
    // the solution X(w) and its derivative X'(w) for this active set
    // ((K_A - w M) u' = F_c + M u, same factorisation), stored as the
    // tangent X_I + w' X_C, X_I = X(w) - w X'(w): exact at w, and it
    // predicts the openings up to the next speed to first order
    const auto        &active = next.active;
    const unsigned int n      = active.size();
    uzawa_count +=
      solve_load_case(LoadCase::at_speed(*F_c, w), active, next.force_I, next.gap_I, next.u_I);
    PETScWrappers::MPI::Vector u_free = next.u_I, load(owned, comm);
    constraints->set_zero(u_free); // M_perp acts on the condensed u
    M_perp->vmult(load, u_free);
    load += *F_c;
    uzawa_count += solve_load_case(LoadCase::per_unit_w(load, w_max), active, next.force_C,
                                   next.gap_C, next.u_C);
    for (unsigned int i = 0; i < n; ++i)
      {
        next.force_I[i] -= w * next.force_C[i];
        next.gap_I[i] -= w * next.gap_C[i];
      }
    next.u_I.add(-w, next.u_C);
  }

  unsigned int
  SampledLaw::solve_load_case(const LoadCase             &load,
                              const std::vector<bool>    &active,
                              std::vector<double>        &force,
                              std::vector<double>        &gap,
                              PETScWrappers::MPI::Vector &u)
  {
    const auto        &list    = pairs->pairs();
    const bool         penalty = (parameters->method == ContactParameters::Method::penalty);
    const unsigned int n       = list.size();
    const unsigned int cap     = parameters->max_uzawa_iterations;
    const auto interference    = [&](const unsigned int i) {
      return load.with_interference ? list[i].interference : 0.;
    };
    if (penalty)
      std::fill(force.begin(), force.end(), 0.);
    for (unsigned int i = 0; i < n; ++i)
      if (!active[i])
        force[i] = 0;

    PETScWrappers::MPI::Vector rhs(owned, comm);
    u.reinit(owned, comm);
    std::vector<double> f(n), c;
    unsigned int        iterations = 0;
    for (unsigned int k = 0; k < (penalty ? 1 : cap); ++k)
      {
        if (load.load != nullptr)
          {
            rhs = *load.load;
            rhs *= load.factor;
          }
        else
          rhs = 0;
        for (unsigned int i = 0; i < n; ++i)
          f[i] = active[i] ? force[i] + ops->penalty(i) * interference(i) : 0.;
        ops->add_pair_forces(f, rhs);
        base->solve(u, rhs);
        // B^T K_A^-1 rhs in pair space; u stays K_base^-1 rhs for now
        std::vector<double> t = ops->project(u);
        c                     = base->update().apply(t, base->columns());

        double worst = 0;
        for (unsigned int i = 0; i < n; ++i)
          {
            gap[i] = t[i] - interference(i);
            if (active[i])
              {
                force[i] -= ops->penalty(i) * gap[i];
                worst = std::max(worst, load.gap_scale * std::abs(gap[i]) / list[i].interference);
              }
          }
        if (!penalty)
          ++iterations;
        if (penalty || worst <= parameters->uzawa_tolerance)
          break;
        if (k + 1 == cap)
          uzawa_capped = true;
      }
    if (!base->update().empty())
      check_update(c, active, force, rhs, u);
    constraints->distribute(u);
    return iterations;
  }

  void
  SampledLaw::check_update(const std::vector<double>  &c,
                           const std::vector<bool>    &active,
                           const std::vector<double>  &force,
                           PETScWrappers::MPI::Vector &rhs,
                           PETScWrappers::MPI::Vector &u)
  {
    const unsigned int  n = pairs->pairs().size();
    std::vector<double> f(n);
    const auto         &changed   = base->update().changed();
    const auto         &changed_k = base->update().springs();
    // u = K_base^-1 (rhs - B_D c); its residual against K_A lives on the
    // changed pairs only: B_D (S B_D^T u - c)
    std::fill(f.begin(), f.end(), 0.);
    for (unsigned int a = 0; a < changed.size(); ++a)
      f[changed[a]] = -c[a];
    ops->add_pair_forces(f, rhs);
    base->solve(u, rhs);
    const std::vector<double> t = ops->project(u);
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
} // namespace rotorfit
