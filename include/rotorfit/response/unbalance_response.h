#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/model/station.h>
#include <rotorfit/response/response_peaks.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/parameter_handler.h>

#include <array>
#include <functional>
#include <complex>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  struct ProjectionBasis;

  /// The steady unbalance response of one station at one speed: complex
  /// amplitudes of its averaged lateral displacement, x(t) = Re(X e^{i Omega t}).
  struct ProbeResponse
  {
    std::string          probe;
    std::complex<double> x, y; ///< [m]

    /// Forward and backward circular components of the orbit [m].
    double
    forward() const
    {
      return std::abs(x + std::complex<double>(0, 1) * y) / 2;
    }
    double
    backward() const
    {
      return std::abs(x - std::complex<double>(0, 1) * y) / 2;
    }
  };

  struct ResponseAtSpeed
  {
    double                     rpm = 0;
    std::string                fit_state;
    std::vector<ProbeResponse> probes;
    double       residual   = 0; ///< ||F - Z U|| / ||F|| of the full system
    unsigned int basis_size = 0;
    bool         converged  = true;
  };

  /**
   * Unbalance response (doc/theory.md 13): masses m e at stations, at
   * every speed the steady forced response with that speed's contact state
   * and prestress,
   *
   *   (K_t - Omega^2 M + i Omega (C + Omega G)) U = F Omega^2,
   *
   * F_x = m e e^{i phi} a, F_y = -i F_x (a: the station's weights). Solved on
   * the eigen reduced model's basis where the speed was solved on it (its
   * projections are at hand), else on the speed's eigenvectors, plus
   * Q(sigma)^{-1} F (the eigensolver's factorisation), enriched by
   * Q(sigma)^{-1} r until the full-space residual r is below a tolerance: no
   * factorisation of its own. The response is read
   * at probes (every bearing and unbalance station, and "Probe <name>"); the
   * peaks get their half-power amplification factor and separation margin.
   *
   * Parameters: the lists "Unbalances" and "Probes", subsections
   * "Unbalance <name>", "Probe <name>" and "Unbalance response".
   */
  class UnbalanceResponse
  {
  public:
    /// Within one contact segment (SpeedOperators::segment) the kept
    /// columns' D and K products follow the speed's affine share: their
    /// products at the speed they were kept (omega) and, made at the
    /// first speed after, G and K_t2 times them (no sparse products per speed)
    struct KeptProducts
    {
      unsigned int                        segment = 0;
      double                              omega   = 0;
      std::vector<dealii::Vector<double>> d, k, g, k2;
      /// their projections, made once: V_h^T X and X^T (A V_h) (h x k,
      /// column-major), e_c^T X_e (k x k) for X = M E, D_s E, G E, K_s E,
      /// K_t2 E (and the head's five products); the head's tangent was made
      /// at w_tangent
      /// speeds served by this base and by all (served), the largest
      /// mismatch against the sparse products where checked (every tenth
      /// speed) and the bases dropped for it
      unsigned int                       uses = 0, served = 0, refused = 0;
      double                             worst = 0;
      bool                               projected = false;
      double                             w_tangent = 0;
      std::array<std::vector<double>, 5> col, row, own;
    };

    UnbalanceResponse(const Discretization &model, Log &log);

    static void
    declare_lists(dealii::ParameterHandler &prm);

    static void
    declare_parameters(dealii::ParameterHandler       &prm,
                       const std::vector<std::string> &unbalances,
                       const std::vector<std::string> &probes);

    /// @p modes_computed: the response needs the eigenproblem's matrices.
    void
    parse_parameters(dealii::ParameterHandler &prm, const bool modes_computed);

    bool
    enabled() const
    {
      return !unbalances.empty();
    }

    /// Stations of the unbalances, bearings and probes: on the 3D mesh, or
    /// (@p place given) each placed by it, the bearings' too (the
    /// axisymmetric model's meridian).
    void
    setup(const Bearings &bearings, const std::function<void(Station &)> &place = {});

    /// The response at the speed of @p state (after eigen.solve() there).
    ResponseAtSpeed
    solve(const StaticState                              &state,
          const PrestressedEigenproblem::SpeedOperators &operators,
          const std::vector<EigenPair>                   &modes);

    /// Peaks of every probe over the sweep so far.
    std::vector<ResponsePeak>
    peaks() const;

    /// The operating range [r/min] (empty: none given).
    const std::vector<double> &
    operating_range() const
    {
      return operating;
    }

    void
    finish(Summary &summary) const;

    /// An unbalance mass of the list "Unbalances".
    struct Unbalance
    {
      std::string name; ///< as listed (subsection "Unbalance <name>")
      Station station;
      double  mass_eccentricity = 0; ///< [kg m]
      double  phase             = 0; ///< [rad]

      /// F_x per unit Omega^2: m e e^{i phi} (F_y = -i F_x, doc/theory.md 13)
      std::complex<double>
      force_x() const
      {
        return mass_eccentricity * std::polar(1., phase);
      }
    };

    /// A station whose response is read: a bearing, an unbalance or one of
    /// the list "Probes".
    struct Probe
    {
      std::string name;
      Station     station;
    };

    const std::vector<Unbalance> &
    unbalance_list() const
    {
      return unbalances;
    }

    /// The probes, in the order of response.csv (after setup()).
    const std::vector<Probe> &
    probe_list() const
    {
      return probes;
    }

    /// Unbalance response/Residual tolerance.
    double
    residual_tolerance() const
    {
      return tolerance;
    }

    /// Unbalance response/Maximum enrichments.
    unsigned int
    maximum_enrichments() const
    {
      return max_enrichment;
    }

    /// A speed solved elsewhere (the axisymmetric model) on a reduced
    /// basis: counted in response.reduced_speeds.
    void
    count_reduced_speed()
    {
      ++reduced_speeds;
    }

    /// Record @p out, a speed's response solved elsewhere (the axisymmetric
    /// model) or by solve(): not converged if its residual is not finite,
    /// flagged and warned about (with @p remedy) if not converged; kept for
    /// the peaks.
    void
    record(ResponseAtSpeed   &out,
           const std::string &remedy = "Raise Maximum enrichments or Eigenproblem/Number of modes");

  private:
    /// The forcing of a speed: F Omega^2, Omega [rad/s] and ||F Omega^2||.
    struct Load
    {
      const ComplexVector &f;
      double               w    = 0;
      double               norm = 0;
    };

    /// Solve @p load on the basis of operators @p o (the eigen reduced
    /// basis if it has one, else @p modes), enriched until the residual
    /// meets the tolerance: into @p u, with residual and basis size in
    /// @p out; false if it did not converge.
    bool
    attempt(const PrestressedEigenproblem::SpeedOperators &o,
            const std::vector<EigenPair>                   &modes,
            const Load                                     &load,
            ComplexVector                                  &u,
            ResponseAtSpeed                                &out);

    /// A fresh basis: the speed's modes (unless on the eigen reduced
    /// basis) and the static correction S^-1 F_0.
    void
    start_basis(ProjectionBasis &basis, const std::vector<EigenPair> &modes);

    /// Keep @p basis's explicit columns for the next speed on the same
    /// @p head (if @p ok and few), else drop the kept ones; returns @p ok.
    bool
    keep(const ProjectionBasis                               &basis,
         const std::pair<const ReducedBasis *, unsigned int> &head,
         const bool                                           reuse,
         const bool                                           ok);

    /// Replace the kept products by @p next, carrying the checks' record.
    void
    rekeep(KeptProducts next);

    /// Full-space forcing per unit Omega^2 (replicated, complex).
    ComplexVector
    forcing() const;

    /// The averaged complex displacement of every probe.
    std::vector<ProbeResponse>
    read_probes(const ComplexVector &u) const;

    const Discretization &model;
    Log                  &log;

    std::vector<Unbalance> unbalances;
    std::vector<Probe>     probes;
    std::vector<double>    operating;
    double                 tolerance      = 1e-8;
    unsigned int           max_enrichment = 20;

    /// S^-1 F_0 (real, imaginary part) of the factorisation named by
    /// correction_factor (solver, its factorisation count)
    std::vector<dealii::Vector<double>>          static_correction;
    std::pair<const DirectSolver *, unsigned int> correction_factor{nullptr, 0};
    /// The explicit columns (static correction, enrichments) of the last
    /// speed solved on the eigen reduced basis named by kept_head (basis,
    /// its version), with their M products: the next speed on the same
    /// basis starts from them (the response moves little from speed to
    /// speed, so it rarely needs a new back-substitution)
    std::vector<dealii::Vector<double>>             kept, kept_m;
    std::pair<const ReducedBasis *, unsigned int>   kept_head{nullptr, 0};
    KeptProducts                                    kept_products;
    std::vector<ResponseAtSpeed> history;
    unsigned int                 unconverged_speeds = 0;
    unsigned int                 reduced_speeds     = 0; ///< solved on the eigen reduced basis
    double                       worst_residual     = 0;
  };
} // namespace rotorfit
