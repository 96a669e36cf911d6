#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/response/projection_basis.h>
#include <rotorfit/response/unbalance_response.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/lac/lapack_full_matrix.h>

#include <cmath>
#include <limits>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  UnbalanceResponse::UnbalanceResponse(const Discretization &model, Log &log)
    : model(model)
    , log(log)
  {}

  void
  UnbalanceResponse::declare_lists(ParameterHandler &prm)
  {
    prm.declare_entry("Unbalances",
                      "",
                      Patterns::List(Patterns::Anything(), 0),
                      "Names of the unbalance masses (empty: no unbalance "
                      "response). Each needs a subsection 'Unbalance <name>'.");
    prm.declare_entry("Probes",
                      "",
                      Patterns::List(Patterns::Anything(), 0),
                      "Names of extra response stations (every bearing and "
                      "unbalance station is probed anyway). Each needs a "
                      "subsection 'Probe <name>'.");
  }

  void
  UnbalanceResponse::declare_parameters(ParameterHandler               &prm,
                                        const std::vector<std::string> &unbalance_names,
                                        const std::vector<std::string> &probe_names)
  {
    for (const auto &name : unbalance_names)
      {
        prm.enter_subsection("Unbalance " + name);
        Station::declare_parameters(prm, "the unbalance");
        prm.declare_entry("Mass eccentricity",
                          "",
                          patterns::Mandatory(patterns::Positive()),
                          "Unbalance m e [kg m] (mass times its distance from the "
                          "axis; 1 g mm = 1e-6 kg m). Mandatory.");
        prm.declare_entry("Phase",
                          "0",
                          Patterns::Double(),
                          "Angular position of the unbalance at t = 0 from the x "
                          "axis towards y [deg].");
        prm.leave_subsection();
      }
    for (const auto &name : probe_names)
      {
        prm.enter_subsection("Probe " + name);
        Station::declare_parameters(prm, "the probe");
        prm.leave_subsection();
      }
    prm.enter_subsection("Unbalance response");
    prm.declare_entry("Operating speed range",
                      "",
                      Patterns::List(Patterns::Double(0), 0, 2),
                      "Minimum and maximum continuous operating speed [r/min] "
                      "(empty: no separation margins).");
    prm.declare_entry("Residual tolerance",
                      "1e-8",
                      patterns::Positive(),
                      "The projected solve is enriched until the full-space "
                      "residual ||F - Z U|| / ||F|| is below this [-].");
    prm.declare_entry("Maximum enrichments",
                      "20",
                      Patterns::Integer(0),
                      "Cap on the enrichment steps per speed (two vectors each); "
                      "a speed that does not meet the tolerance is flagged.");
    prm.leave_subsection();
  }

  void
  UnbalanceResponse::parse_parameters(ParameterHandler &prm, const bool modes_computed)
  {
    unbalances.clear();
    probes.clear();
    for (const auto &name : Utilities::split_string_list(prm.get("Unbalances"), ','))
      {
        prm.enter_subsection("Unbalance " + name);
        Unbalance u;
        u.name = name;
        u.station.parse_parameters(prm, "Unbalance " + name);
        u.mass_eccentricity = prm.get_double("Mass eccentricity");
        u.phase             = prm.get_double("Phase") * M_PI / 180;
        prm.leave_subsection();
        unbalances.push_back(u);
      }
    for (const auto &name : Utilities::split_string_list(prm.get("Probes"), ','))
      {
        prm.enter_subsection("Probe " + name);
        Station s;
        s.parse_parameters(prm, "Probe " + name);
        prm.leave_subsection();
        probes.push_back({name, s});
      }
    prm.enter_subsection("Unbalance response");
    operating.clear();
    for (const auto &v : Utilities::split_string_list(prm.get("Operating speed range"), ','))
      operating.push_back(Utilities::string_to_double(v));
    if (operating.size() == 1 || (operating.size() == 2 && !(operating[1] >= operating[0])))
      throw InputError("Unbalance response/Operating speed range = " +
                       prm.get("Operating speed range") +
                       ": give the minimum and the maximum continuous speed [r/min], "
                       "minimum first.");
    tolerance      = prm.get_double("Residual tolerance");
    max_enrichment = prm.get_integer("Maximum enrichments");
    prm.leave_subsection();
    if (enabled() && !modes_computed)
      throw InputError("Unbalances are given but Eigenproblem/Compute modes = false; the "
                       "unbalance response needs the eigenproblem's matrices (set it to true).");
    if (!enabled() && !probes.empty())
      log << "Warning: Probes are given but no Unbalances: there is no response to probe.\n";
  }

  void
  UnbalanceResponse::setup(const Bearings &bearings, const std::function<void(Station &)> &place)
  {
    if (!enabled())
      return;
    const auto put = [&](Station &s) {
      if (place)
        place(s);
      else
        s.setup(model, log);
    };
    std::vector<Probe> extra;
    extra.swap(probes);
    for (const auto &b : bearings.list())
      {
        probes.push_back({b.name, b.station});
        if (place) // (on the 3D mesh the bearings have placed their own)
          place(probes.back().station);
      }
    for (auto &u : unbalances)
      {
        put(u.station);
        probes.push_back({u.name, u.station});
      }
    for (auto &[name, s] : extra)
      {
        put(s);
        probes.push_back({name, s});
      }
    for (unsigned int i = 0; i < probes.size(); ++i)
      for (unsigned int j = 0; j < i; ++j)
        if (probes[i].name == probes[j].name)
          throw InputError("the response probe name '" + probes[i].name +
                           "' is used twice (bearings, unbalances and Probes share one "
                           "list of names in response.csv); rename one.");
    std::ostringstream m;
    m << "Unbalance response: " << unbalances.size() << " unbalance(s)";
    for (const auto &u : unbalances)
      m << "; " << u.station.owner << " m e " << u.mass_eccentricity << " kg m at "
        << u.phase * 180 / M_PI << " deg on the " << u.station.describe() << " (z "
        << u.station.z << " m)";
    m << "; probes:";
    for (const auto &[name, s] : probes)
      m << ' ' << name;
    log << m.str() << '\n';
  }

  ComplexVector
  UnbalanceResponse::forcing() const
  {
    const std::size_t n = model.dofs().n_dofs();
    ComplexVector     f{Vector<double>(n), Vector<double>(n)};
    // F_x = m e e^{i phi}, F_y = -i F_x: the force m e Omega^2
    // (cos(Omega t + phi), sin(Omega t + phi)) turning with the rotor
    for (const auto &u : unbalances)
      {
        const std::complex<double> fx = u.force_x(), fy = std::complex<double>(0, -1) * fx;
        const Station &s = u.station;
        for (unsigned int i = 0; i < s.weight.size(); ++i)
          {
            f.re[s.dof_x[i]] += s.weight[i] * fx.real();
            f.im[s.dof_x[i]] += s.weight[i] * fx.imag();
            f.re[s.dof_y[i]] += s.weight[i] * fy.real();
            f.im[s.dof_y[i]] += s.weight[i] * fy.imag();
          }
      }
    return f;
  }

  ResponseAtSpeed
  UnbalanceResponse::solve(const StaticState                              &state,
                           const PrestressedEigenproblem::SpeedOperators &op,
                           const std::vector<EigenPair>                   &modes)
  {
    AssertThrow(op.rpm == state.rpm, ExcInternalError());
    ResponseAtSpeed out;
    out.rpm       = state.rpm;
    out.fit_state = state.fit_state;
    const double  w = SpeedSchedule::rpm_to_rad_per_s(state.rpm);
    ComplexVector f = forcing();
    f.re *= w * w;
    f.im *= w * w;
    const double f_norm = std::sqrt(f.re.norm_sqr() + f.im.norm_sqr());
    const std::size_t n = f.re.size();
    ComplexVector u{Vector<double>(n), Vector<double>(n)};
    if (f_norm > 0)
      {
        bool done = false;
        if (op.basis)
          {
            done = attempt(op, modes, {f, w, f_norm}, u, out);
            reduced_speeds += done ? 1 : 0;
          }
        if (!done)
          {
            PrestressedEigenproblem::SpeedOperators on_modes = op;
            on_modes.basis                                   = nullptr;
            out.converged = attempt(on_modes, modes, {f, w, f_norm}, u, out);
          }
      }
    out.probes = read_probes(u);
    record(out);
    return out;
  }

  void
  UnbalanceResponse::record(ResponseAtSpeed &out, const std::string &remedy)
  {
    if (!std::isfinite(out.residual))
      out.converged = false;
    if (!out.converged)
      {
        ++unconverged_speeds;
        log << "Warning: unbalance response at " << out.rpm << " r/min: the residual "
            << std::setprecision(3) << out.residual << " is above Unbalance response/Residual "
            << "tolerance = " << tolerance << " after " << out.basis_size
            << " basis vectors; the row is flagged (converged = 0). " << remedy << ".\n";
      }
    if (!(out.residual <= worst_residual))
      worst_residual = out.residual;
    history.push_back(out);
  }

  bool
  UnbalanceResponse::attempt(const PrestressedEigenproblem::SpeedOperators &o,
                             const std::vector<EigenPair>                   &modes,
                             const Load                                     &load,
                             ComplexVector                                  &u,
                             ResponseAtSpeed                                &out)
  {
    // one attempt on a basis; on the eigen reduced model's basis it gives up
    // when an enrichment step no longer halves the residual (the products
    // of its head with a stiff K round to about that level), and the speed
    // is solved on its modes instead
    const ComplexVector &f = load.f;
    const double         w = load.w;
    ProjectionBasis      basis{o, {}, {}, {}, {}, nullptr, w, {}, {}, {}};
    // on the eigen reduced basis of the last speed: that speed's explicit
    // columns (at most as many as a fresh start and four enrichments hold)
    const std::pair<const ReducedBasis *, unsigned int> head{o.basis,
                                                             o.basis ? o.basis->version() : 0};
    const bool reuse = o.basis && head == kept_head && !kept.empty();
    if (reuse)
      basis.adopt(kept, kept_m, kept_products, w);
    else
      start_basis(basis, modes);
    std::vector<Vector<double>> x;
    double previous = std::numeric_limits<double>::infinity();
    for (unsigned int step = 0;; ++step)
      {
        ComplexVector r = f;
        basis.solve(f, w, tolerance, u, r);
        out.residual   = std::sqrt(r.re.norm_sqr() + r.im.norm_sqr()) / load.norm;
        out.basis_size = basis.size();
        if (out.residual <= tolerance)
          return keep(basis, head, reuse, true);
        if (o.basis && !(out.residual < 0.5 * previous))
          return keep(basis, head, reuse, false);
        previous   = out.residual;
        bool grown = false;
        if (step < max_enrichment)
          {
            replicated_solve(o.shifted_inverse, o.mass, {&r.re, &r.im}, x);
            grown = basis.add(std::move(x));
          }
        if (!grown)
          return keep(basis, head, reuse, false);
      }
  }

  void
  UnbalanceResponse::start_basis(ProjectionBasis &basis, const std::vector<EigenPair> &modes)
  {
    const PrestressedEigenproblem::SpeedOperators &o = basis.op;
    // the speed's modes lie in the eigen reduced basis when it solved them
    if (!o.basis)
      for (const auto &p : modes)
        basis.add({p.phi.re, p.phi.im});
    // S^-1 F: F = Omega^2 F_0, so the direction of the latest
    // factorisation's S^-1 F_0 (the real and imaginary parts in one pass
    // over the factors), made once per factorisation
    if (correction_factor != std::make_pair(&o.shifted_inverse, o.shifted_inverse.n_operators()))
      {
        const ComplexVector f0 = forcing();
        replicated_solve(o.shifted_inverse, o.mass, {&f0.re, &f0.im}, static_correction);
        correction_factor = {&o.shifted_inverse, o.shifted_inverse.n_operators()};
      }
    basis.add(static_correction);
  }

  bool
  UnbalanceResponse::keep(const ProjectionBasis                               &basis,
                          const std::pair<const ReducedBasis *, unsigned int> &head,
                          const bool                                           reuse,
                          const bool                                           ok)
  {
    const PrestressedEigenproblem::SpeedOperators &o = basis.op;
    if (o.basis && ok && basis.v.size() <= 10)
      {
        // the same columns again: their products at the speed they were
        // first kept stay the base of the affine share
        if (!(reuse && basis.v.size() == kept.size() && o.segment != 0 &&
              o.segment == kept_products.segment))
          rekeep({o.segment, basis.omega, basis.dv, basis.kv, {}, {}});
        kept      = basis.v;
        kept_m    = basis.mv;
        kept_head = head;
      }
    else if (o.basis)
      {
        kept.clear();
        kept_m.clear();
        kept_head = {nullptr, 0};
        rekeep({});
      }
    return ok;
  }

  void
  UnbalanceResponse::rekeep(KeptProducts next)
  {
    // (the checks' record goes on from one kept base to the next)
    next.worst    = kept_products.worst;
    next.served   = kept_products.served;
    next.refused  = kept_products.refused;
    kept_products = std::move(next);
  }

  std::vector<ResponsePeak>
  UnbalanceResponse::peaks() const
  {
    return find_response_peaks(history, operating);
  }

  std::vector<ProbeResponse>
  UnbalanceResponse::read_probes(const ComplexVector &u) const
  {
    std::vector<ProbeResponse> out;
    for (const auto &[name, s] : probes)
      {
        ProbeResponse p;
        p.probe = name;
        for (unsigned int i = 0; i < s.weight.size(); ++i)
          {
            p.x += s.weight[i] * std::complex<double>(u.re[s.dof_x[i]], u.im[s.dof_x[i]]);
            p.y += s.weight[i] * std::complex<double>(u.re[s.dof_y[i]], u.im[s.dof_y[i]]);
          }
        out.push_back(p);
      }
    return out;
  }

  void
  UnbalanceResponse::finish(Summary &summary) const
  {
    if (!enabled())
      return;
    summary.add("response.speeds", history.size());
    summary.add("response.unconverged_speeds", unconverged_speeds);
    summary.add("response.reduced_speeds", reduced_speeds);
    summary.add("response.worst_residual", worst_residual, 3);
    // the kept columns' D and K products from the speed's affine share,
    // against the sparse products where checked
    summary.add("response.kept_products_worst_mismatch", kept_products.worst, 3);
    summary.add("response.kept_products_speeds", kept_products.served);
    summary.add("response.kept_products_refused", kept_products.refused);
    unsigned int unresolved = 0;
    for (const auto &p : peaks())
      if (!p.resolved)
        {
          ++unresolved;
          log << "Warning: response peak of " << p.probe << " at " << format_number(p.rpm)
              << " r/min: fewer than three speeds lie in its half-power band, so the "
                 "amplification factor "
              << std::setprecision(3) << p.amplification_factor
              << " is a lower bound and the separation margin is judged against the "
                 "largest required (16 % below, 26 % above the range); add speeds near it "
                 "(Speeds/Mode = list) to resolve it (response_peaks.csv: resolved = 0).\n";
        }
    summary.add("response.unresolved_peaks", unresolved);
    if (operating.size() == 2)
      summary.add("response.operating_range_rpm",
                  format_number(operating[0]) + " " + format_number(operating[1]));
  }
} // namespace rotorfit
