#include <rotorfit/output/tables.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <iomanip>
#include <limits>

namespace rotorfit
{
  std::string
  csv_field(const std::string &text)
  {
    if (text.find_first_of(",\"\r\n") == std::string::npos)
      return text;
    std::string quoted = "\"";
    for (const char c : text)
      quoted += (c == '"' ? "\"\"" : std::string(1, c));
    return quoted + '"';
  }

  void
  CsvTable::create(const std::string &path, const char *header, const int digits)
  {
    file.open(path);
    file << header << '\n' << std::setprecision(digits) << std::flush;
  }

  void
  ContactTable::open(const std::string &directory)
  {
    create(directory + "/contact.csv", "speed_rpm,interface,closed_pairs,total_pairs,contact_fraction,"
           "mean_pressure_Pa,max_pressure_Pa,constraint_error,"
           "active_set_iterations,uzawa_iterations,factorizations,"
           "low_rank_updates,converged,first_opening_rpm,loss_of_fit_rpm,"
           "asymmetry,status", 8);
  }

  void
  ContactTable::add(const StaticState &state)
  {
    if (!file.is_open())
      return;
    const auto &c = state.contact;
    for (const auto &row : state.interfaces)
      file << state.rpm << ',' << csv_field(row.name) << ',' << row.closed_pairs << ',' << row.total_pairs
           << ',' << row.contact_fraction << ',' << row.mean_pressure << ','
           << row.max_pressure << ',' << row.constraint_error << ','
           << c.active_set_iterations << ',' << c.uzawa_iterations << ','
           << c.factorizations << ',' << c.low_rank_updates << ','
           << (row.status == "ok" ? 1 : 0) << ',' << row.first_opening_rpm << ','
           << row.loss_of_fit_rpm << ',' << row.asymmetry << ',' << csv_field(row.status) << '\n';
    file << std::flush;
  }

  namespace
  {
    /// An empty field for a value that is not defined (NaN).
    struct Field
    {
      double value;
    };
    std::ostream &
    operator<<(std::ostream &out, const Field &f)
    {
      if (!std::isnan(f.value))
        out << f.value;
      return out;
    }
  } // namespace

  void
  FitTable::open(const std::string &directory)
  {
    create(directory + "/fit.csv",
           "speed_rpm,interface,radial_interference_m,mean_pressure_Pa,edge_peak_ratio,"
           "torque_capacity_Nm,axial_capacity_N,slip_safety,slip_rpm,hub_bore_von_mises_Pa,"
           "shaft_bore_von_mises_Pa,hub_bore_hoop_Pa,shaft_bore_hoop_Pa,hub_yield_safety,"
           "shaft_yield_safety",
           8);
  }

