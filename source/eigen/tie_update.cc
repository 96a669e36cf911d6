#include <rotorfit/eigen/tie_update.h>

namespace rotorfit
{
  TieUpdate::TieUpdate(const Discretization &model,
                       const Bearings       &bearings,
                       const SpeedTangent   &operators)
    : model(model)
    , bearings(bearings)
    , operators(operators)
  {}

  void
  TieUpdate::record(const DirectSolver      &solver,
                    const StaticState       &state,
                    const std::vector<bool> &tied)
  {
    const std::size_t n_pairs = model.pairs().pairs().size();
    factored = FactorTies{solver.n_factorizations(), state.rpm, std::vector<double>(n_pairs, 0.)};
    for (unsigned int i = 0; i < n_pairs; ++i)
      if (tied[i])
        factored->eps[i] = operators.tie_spring(state, i);
  }

  bool
  TieUpdate::columns(const DirectSolver                      &solver,
                     const StaticState                       &state,
                     const std::vector<bool>                 &tied,
                     const unsigned int                       limit,
                     std::vector<DirectSolver::UpdateColumn> &columns) const
  {
    columns.clear();
    // (bearing coefficients that change with speed: S would lack their change)
    if (!solver.factorized() || !factored ||
        solver.n_factorizations() != factored->factorizations || bearings.speed_dependent())
      return false;
    // a fit that lets go of its last tie frees a body (or the factorised
    // one had it free): its rigid motions then rest on sigma^2 M alone, some
    // 1e14 below the ties' springs, more than the Woodbury sum keeps (TS at
    // the loss of fit: no mode converged)
    const auto &pair_list = model.pairs();
    for (unsigned int f = 0; f < pair_list.n_interfaces(); ++f)
      {
        bool then = false, now = false;
        for (const unsigned int p : pair_list.pairs_of(f))
          then |= factored->eps[p] > 0, now |= tied[p];
        if (then != now)
          return false;
      }
    // the springs SpeedTangent puts in: eps n n^T on the radial direction
    // (frictionless), eps in every direction (bonded), on the relative
    // motion of the pair's hub and shaft nodes
    const auto &list = model.pairs().pairs();
    const bool  normal_only =
      operators.settings.contact_model == SpeedTangent::ContactModel::frictionless;
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        const double now    = tied[i] ? operators.tie_spring(state, i) : 0.;
        const double spring = now - factored->eps[i];
        if (spring == 0)
          continue;
        const auto &p = list[i];
        for (unsigned int d = 0; d < (normal_only ? 1u : 3u); ++d)
          {
            DirectSolver::UpdateColumn u;
            u.key    = 3 * i + d;
            u.spring = spring;
            for (unsigned int a = 0; a < 3; ++a)
              {
                const double v = normal_only ? (a < 2 ? p.normal[a] : 0.) : (a == d ? 1. : 0.);
                if (v != 0)
                  {
                    u.entries.emplace_back(p.hub_dofs[a], v);
                    u.entries.emplace_back(p.shaft_dofs[a], -v);
                  }
              }
            columns.push_back(std::move(u));
          }
        if (columns.size() > limit)
          return false;
      }
    return !columns.empty();
  }
} // namespace rotorfit
