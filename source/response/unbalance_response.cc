#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/response/unbalance_response.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/lac/lapack_full_matrix.h>

#include <cmath>
#include <limits>
#include <iomanip>
#include <sstream>

// UnbalanceResponse, part 1: parameters, stations and the forced solve of a
// speed. Part 2 (the peaks, their amplification factors and separation
// margins): response_peaks.cc.

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
        probes.emplace_back(name, s);
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
  UnbalanceResponse::setup(const Bearings &bearings)
  {
    if (!enabled())
      return;
    std::vector<std::pair<std::string, Station>> extra;
    extra.swap(probes);
    for (const auto &b : bearings.list())
      probes.emplace_back(b.name, b.station);
    for (auto &u : unbalances)
      {
        u.station.setup(model, log);
        probes.emplace_back(u.station.owner.substr(std::string("Unbalance ").size()), u.station);
      }
    for (auto &[name, s] : extra)
      {
        s.setup(model, log);
        probes.emplace_back(name, s);
      }
    for (unsigned int i = 0; i < probes.size(); ++i)
      for (unsigned int j = 0; j < i; ++j)
        if (probes[i].first == probes[j].first)
          throw InputError("the response probe name '" + probes[i].first +
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
        const std::complex<double> fx = u.mass_eccentricity * std::polar(1., u.phase),
                                   fy = std::complex<double>(0, -1) * fx;
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

  namespace
  {
    /// The Galerkin basis of the response: the eigen reduced model's basis
    /// V_h of this speed (if it was solved on it: its projections are
    /// known, doc/theory.md 13) followed by explicit columns e, orthonormal
    /// and M-orthogonal to V_h, with their products by M, D, K.
    struct ProjectionBasis
    {
      const PrestressedEigenproblem::SpeedOperators &op;
      std::vector<Vector<double>> v, mv, dv, kv;
      /// W^T M W, W^T D W, W^T K W over W = [V_h e], grown with the basis
      std::vector<std::vector<double>> mr, dr, kr;

      unsigned int
      head() const
      {
        return op.basis ? op.basis->size() : 0;
      }

      unsigned int
      size() const
      {
        return head() + v.size();
      }

      /// Galerkin on the basis: U = W y with (A + i B) y = W^T f, A = W^T (K -
      /// w^2 M) W, B = w W^T D W, solved as the real block system
      /// [A -B; B A] [y_re; y_im] = [W^T f_re; W^T f_im]; @p r becomes the
      /// full-space residual f - (K - w^2 M + i w D) U.
      void
      solve(const ComplexVector &f, const double w, ComplexVector &u, ComplexVector &r)
      {
        const unsigned int k = size();
        project();
        LAPACKFullMatrix<double> S(2 * k, 2 * k);
        for (unsigned int i = 0; i < k; ++i)
          for (unsigned int j = 0; j < k; ++j)
            {
              const double a = kr[i][j] - w * w * mr[i][j];
              const double b = w * dr[i][j];
              S(i, j) = S(k + i, k + j) = a;
              S(i, k + j)               = -b;
              S(k + i, j)               = b;
            }
        S.compute_lu_factorization();
        Vector<double> y = project_vector(f);
        S.solve(y);
        residual(f, w, y, u, r);
        // the projected system of a large basis solves to about eps times its
        // condition; one or two steps of refinement on the residual
        // recover what the basis can give
        const auto norm = [](const ComplexVector &z) {
          return std::sqrt(z.re.norm_sqr() + z.im.norm_sqr());
        };
        for (unsigned int refinement = 0; refinement < 2 && head() > 0; ++refinement)
          {
            Vector<double> dy = project_vector(r);
            S.solve(dy);
            Vector<double> y_new = y;
            y_new += dy;
            ComplexVector u_new, r_new;
            residual(f, w, y_new, u_new, r_new);
            if (!(norm(r_new) < 0.5 * norm(r)))
              break;
            y = std::move(y_new);
            u = std::move(u_new);
            r = std::move(r_new);
          }
      }

      /// [W^T g_re; W^T g_im].
      Vector<double>
      project_vector(const ComplexVector &g) const
      {
        const unsigned int k = size(), h = head();
        Vector<double>     y(2 * k);
        if (h > 0)
          {
            const std::vector<double> c = op.basis->coefficients(
              std::vector<const Vector<double> *>{&g.re, &g.im});
            for (unsigned int i = 0; i < h; ++i)
              y[i] = c[i], y[k + i] = c[h + i];
          }
        for (unsigned int i = h; i < k; ++i)
          {
            y[i]     = v[i - h] * g.re;
            y[k + i] = v[i - h] * g.im;
          }
        return y;
      }

      /// u = W y and r = f - (K - w^2 M + i w D) u.
      void
      residual(const ComplexVector  &f,
               const double          w,
               const Vector<double> &y,
               ComplexVector        &u,
               ComplexVector        &r) const
      {
        const unsigned int k = size(), h = head();
        r = f;
        if (h > 0)
          {
            // the head's part from the products its projections were made of
            std::vector<std::complex<double>> yh(h);
            for (unsigned int i = 0; i < h; ++i)
              yh[i] = {y[i], y[k + i]};
            u = op.basis->expand(yh);
            ComplexVector mu, du, ku;
            op.products(yh, mu, du, ku);
            r.re.add(-1., ku.re, w * w, mu.re);
            r.re.add(w, du.im);
            r.im.add(-1., ku.im, w * w, mu.im);
            r.im.add(-w, du.re);
          }
        else
          u = {Vector<double>(f.re.size()), Vector<double>(f.re.size())};
        for (unsigned int j = h; j < k; ++j)
          {
            const double       yr = y[j], yi = y[k + j];
            const unsigned int e  = j - h;
            u.re.add(yr, v[e]);
            u.im.add(yi, v[e]);
            r.re.add(-yr, kv[e], w * w * yr, mv[e]);
            r.re.add(w * yi, dv[e]);
            r.im.add(-yi, kv[e], w * w * yi, mv[e]);
            r.im.add(-w * yr, dv[e]);
          }
      }

      /// Complete the reduced matrices for the columns added since the
      /// last call (only the new rows and columns are computed).
      void
      project()
      {
        const std::size_t k = size(), h = head(), old = mr.size();
        for (auto *r : {&mr, &dr, &kr})
          {
            r->resize(k);
            for (auto &row : *r)
              row.resize(k);
          }
        if (old == 0)
          for (std::size_t i = 0; i < h; ++i)
            for (std::size_t j = 0; j < h; ++j)
              {
                mr[i][j] = (*op.Mr)(i, j);
                dr[i][j] = (*op.Cr)(i, j);
                kr[i][j] = (*op.Kr)(i, j);
              }
        const std::size_t first = std::max(old, h);
        if (h > 0 && first < k)
          {
            // V_h^T (A e), and e^T (A V_h) from the head's products, so that
            // every entry rounds as the residual does; all new columns in one
            // pass over each block
            std::vector<const Vector<double> *> e_v, e_m, e_d, e_k;
            for (std::size_t j = first; j < k; ++j)
              {
                e_v.push_back(&v[j - h]);
                e_m.push_back(&mv[j - h]);
                e_d.push_back(&dv[j - h]);
                e_k.push_back(&kv[j - h]);
              }
            const std::vector<double> m_col = op.basis->coefficients(e_m),
                                      d_col = op.basis->coefficients(e_d),
                                      k_col = op.basis->coefficients(e_k);
            std::vector<double> m_row, d_row, k_row;
            op.row_products(e_v, m_row, d_row, k_row);
            for (std::size_t j = first; j < k; ++j)
              for (std::size_t i = 0, at = (j - first) * h; i < h; ++i, ++at)
                {
                  mr[i][j] = m_col[at], mr[j][i] = m_row[at];
                  dr[i][j] = d_col[at], dr[j][i] = d_row[at];
                  kr[i][j] = k_col[at], kr[j][i] = k_row[at];
                }
          }
        for (std::size_t j = first; j < k; ++j)
          {
            const std::size_t e = j - h;
            for (std::size_t i = h; i < k; ++i)
              {
                const std::size_t c = i - h;
                mr[i][j] = v[c] * mv[e], mr[j][i] = v[e] * mv[c];
                dr[i][j] = v[c] * dv[e], dr[j][i] = v[e] * dv[c];
                kr[i][j] = v[c] * kv[e], kr[j][i] = v[e] * kv[c];
              }
          }
      }

      /// Take columns kept from an earlier speed on the same head (already
      /// M-orthonormal to it and each other, @p mx their M products); their
      /// products with this speed's D and K are made afresh.
      void
      adopt(const std::vector<Vector<double>> &x, const std::vector<Vector<double>> &mx)
      {
        v  = x;
        mv = mx;
        replicated_mmult(op.damping, pointers(v), dv);
        replicated_mmult(op.stiffness, pointers(v), kv);
      }

      /// Orthogonalise the columns @p xs against the basis and each other
      /// (twice) and append those not in its span; true if any was. Their
      /// products with M, D, K are block products (one pass over a matrix
      /// for all of them: the real and imaginary parts of a correction).
      bool
      add(std::vector<Vector<double>> xs)
      {
        std::vector<Vector<double>> x, mx;
        std::vector<double>         norm0;
        for (auto &z : xs)
          {
            const double a = z.l2_norm();
            if (a > 0 && std::isfinite(a))
              {
                norm0.push_back(a);
                x.push_back(std::move(z));
              }
          }
        if (x.empty())
          return false;
        const std::size_t old = v.size();
        if (head() > 0)
          {
            // M-orthonormal like the head (columns of one scale keep the
            // projected system as well conditioned as the basis is): against
            // the head twice, then the explicit columns, then each other
            replicated_mmult(op.mass, pointers(x), mx);
            for (std::size_t i = 0; i < x.size(); ++i)
              norm0[i] = std::sqrt(std::max(0., x[i] * mx[i]));
            for (unsigned int pass = 0; pass < 2; ++pass)
              {
                for (std::size_t i = 0; i < x.size(); ++i)
                  op.basis->subtract_projection(x[i], mx[i]);
                replicated_mmult(op.mass, pointers(x), mx);
              }
            for (std::size_t i = 0; i < x.size(); ++i)
              for (unsigned int pass = 0; pass < 2; ++pass)
                for (std::size_t e = 0; e < old; ++e)
                  x[i].add(-(mv[e] * x[i]), v[e]);
            replicated_mmult(op.mass, pointers(x), mx);
            for (std::size_t i = 0; i < x.size(); ++i)
              {
                if (v.size() > old)
                  {
                    // the columns of this block kept before it
                    for (unsigned int pass = 0; pass < 2; ++pass)
                      for (std::size_t e = old; e < v.size(); ++e)
                        x[i].add(-(mv[e] * x[i]), v[e]);
                    replicated_vmult(op.mass, x[i], mx[i]);
                  }
                const double m_norm = std::sqrt(std::max(0., x[i] * mx[i]));
                if (!(m_norm > 1e-10 * norm0[i]))
                  continue;
                x[i] /= m_norm;
                mx[i] /= m_norm;
                v.push_back(std::move(x[i]));
                mv.push_back(std::move(mx[i]));
              }
          }
        else
          {
            for (std::size_t i = 0; i < x.size(); ++i)
              {
                for (unsigned int pass = 0; pass < 2; ++pass)
                  for (const auto &q : v)
                    x[i].add(-(q * x[i]), q);
                const double norm = x[i].l2_norm();
                if (!(norm > 1e-10 * norm0[i]))
                  continue;
                x[i] /= norm;
                v.push_back(std::move(x[i]));
              }
            std::vector<const Vector<double> *> added;
            for (std::size_t e = old; e < v.size(); ++e)
              added.push_back(&v[e]);
            replicated_mmult(op.mass, added, mx);
            for (auto &z : mx)
              mv.push_back(std::move(z));
          }
        std::vector<const Vector<double> *> added;
        for (std::size_t e = old; e < v.size(); ++e)
          added.push_back(&v[e]);
        std::vector<Vector<double>> dx, kx;
        replicated_mmult(op.damping, added, dx);
        replicated_mmult(op.stiffness, added, kx);
        for (std::size_t e = 0; e < added.size(); ++e)
          {
            dv.push_back(std::move(dx[e]));
            kv.push_back(std::move(kx[e]));
          }
        return v.size() > old;
      }
    };
  } // namespace

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
    // one attempt on a basis; on the eigen reduced model's basis it gives up
    // when an enrichment step no longer halves the residual (the products
    // of its head with a stiff K round to about that level), and the speed
    // is solved on its modes instead
    const auto attempt = [&](const PrestressedEigenproblem::SpeedOperators &o) {
      ProjectionBasis basis{o, {}, {}, {}, {}, {}, {}, {}};
      // on the eigen reduced basis of the last speed: that speed's explicit
      // columns (at most as many as a fresh start and four enrichments hold)
      const std::pair<const ReducedBasis *, unsigned int> head{o.basis,
                                                               o.basis ? o.basis->version() : 0};
      const bool reuse = o.basis && head == kept_head && !kept.empty();
      const auto keep  = [&](const bool ok) {
        if (o.basis && ok && basis.v.size() <= 10)
          {
            kept      = basis.v;
            kept_m    = basis.mv;
            kept_head = head;
          }
        else if (o.basis)
          {
            kept.clear();
            kept_m.clear();
            kept_head = {nullptr, 0};
          }
        return ok;
      };
      if (reuse)
        basis.adopt(kept, kept_m);
      else
        {
          // the speed's modes lie in the eigen reduced basis when it solved them
          if (!o.basis)
            for (const auto &p : modes)
              basis.add({p.phi.re, p.phi.im});
          // S^-1 F: F = Omega^2 F_0, so the direction of the latest
          // factorisation's S^-1 F_0 (the real and imaginary parts in one
          // pass over the factors), made once per factorisation
          if (correction_factor !=
              std::make_pair(&o.shifted_inverse, o.shifted_inverse.n_operators()))
            {
              const ComplexVector f0 = forcing();
              replicated_solve(o.shifted_inverse, o.mass, {&f0.re, &f0.im}, static_correction);
              correction_factor = {&o.shifted_inverse, o.shifted_inverse.n_operators()};
            }
          basis.add(static_correction);
        }
      std::vector<Vector<double>> x;
      double previous = std::numeric_limits<double>::infinity();
      for (unsigned int step = 0;; ++step)
        {
          ComplexVector r = f;
          basis.solve(f, w, u, r);
          out.residual   = std::sqrt(r.re.norm_sqr() + r.im.norm_sqr()) / f_norm;
          out.basis_size = basis.size();
          if (out.residual <= tolerance)
            return keep(true);
          if (o.basis && !(out.residual < 0.5 * previous))
            return keep(false);
          previous   = out.residual;
          bool grown = false;
          if (step < max_enrichment)
            {
              replicated_solve(o.shifted_inverse, o.mass, {&r.re, &r.im}, x);
              grown = basis.add(std::move(x));
            }
          if (!grown)
            return keep(false);
        }
    };
    if (f_norm > 0)
      {
        bool done = false;
        if (op.basis)
          {
            done = attempt(op);
            reduced_speeds += done ? 1 : 0;
          }
        if (!done)
          {
            PrestressedEigenproblem::SpeedOperators on_modes = op;
            on_modes.basis                                   = nullptr;
            out.converged                                    = attempt(on_modes);
          }
      }
    if (!std::isfinite(out.residual))
      out.converged = false;
    out.probes = read_probes(u);
    if (!out.converged)
      {
        ++unconverged_speeds;
        log << "Warning: unbalance response at " << state.rpm << " r/min: the residual "
            << std::setprecision(3) << out.residual << " is above Unbalance response/Residual "
            << "tolerance = " << tolerance << " after " << out.basis_size
            << " basis vectors; the row is flagged (converged = 0). Raise Maximum "
               "enrichments or Eigenproblem/Number of modes.\n";
      }
    if (!(out.residual <= worst_residual))
      worst_residual = out.residual;
    history.push_back(out);
    return out;
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
