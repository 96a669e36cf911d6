#include <rotorfit/base/format.h>
#include <rotorfit/statics/fit_history.h>
#include <rotorfit/statics/speed_schedule.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace rotorfit
{
  namespace
  {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    constexpr double inf = std::numeric_limits<double>::infinity();

    /// Speed [r/min] at which a pair with p = p_I + w p_C reaches p = 0.
    double
    opening_rpm(const double n_i, const double n_c)
    {
      if (!(n_c < 0))
        return inf;
      if (!(n_i > 0))
        return 0;
      return SpeedSchedule::rad_per_s_to_rpm(std::sqrt(-n_i / n_c));
    }

    /// Speed [r/min] at which the total force sum_A (N_I + w N_C) of the
    /// closed pairs @p ids of an interface vanishes: the loss of fit of that
    /// active set. Robust where single pairs are noisy (doc/theory.md 9.6).
    double
    total_force_zero_rpm(const std::vector<unsigned int> &ids,
                         const std::vector<bool>         &active,
                         const std::vector<double>       &n_i,
                         const std::vector<double>       &n_c)
    {
      double sum_i = 0, sum_c = 0;
      for (const auto i : ids)
        if (active[i])
          {
            sum_i += n_i[i];
            sum_c += n_c[i];
          }
      return opening_rpm(sum_i, sum_c);
    }

    /// Above this ContactPairs::asymmetry() the stationary-frame
    /// eigenproblem (a rotationally symmetric rotor) no longer holds.
    constexpr double asymmetry_warning = 0.5;

  } // namespace

  FitHistory::FitHistory(const ContactPairs      &pairs,
                         const ContactInterfaces &interfaces,
                         Log                     &log)
    : pairs(pairs)
    , interfaces(interfaces)
    , log(log)
  {}

  void
  FitHistory::record(StaticState                        &state,
                     const ContactSolver::Decomposition &law,
                     const double                        error_limit)
  {
    const unsigned int n_if = pairs.n_interfaces();
    if (speeds == 0)
      {
        first_open.assign(n_if, nan);
        loss_of_fit.assign(n_if, nan);
        mean_p0.assign(n_if, nan);
        max_p0.assign(n_if, nan);
        worst_error.assign(n_if, 0.);
        worst_asymmetry.assign(n_if, 0.);
        fully_open.assign(n_if, false);
        half_open.assign(n_if, nan);
        last_fraction.assign(n_if, nan);
      }
    state.interfaces.resize(n_if);
    state.openings.clear();
    state.events.clear();
    bool within_limit = true;
    for (unsigned int f = 0; f < n_if; ++f)
      within_limit &= evaluate_interface(f, state, law, error_limit);

    auto &contact = state.contact;
    if (!contact.converged)
      log << "Warning: the static contact state at " << state.rpm
          << " r/min is not converged: " << contact.reason
          << " (the last active set is kept, and may hold pairs in tension); its "
             "rows have converged = 0, and so do its eigen rows.\n";
    if (!within_limit)
      {
        log << "Warning: the constraint error at " << state.rpm
            << " r/min exceeds its limit " << error_limit
            << " (see contact.csv, status); its rows have converged = 0.\n";
        contact.reason += std::string(contact.reason.empty() ? "" : "; ") + "constraint error";
        contact.converged = false;
      }
    if (!contact.converged)
      ++unconverged;
    std::string asymmetric;
    for (const auto &row : state.interfaces)
      if (row.asymmetry > asymmetry_warning)
        asymmetric += " " + row.name + " " + format_number(row.asymmetry);
    if (!asymmetric.empty())
      log << "Warning: the closed set at " << state.rpm
          << " r/min is not rotationally symmetric (asymmetry" << asymmetric << " > "
          << asymmetry_warning
          << "): the stationary-frame eigenproblem assumes a symmetric rotor; "
             "treat this speed's modes with care, or mesh the bodies with Geometry/Mesher = "
             "sections, whose closed sets stay symmetric.\n";

    state.fit_state = "closed";
    for (const auto &row : state.interfaces)
      if (row.closed_pairs == 0)
        state.fit_state = "open";
      else if (row.closed_pairs < row.total_pairs && state.fit_state == "closed")
        state.fit_state = "partial";

    ++speeds;
    previous_rpm = state.rpm;
    last_active  = contact.active;
    last_p_I     = law.pressure_I;
    last_p_C     = law.pressure_C;
    last_f_I     = law.force_I;
    last_f_C     = law.force_C;
    last_affine  = law.affine;
  }

  bool
  FitHistory::evaluate_interface(const unsigned int                  f,
                                 StaticState                        &state,
                                 const ContactSolver::Decomposition &law,
                                 const double                        error_limit)
  {
    const auto  &list = pairs.pairs();
    const auto  &ids  = pairs.pairs_of(f);
    const auto  &c    = state.contact;
    InterfaceRow row;
    row.name        = interfaces.list()[f].name;
    row.total_pairs = ids.size();
    double force    = 0;
    for (const auto i : ids)
      if (c.active[i])
        {
          ++row.closed_pairs;
          force += c.force[i];
          row.max_pressure = std::max(row.max_pressure, c.pressure[i]);
          row.constraint_error =
            std::max(row.constraint_error, std::abs(c.gap[i]) / list[i].interference);
        }
    row.asymmetry      = pairs.asymmetry(f, c.active);
    worst_asymmetry[f] = std::max(worst_asymmetry[f], row.asymmetry);
    state.contact.asymmetry = std::max(state.contact.asymmetry, row.asymmetry);
    row.status = c.converged ? "ok" : c.reason;
    const bool within_limit = row.constraint_error <= error_limit;
    if (!within_limit)
      row.status = (row.status == "ok" ? "" : row.status + "; ") + "constraint error " +
                   format_number(row.constraint_error) + " above " + format_number(error_limit);
    const double area = pairs.closed_area(f, c.active);
    // total normal force over the closed area (exact for uniform p)
    row.mean_pressure    = row.closed_pairs > 0 ? force / area : 0.;
    row.contact_fraction = area / pairs.area(f);
    worst_error[f]       = std::max(worst_error[f], row.constraint_error);
    if (speeds == 0)
      {
        mean_p0[f] = row.mean_pressure;
        max_p0[f]  = row.max_pressure;
      }

    if (speeds > 0 && !law.q_I.empty())
      follow_events(f, state);
    else if (speeds > 0)
      {
        find_openings(f, state, row.closed_pairs);
        const double from = last_fraction[f], to = row.contact_fraction;
        if (std::isnan(half_open[f]) && from >= 0.5 && to < 0.5)
          half_open[f] = previous_rpm + (from - 0.5) / (from - to) * (state.rpm - previous_rpm);
      }
    else if (row.closed_pairs < ids.size())
      log << "Interface " << row.name << ": " << ids.size() - row.closed_pairs
          << " pairs are already open at the first speed\n";

    last_fraction[f]      = row.contact_fraction;
    row.first_opening_rpm = first_open[f];
    row.loss_of_fit_rpm =
      fully_open[f]         ? loss_of_fit[f] :
      row.closed_pairs == 0 ? nan :
                              total_force_zero_rpm(ids, c.active, law.force_I, law.force_C);
    state.interfaces[f] = row;
    return within_limit;
  }

  void
  FitHistory::find_openings(const unsigned int f, StaticState &state, const unsigned int closed)
  {
    // pairs that opened since the previous speed: their opening speed from
    // the previous active set's affine law (exact for the first; with spin
    // softening the tangent at the previous speed: a Newton step, first
    // order)
    const auto  &list = pairs.pairs();
    const auto  &ids  = pairs.pairs_of(f);
    const auto  &name = interfaces.list()[f].name;
    const double from = previous_rpm, to = state.rpm;
    double       first_now = inf, last_now = 0;
    for (const auto i : ids)
      if (last_active[i] && !state.contact.active[i])
        {
          double o = opening_rpm(last_p_I[i], last_p_C[i]);
          if (!std::isnan(o))
            o = std::min(std::max(o, from), to);
          first_now = std::min(first_now, o);
          last_now  = std::max(last_now, o);
          state.openings.push_back({name, list[i].position, o, from, to});
        }
    if (std::isnan(first_open[f]) && first_now < inf)
      first_open[f] = first_now;
    if (closed == 0 && !fully_open[f])
      {
        double lof = total_force_zero_rpm(ids, last_active, last_f_I, last_f_C);
        if (!std::isnan(lof))
          lof = std::min(std::max(lof, from), to);
        mark_fully_open(f, lof, from, to, last_now);
      }
  }

  void
  FitHistory::mark_fully_open(const unsigned int f, const double rpm, const double from,
                              const double to, const double last_pair)
  {
    fully_open[f]  = true;
    loss_of_fit[f] = rpm;
    log << "Interface " << interfaces.list()[f].name << ": the fit is fully open between "
        << from << " and " << to << " r/min (loss of fit at " << format_number(rpm)
        << (std::isnan(last_pair) ? " r/min, exact on the path)\n" :
                                    " r/min from the total contact force; last pair at " +
                                      format_number(last_pair) + " r/min)\n");
  }

  void
  FitHistory::follow_events(const unsigned int f, StaticState &state)
  {
    // replay the path's changes of this interface in order: every opening
    // speed, the first opening, the half-open and the full-opening speed
    // are event speeds, exact to the solver's precision
    const auto        &list = pairs.pairs();
    const auto        &ids  = pairs.pairs_of(f);
    const auto        &name = interfaces.list()[f].name;
    std::vector<bool>  member(list.size(), false), active = last_active;
    unsigned int       closed = 0;
    for (const auto i : ids)
      {
        member[i] = true;
        closed += active[i];
      }
    double fraction = last_fraction[f];
    for (const auto &e : state.contact.events)
      if (member[e.pair])
        {
          const double rpm = SpeedSchedule::rad_per_s_to_rpm(std::sqrt(e.w));
          active[e.pair]   = !e.opening;
          closed           = e.opening ? closed - 1 : closed + 1;
          const double now = pairs.closed_area(f, active) / pairs.area(f);
          if (e.opening)
            {
              state.openings.push_back({name, list[e.pair].position, rpm, previous_rpm, state.rpm});
              if (std::isnan(first_open[f]))
                first_open[f] = rpm;
            }
          if (std::isnan(half_open[f]) && fraction >= 0.5 && now < 0.5)
            half_open[f] = rpm;
          if (closed == 0 && !fully_open[f])
            mark_fully_open(f, rpm, previous_rpm, state.rpm, nan);
          fraction = now;
          state.events.push_back({name, list[e.pair].position, rpm, e.opening, closed, now});
        }
  }

  bool
  FitHistory::every_fit_open() const
  {
    return !fully_open.empty() &&
           std::all_of(fully_open.begin(), fully_open.end(), [](bool b) { return b; });
  }

  void
  FitHistory::add_to_summary(Summary &summary) const
  {
    // a fit that never opened: its loss of fit is extrapolated from the last
    // recorded speed's law, the same law as the loss_of_fit_rpm column of
    // the last row of contact.csv
    const bool have = speeds > 0;
    for (unsigned int f = 0; f < pairs.n_interfaces(); ++f)
      {
        const std::string key = "interface." + interfaces.list()[f].name + ".";
        const auto       &ids = pairs.pairs_of(f);
        double lof = have ? loss_of_fit[f] : nan, first = have ? first_open[f] : nan;
        if (have && !fully_open[f])
          {
            double firstp = inf;
            for (const auto i : ids)
              if (last_active[i])
                firstp = std::min(firstp, opening_rpm(last_p_I[i], last_p_C[i]));
            lof = total_force_zero_rpm(ids, last_active, last_f_I, last_f_C);
            if (std::isnan(first))
              first = firstp;
          }
        const bool opened = have && fully_open[f];
        summary.add(key + "pairs", ids.size());
        summary.add(key + "mean_pressure_first_speed_Pa", have ? mean_p0[f] : nan);
        summary.add(key + "max_pressure_first_speed_Pa", have ? max_p0[f] : nan);
        summary.add(key + "constraint_error_max", have ? worst_error[f] : 0.);
        summary.add(key + "asymmetry_max", have ? worst_asymmetry[f] : 0.);
        summary.add(key + "first_opening_rpm", first);
        summary.add(key + "half_open_rpm", have ? half_open[f] : nan);
        summary.add(key + "loss_of_fit_rpm", lof);
        summary.add(key + "loss_of_fit_within_sweep", opened ? 1 : 0);
        log << "Interface " << interfaces.list()[f].name << ": first opening " << format_number(first)
            << " r/min, loss of fit " << format_number(lof) << " r/min"
            << (opened      ? "" :
                last_affine ? " (extrapolated beyond the sweep)" :
                              " (extrapolated beyond the sweep along the last "
                              "speed's tangent: a first-order estimate)")
            << '\n';
      }
    summary.add("static.speeds", speeds);
    summary.add("static.unconverged_speeds", unconverged);
  }
} // namespace rotorfit
