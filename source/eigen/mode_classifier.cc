#include <rotorfit/eigen/mode_classifier.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

namespace rotorfit
{
  using namespace dealii;

  ModeClassifier::ModeClassifier(const Discretization         &model,
                                 const Bearings               &bearings,
                                 const SpeedTangent::Settings &operators,
                                 const DampedEigensolver      &eigensolver,
                                 Log                          &log)
    : model(model)
    , bearings(bearings)
    , operators(operators)
    , eigensolver(eigensolver)
    , log(log)
  {}

  void
  ModeClassifier::setup()
  {
    const auto &dof_handler = model.dofs();
    body_of_dof.assign(dof_handler.n_dofs(), 0);
    std::vector<types::global_dof_index> dofs(dof_handler.get_fe().n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (const auto d : dofs)
          body_of_dof[d] = cell->material_id();
      }
  }

  unsigned int
  ModeClassifier::expected_zero_modes(const std::vector<bool> &tied,
                                      std::vector<bool>       &loose_body) const
  {
    const unsigned int n_bodies = model.bodies().size();
    std::vector<unsigned int> group(n_bodies);
    std::iota(group.begin(), group.end(), 0);
    const auto find = [&](unsigned int b) {
      while (group[b] != b)
        b = group[b];
      return b;
    };
    const auto        &list = model.pairs().pairs();
    std::set<unsigned int> sliding_hubs;
    for (unsigned int i = 0; i < list.size(); ++i)
      if (tied[i])
        {
          const unsigned int s = body_of_dof[list[i].shaft_dofs[0]],
                             h = body_of_dof[list[i].hub_dofs[0]];
          group[find(h)] = find(s);
          sliding_hubs.insert(h);
        }
    // distinct bearing stations per group decide which rigid motions remain
    std::map<unsigned int, std::set<long>> stations_of;
    for (const auto &b : bearings.list())
      if (!b.station.dof_x.empty())
        stations_of[find(body_of_dof[b.station.dof_x[0]])].insert(
          std::lround(b.station.z * 1e6));
    unsigned int main = find(0), best = 0;
    for (const auto &[g, s] : stations_of)
      if (s.size() > best)
        {
          best = s.size();
          main = g;
        }
    unsigned int zeros = 0;
    std::set<unsigned int> groups;
    loose_body.assign(n_bodies, false);
    for (unsigned int b = 0; b < n_bodies; ++b)
      {
        groups.insert(find(b));
        loose_body[b] = !stations_of.empty() && find(b) != main;
      }
    for (const auto g : groups)
      {
        const std::size_t n = stations_of.count(g) ? stations_of[g].size() : 0;
        zeros += n == 0 ? 6 : n == 1 ? 4 : 2; // axial and twist always free
      }
    // normal-only ties leave relative axial sliding and twist (doc/theory.md 7.4)
    if (operators.contact_model == SpeedTangent::ContactModel::frictionless)
      zeros += 2 * sliding_hubs.size();
    return zeros;
  }

  bool
  ModeClassifier::sort_eigenpairs(std::vector<EigenPair>  &pairs,
                                  const std::vector<bool> &loose_body,
                                  EigenSolution           &solution,
                                  unsigned int            &unconverged,
                                  double                  &worst) const
  {
    const auto &bodies = model.bodies();
    solution.elastic.clear();
    solution.rigid.clear();
    worst = 0;
    for (auto &p : pairs)
      {
        if (std::isnan(p.backward_error) ||
            (!std::isnan(worst) && p.backward_error > worst)) // NaN sticks
          worst = p.backward_error;
        if (!(p.backward_error <= eigensolver.backward_error_limit()))
          {
            ++unconverged;
            continue;
          }
        // kinetic energy share per body: M is block diagonal by body
        std::vector<double> energy(bodies.size(), 0.);
        for (std::size_t i = 0; i < p.phi.re.size(); ++i)
          energy[body_of_dof[i]] += p.phi.re[i] * p.m_phi.re[i] + p.phi.im[i] * p.m_phi.im[i];
        const double       total = std::accumulate(energy.begin(), energy.end(), 0.);
        const unsigned int dominant =
          std::max_element(energy.begin(), energy.end()) - energy.begin();
        const bool in_loose_body = loose_body[dominant] && energy[dominant] > 0.9 * total;
        const bool rigid_mode    = std::abs(p.lambda) < 2 * M_PI * rigid_threshold_hz;
        const bool real_mode     = p.lambda.imag() == 0;
        if (rigid_mode || real_mode || in_loose_body)
          solution.rigid.push_back({in_loose_body ? "loose" :
                                    rigid_mode    ? "rigid" :
                                                    "overdamped",
                                    in_loose_body ? bodies[dominant].name : "assembly",
                                    p.lambda,
                                    p.backward_error});
        else
          solution.elastic.push_back(std::move(p));
      }
    return unconverged == 0 && solution.elastic.size() >= n_wanted;
  }

  void
  ModeClassifier::announce_loose_bodies(const StaticState       &state,
                                        const std::vector<bool> &loose_body)
  {
    using ContactModel = SpeedTangent::ContactModel;
    if (state.fit_state != "open" || operators.contact_model == ContactModel::fixed ||
        operators.contact_model == ContactModel::frozen || announced_loose)
      return;
    announced_loose = true;
    std::string names;
    for (unsigned int b = 0; b < model.bodies().size(); ++b)
      if (loose_body[b])
        names += (names.empty() ? "" : ", ") + model.bodies()[b].name;
    log << "  note: a fit is fully open at " << state.rpm << " r/min: "
        << (names.empty() ? "the assembly falls apart" : "body " + names + " is loose")
        << "; from here on the whirl lines are not assembly modes (fit_state = "
           "open in campbell.csv), loose-body modes go to rigid_modes.csv\n";
  }
} // namespace rotorfit