  void
  FitTable::add(const StaticState &state)
  {
    if (!file.is_open())
      return;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const auto &r : state.fits)
      {
        const auto friction = [&](const double v) { return Field{r.with_friction ? v : nan}; };
        file << state.rpm << ',' << csv_field(r.name) << ',' << r.radial_interference << ','
             << r.mean_pressure << ',' << Field{r.edge_peak_ratio} << ','
             << friction(r.torque_capacity) << ',' << friction(r.axial_capacity) << ','
             << friction(r.slip_safety) << ',' << friction(r.slip_rpm) << ','
             << r.hub_bore_von_mises << ',' << r.shaft_bore_von_mises << ',' << r.hub_bore_hoop
             << ',' << r.shaft_bore_hoop << ',' << Field{r.hub_yield_safety} << ','
             << Field{r.shaft_yield_safety} << '\n';
      }
    file << std::flush;
  }

  void
  BodyStressTable::open(const std::string &directory)
  {
    create(directory + "/body_stress.csv",
           "speed_rpm,body,max_von_mises_Pa,x_m,y_m,z_m,yield_safety", 8);
  }

  void
  BodyStressTable::add(const StaticState &state)
  {
    if (!file.is_open())
      return;
    for (const auto &r : state.body_stresses)
      file << state.rpm << ',' << csv_field(r.name) << ',' << r.max_von_mises << ','
           << r.location[0] << ',' << r.location[1] << ',' << r.location[2] << ','
           << Field{r.yield_safety} << '\n';
    file << std::flush;
  }

  void
  PairOpeningTable::open(const std::string &directory)
  {
    create(directory + "/pair_openings.csv", "interface,x_m,y_m,z_m,opening_rpm,from_rpm,to_rpm", 8);
  }

  void
  PairOpeningTable::add(const StaticState &state)
  {
    if (!file.is_open())
      return;
    for (const auto &o : state.openings)
      file << csv_field(o.interface) << ',' << o.position[0] << ',' << o.position[1] << ','
           << o.position[2] << ',' << o.opening_rpm << ',' << o.from_rpm << ',' << o.to_rpm
           << '\n';
    file << std::flush;
  }

  void
  ContactEventTable::open(const std::string &directory)
  {
    create(directory + "/contact_events.csv",
           "speed_rpm,interface,x_m,y_m,z_m,event,closed_pairs,contact_fraction", 10);
  }

  void
  ContactEventTable::add(const StaticState &state)
  {
    if (!file.is_open())
      return;
    for (const auto &e : state.events)
      file << e.rpm << ',' << csv_field(e.interface) << ',' << e.position[0] << ',' << e.position[1] << ','
           << e.position[2] << ',' << (e.opening ? "opening" : "closing") << ','
           << e.closed_pairs << ',' << e.contact_fraction << '\n';
    file << std::flush;
  }

  void
  CampbellTable::open(const std::string &directory)
  {
    create(directory + "/campbell.csv", "speed_rpm,mode,tracked_id,whirl,frequency_hz,damping_ratio,"
           "log_dec,stable,backward_error,fit_state,static_converged,contact_asymmetry", 10);
  }

  void
  CampbellTable::add(const StaticState &state, const ModalResult &modes)
  {
    if (!file.is_open())
      return;
    for (unsigned int b = 0; b < modes.modes.size(); ++b)
      {
        const WhirlMode &m      = modes.modes[b];
        const double     zeta   = -m.lambda.real() / std::abs(m.lambda);
        const double     logdec = -2 * M_PI * m.lambda.real() / m.lambda.imag();
        file << modes.rpm << ',' << b + 1 << ',' << m.tracked_id << ',' << csv_field(m.whirl) << ','
             << m.frequency_hz() << ',' << zeta << ',' << logdec << ','
             // undamped modes (Re = 0 up to round-off) count as stable
             << (m.lambda.real() <= 1e-8 * std::abs(m.lambda) ? 1 : 0) << ','
             << m.backward_error << ',' << csv_field(state.fit_state) << ','
             << (state.converged() ? 1 : 0) << ',' << state.contact.asymmetry << '\n';
      }
    file << std::flush;
  }

  void
  HarmonicCampbellTable::open(const std::string &directory)
  {
    create(directory + "/campbell.csv", "speed_rpm,harmonic,mode,tracked_id,whirl,travel,frequency_hz,damping_ratio,"
           "log_dec,stable,backward_error,forward_fraction,fit_state,static_converged", 10);
  }

  void
  HarmonicCampbellTable::add(const StaticState &state, const std::vector<HarmonicMode> &modes)
  {
    if (!file.is_open())
      return;
    for (const auto &m : modes)
      {
        const double zeta   = -m.lambda.real() / std::abs(m.lambda);
        const double logdec = -2 * M_PI * m.lambda.real() / m.lambda.imag();
        file << state.rpm << ',' << m.harmonic << ',' << m.index << ',' << m.tracked_id << ','
             << m.whirl << ','
             << m.travel << ',' << m.frequency_hz() << ',' << zeta << ',' << logdec << ','
             << (m.lambda.real() <= 1e-8 * std::abs(m.lambda) ? 1 : 0) << ',' << m.backward_error
             << ',' << m.forward_fraction << ',' << csv_field(state.fit_state) << ','
             << (state.converged() ? 1 : 0) << '\n';
      }
    file << std::flush;
  }

  void
  CriticalSpeedTable::open(const std::string &directory, const bool with_harmonic)
  {
    harmonic_columns = with_harmonic;
    create(directory + "/critical_speeds.csv",
           with_harmonic ? "tracked_id,whirl,order,speed_rpm,frequency_hz,kind,unbalance_excited,"
                           "damping_ratio,amplification_factor,solved,eigen_solves,harmonic,travel,mode" :
                           "tracked_id,whirl,order,speed_rpm,frequency_hz,kind,unbalance_excited,"
                           "damping_ratio,amplification_factor,solved,eigen_solves", 10);
  }

  void
  CriticalSpeedTable::add(const ModalResult &modes)
  {
    if (!file.is_open())
      return;
    // kind: lateral or non-lateral (axial, torsional, ND >= 2: unbalance
    // cannot excite them, and the picture does not mark them); unbalance
    // (1X, a forward force) excites forward whirl, and backward whirl only
    // on anisotropic supports; amplification factor 1 / (2 zeta)
    for (const auto &c : modes.crossings)
      {
        const bool lateral = c.whirl != "non-lateral";
        const bool excited = lateral && c.order == 1 &&
                             (c.whirl != "backward" || !modes.isotropic_supports);
        file << c.tracked_id << ',' << csv_field(c.whirl) << ',' << c.order << ',' << c.rpm << ','
             << c.frequency_hz << ',' << (lateral ? "lateral" : "non-lateral") << ','
             << (excited ? 1 : 0) << ',' << c.damping_ratio << ','
             << (c.damping_ratio > 0 ? 1 / (2 * c.damping_ratio) : 0.) << ','
             << (c.solved ? 1 : 0) << ',' << c.eigen_solves;
        if (harmonic_columns)
          file << ',' << c.harmonic << ',' << csv_field(c.travel) << ',' << c.mode;
        file << '\n';
      }
    file << std::flush;
  }

  void
  RigidModeTable::open(const std::string &directory, const bool with_harmonic)
  {
    harmonic_column = with_harmonic;
    create(directory + "/rigid_modes.csv",
           with_harmonic ? "speed_rpm,kind,body,real_part_per_s,frequency_hz,backward_error,harmonic" :
                           "speed_rpm,kind,body,real_part_per_s,frequency_hz,backward_error",
           10);
  }

  void
  RigidModeTable::add(const ModalResult &modes)
  {
    if (!file.is_open())
      return;
    for (const auto &r : modes.rigid)
      {
        file << modes.rpm << ',' << csv_field(r.kind) << ',' << csv_field(r.body) << ','
             << r.lambda.real() << ',' << r.lambda.imag() / (2 * M_PI) << ',' << r.backward_error;
        if (harmonic_column)
          file << ',' << r.harmonic;
        file << '\n';
      }
    file << std::flush;
  }
} // namespace rotorfit

