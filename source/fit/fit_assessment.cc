#include <rotorfit/fit/fit_assessment.h>
#include <rotorfit/statics/speed_schedule.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    constexpr double nan      = std::numeric_limits<double>::quiet_NaN();
    constexpr double infinity = std::numeric_limits<double>::infinity();

    double
    rpm_of(const double w)
    {
      return std::sqrt(std::max(w, 0.)) * 60. / (2. * M_PI);
    }

    /// Rp0.2 / sigma, NaN without Rp0.2.
    double
    yield_safety(const Body &body, const double sigma)
    {
      return body.yield_strength ? *body.yield_strength / sigma : nan;
    }
  } // namespace

  FitAssessment::FitAssessment(const ContactPairs &pairs, const ContactInterfaces &interfaces,
                               const Bodies &bodies)
    : pairs(pairs)
    , interfaces(interfaces)
    , bodies(bodies)
  {}

  void
  FitAssessment::initialize(std::unique_ptr<StressField> field)
  {
    stress = std::move(field);
    first = true;
    first_rows.clear();
    slip_rpm.clear();
    const unsigned int n_f = pairs.n_interfaces();
    last_w.assign(n_f, 0.);
    last_force.assign(n_f, 0.);
    last_moment.assign(n_f, 0.);
    slip_rpm.assign(n_f, nan);
    least_safety.assign(n_f, infinity);
    least_safety_rpm.assign(n_f, nan);
    worst_hub_bore.assign(n_f, 0.);
    worst_shaft_bore.assign(n_f, 0.);
    worst_body.assign(bodies.size(), BodyStressRow());
    worst_body_rpm.assign(bodies.size(), nan);
  }

  double
  FitAssessment::slip_safety(const unsigned int f, const double force, const double moment) const
  {
    const auto  &spec = interfaces.list()[f].fit;
    const double mu   = spec.friction().value_or(0.);
    const double T = spec.torque_load(), A = spec.axial_load();
    if (T == 0 && A == 0)
      return infinity;
    // the friction a pair can carry is shared between the circumferential
    // and the axial direction: (T / T_cap)^2 + (A / A_cap)^2 = 1 / S^2
    // (one radius: the resultant of 2T/d and A against mu sum N)
    const double t = T > 0 ? T / std::max(mu * moment, 0.) : 0.;
    const double a = A > 0 ? A / std::max(mu * force, 0.) : 0.;
    return 1. / std::hypot(t, a);
  }

  double
  FitAssessment::slip_w(const unsigned int f, const double w0, const double F0, const double M0,
                        const double w1, const double F1, const double M1) const
  {
    const auto S = [&](const double s) {
      return slip_safety(f, F0 + s * (F1 - F0), M0 + s * (M1 - M0));
    };
    if (!(S(0.) >= 1.) || S(1.) >= 1.)
      return nan;
    // the capacity is affine in s on the piece and the safety monotone in
    // it: bisection to round-off
    double lo = 0, hi = 1;
    for (int k = 0; k < 200 && hi - lo > 1e-15; ++k)
      {
        const double mid = 0.5 * (lo + hi);
        (S(mid) >= 1. ? lo : hi) = mid;
      }
    return w0 + 0.5 * (lo + hi) * (w1 - w0);
  }

  void
  FitAssessment::record(StaticState &state, const PETScWrappers::MPI::Vector &u)
  {
    const auto        &list = pairs.pairs();
    const unsigned int n_f  = pairs.n_interfaces();
    const double       w      = state.w();

    std::vector<double> force(n_f, 0.), moment(n_f, 0.), delta(n_f, 0.);
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        delta[list[i].interface] += list[i].interference / pairs.pairs_of(list[i].interface).size();
        if (state.contact.active[i])
          {
            force[list[i].interface] += state.contact.force[i];
            moment[list[i].interface] +=
              state.contact.force[i] * std::hypot(list[i].position[0], list[i].position[1]);
          }
      }
    std::vector<double> pressure(list.size(), 0.);
    for (unsigned int i = 0; i < list.size(); ++i)
      if (state.contact.active[i])
        pressure[i] = state.contact.pressure[i];
    const auto bores = stress->bore(u, pressure);
    state.fits.clear();
    for (unsigned int f = 0; f < n_f; ++f)
      {
        const auto &spec = interfaces.list()[f].fit;
        const auto &g    = pairs.geometry(f);
        FitRow      row;
        row.name                = interfaces.list()[f].name;
        row.radial_interference = delta[f];
        row.mean_pressure       = state.interfaces[f].mean_pressure;
        row.edge_peak_ratio     = row.mean_pressure > 0 ?
                                    state.interfaces[f].max_pressure / row.mean_pressure :
                                    nan;
        row.with_friction = spec.friction().has_value();
        const double mu   = spec.friction().value_or(0.);
        row.torque_capacity = mu * moment[f];
        row.axial_capacity  = mu * force[f];
        row.slip_safety     = slip_safety(f, force[f], moment[f]);
        if (row.with_friction && std::isnan(slip_rpm[f]))
          {
            if (first)
              {
                if (row.slip_safety < 1.)
                  slip_rpm[f] = state.rpm; // slips at the first speed already
              }
            else
              {
                // the pieces since the last speed: its point, the kinks
                // of the path (before / after each change), this speed
                double w0 = last_w[f], F0 = last_force[f], M0 = last_moment[f];
                double found = nan;
                for (const auto &k : state.contact.kinks)
                  {
                    found = slip_w(f, w0, F0, M0, k.w, k.force_before[f], k.moment_before[f]);
                    if (!std::isnan(found))
                      break;
                    // a jump at the change
                    if (slip_safety(f, k.force_before[f], k.moment_before[f]) >= 1. &&
                        slip_safety(f, k.force_after[f], k.moment_after[f]) < 1.)
                      {
                        found = k.w;
                        break;
                      }
                    w0 = k.w;
                    F0 = k.force_after[f];
                    M0 = k.moment_after[f];
                  }
                if (std::isnan(found))
                  found = slip_w(f, w0, F0, M0, w, force[f], moment[f]);
                if (!std::isnan(found))
                  slip_rpm[f] = rpm_of(found);
              }
          }
        row.slip_rpm = slip_rpm[f];
        if (row.with_friction && row.slip_safety < least_safety[f])
          {
            least_safety[f]     = row.slip_safety;
            least_safety_rpm[f] = state.rpm;
          }
        row.hub_bore_von_mises   = bores[f].hub.von_mises;
        row.shaft_bore_von_mises = bores[f].shaft.von_mises;
        row.hub_bore_hoop        = bores[f].hub.sigma_t;
        row.shaft_bore_hoop      = bores[f].shaft.sigma_t;
        row.hub_yield_safety     = yield_safety(bodies[g.hub_body], row.hub_bore_von_mises);
        row.shaft_yield_safety   = yield_safety(bodies[g.shaft_body], row.shaft_bore_von_mises);
        worst_hub_bore[f]        = std::max(worst_hub_bore[f], row.hub_bore_von_mises);
        worst_shaft_bore[f]      = std::max(worst_shaft_bore[f], row.shaft_bore_von_mises);
        last_w[f]                = w;
        last_force[f]            = force[f];
        last_moment[f]           = moment[f];
        state.fits.push_back(row);
      }

    // the cells' quadrature points lie inside; the bores' nominal points
    // on the surface, where a fit's stress is largest: both count
    auto peaks = stress->max_von_mises(u);
    for (unsigned int f = 0; f < n_f; ++f)
      {
        const auto &g   = pairs.geometry(f);
        const double z  = 0.5 * (g.z_min + g.z_max);
        const auto   on = [&](const unsigned int body, const StressField::BoreStress &bore) {
          if (bore.von_mises > peaks[body].von_mises)
            peaks[body] = StressField::Peak{bore.von_mises, Point<3>(bore.radius, 0., z)};
        };
        on(g.hub_body, bores[f].hub);
        on(g.shaft_body, bores[f].shaft);
      }
    state.body_stresses.clear();
    for (unsigned int b = 0; b < bodies.size(); ++b)
      {
        BodyStressRow row;
        row.name          = bodies[b].name;
        row.max_von_mises = peaks[b].von_mises;
        row.location      = peaks[b].location;
        row.yield_safety  = yield_safety(bodies[b], row.max_von_mises);
        if (row.max_von_mises > worst_body[b].max_von_mises || std::isnan(worst_body_rpm[b]))
          {
            worst_body[b]     = row;
            worst_body_rpm[b] = state.rpm;
          }
        state.body_stresses.push_back(row);
      }
    if (first)
      first_rows = state.fits;
    first = false;
  }

  void
  FitAssessment::add_to_summary(Summary &summary) const
  {
    for (unsigned int f = 0; f < pairs.n_interfaces(); ++f)
      {
        const auto       &def = interfaces.list()[f];
        const auto       &g   = pairs.geometry(f);
        const std::string key = "interface." + def.name + ".";
        summary.add(key + "fit_given", def.fit.describe());
        summary.add(key + "diameter_m", g.diameter);
        summary.add(key + "radial_interference_at_reference_m", g.radial_interference);
        summary.add(key + "thermal_shift_m", g.thermal_shift);
        const auto &hub = bodies[g.hub_body];
        if (hub.expansion)
          summary.add(key + "mounting_temperature_C",
                      def.fit.mounting_temperature(g.diameter, *hub.expansion,
                                                   interfaces.reference_temperature()));
        if (!first_rows.empty())
          {
            const FitRow &r = first_rows[f];
            summary.add(key + "hub_bore_von_mises_first_speed_Pa", r.hub_bore_von_mises);
            summary.add(key + "shaft_bore_von_mises_first_speed_Pa", r.shaft_bore_von_mises);
            summary.add(key + "hub_bore_hoop_first_speed_Pa", r.hub_bore_hoop);
            summary.add(key + "shaft_bore_hoop_first_speed_Pa", r.shaft_bore_hoop);
            summary.add(key + "edge_peak_ratio_first_speed", r.edge_peak_ratio);
            summary.add(key + "hub_bore_von_mises_max_Pa", worst_hub_bore[f]);
            summary.add(key + "shaft_bore_von_mises_max_Pa", worst_shaft_bore[f]);
            for (const auto &[side, body, worst] :
                 {std::tuple{"hub", g.hub_body, worst_hub_bore[f]},
                  std::tuple{"shaft", g.shaft_body, worst_shaft_bore[f]}})
              if (bodies[body].yield_strength)
                summary.add(key + side + "_bore_yield_safety_least",
                            *bodies[body].yield_strength / worst);
            if (def.fit.friction())
              {
                summary.add(key + "friction_coefficient", *def.fit.friction());
                summary.add(key + "torque_load_Nm", def.fit.torque_load());
                summary.add(key + "axial_load_N", def.fit.axial_load());
                summary.add(key + "torque_capacity_first_speed_Nm", r.torque_capacity);
                summary.add(key + "axial_capacity_first_speed_N", r.axial_capacity);
                summary.add(key + "slip_safety_first_speed", r.slip_safety);
                summary.add(key + "slip_safety_least", least_safety[f]);
                summary.add(key + "slip_safety_least_at_rpm", least_safety_rpm[f]);
                summary.add(key + "slip_rpm", slip_rpm[f]);
              }
          }
      }
    for (unsigned int b = 0; b < bodies.size(); ++b)
      if (!std::isnan(worst_body_rpm[b]))
        {
          const std::string key = "body." + bodies[b].name + ".";
          summary.add(key + "max_von_mises_Pa", worst_body[b].max_von_mises);
          summary.add(key + "max_von_mises_at_rpm", worst_body_rpm[b]);
          summary.add(key + "max_von_mises_x_m", worst_body[b].location[0]);
          summary.add(key + "max_von_mises_y_m", worst_body[b].location[1]);
          summary.add(key + "max_von_mises_z_m", worst_body[b].location[2]);
          if (bodies[b].yield_strength)
            summary.add(key + "yield_safety_least", worst_body[b].yield_safety);
        }
  }
} // namespace rotorfit