namespace rotorfit
{
  void
  ResponseTable::open(const std::string &directory)
  {
    create(directory + "/response.csv",
           "speed_rpm,probe,fit_state,amplitude_x_m,phase_x_deg,amplitude_y_m,phase_y_deg,"
           "major_m,minor_m,whirl,residual,basis_size,converged",
           8);
  }

  void
  ResponseTable::add(const ResponseAtSpeed &r)
  {
    if (!file.is_open())
      return;
    // phase lag: x(t) = |X| cos(Omega t - phase), phase in (-180, 180]
    const auto lag = [](const std::complex<double> z) {
      return z == 0. ? 0. : -std::arg(z) * 180 / M_PI;
    };
    // an orbit a millionth of the speed's largest is below what the solve
    // resolves (its residual is about 1e-8 of the whole): no whirl to name
    // (a loose sleeve's unbalance leaves the shaft's probes at 1e-24 m)
    double largest = 0;
    for (const auto &p : r.probes)
      largest = std::max(largest, p.forward() + p.backward());
    for (const auto &p : r.probes)
      {
        const double f = p.forward(), b = p.backward();
        file << r.rpm << ',' << csv_field(p.probe) << ',' << csv_field(r.fit_state) << ',' << std::abs(p.x) << ','
             << lag(p.x) << ',' << std::abs(p.y) << ',' << lag(p.y) << ',' << f + b << ','
             << std::abs(f - b) << ','
             << (!(f + b > 1e-6 * largest) ? "none" : f >= b ? "forward" : "backward") << ','
             << r.residual << ',' << r.basis_size << ',' << (r.converged ? 1 : 0) << '\n';
      }
    file << std::flush;
  }

  void
  write_response_peaks(const std::string &directory, const std::vector<ResponsePeak> &peaks)
  {
    std::ofstream out(directory + "/response_peaks.csv");
    out << "probe,speed_rpm,major_m,amplification_factor,half_power_low_rpm,"
           "half_power_high_rpm,separation_margin_percent,required_margin_percent,margin_ok,"
           "fit_state,resolved\n"
        << std::setprecision(8);
    for (const auto &p : peaks)
      out << csv_field(p.probe) << ',' << p.rpm << ',' << p.amplitude << ',' << p.amplification_factor
          << ',' << p.low_rpm << ',' << p.high_rpm << ',' << p.separation_margin << ','
          << p.required_margin << ','
          << (std::isnan(p.required_margin) ? "n/a" :
              p.separation_margin >= p.required_margin ? "yes" : "no")
          << ',' << csv_field(p.fit_state) << ',' << (p.resolved ? 1 : 0) << '\n';
  }
} // namespace rotorfit

namespace rotorfit
{
  void
  StabilityOnsetTable::open(const std::string &directory, const bool with_harmonic)
  {
    harmonic_columns = with_harmonic;
    create(directory + "/stability_onsets.csv",
           with_harmonic ? "tracked_id,whirl,onset_rpm,frequency_hz,direction,evaluations,converged,"
                           "harmonic,travel" :
                           "tracked_id,whirl,onset_rpm,frequency_hz,direction,evaluations,converged",
           10);
  }

  void
  StabilityOnsetTable::add(const std::vector<StabilityOnset> &onsets)
  {
    if (!file.is_open())
      return;
    for (const auto &o : onsets)
      {
        file << o.tracked_id << ',' << csv_field(o.whirl) << ',' << o.rpm << ',' << o.frequency_hz << ','
           << csv_field(o.direction) << ',' << o.evaluations << ',' << (o.converged ? 1 : 0);
        if (harmonic_columns)
          file << ',' << o.harmonic << ',' << csv_field(o.travel);
        file << '\n';
      }
    file << std::flush;
  }
} // namespace rotorfit
