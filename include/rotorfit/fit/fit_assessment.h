#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/material/bodies.h>
#include <rotorfit/statics/stress_field.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/lac/petsc_vector.h>

#include <memory>
#include <vector>

namespace rotorfit
{
  /**
   * The fit designer's numbers at every speed (doc/fit_design.md,
   * doc/theory.md 10f): per interface the friction capacity of the closed
   * pairs, mu sum N_i r_i (torque) and mu sum N_i (axial), the safety
   * against slip under the given torque and axial force, and the speed at
   * which it falls to 1; the nominal bore stresses of hub and shaft and
   * their safety against yield; per body the largest von Mises stress (over the cells' quadrature points and the bores' nominal points).
   *
   * The slip speed is exact on the exact path: between two changes of the
   * closed set the forces are affine in Omega^2, and the path reports the
   * resultants at each change (ResultantKink). On the sampled path it is
   * interpolated linearly between the speeds.
   */
  class FitAssessment
  {
  public:
    /// The fits of @p pairs (their specifications in @p interfaces) and the
    /// bodies' yield strengths: any model's, 3D or meridian.
    FitAssessment(const ContactPairs &pairs, const ContactInterfaces &interfaces,
                  const Bodies &bodies);

    /// After the model's setup(): size the records; @p field evaluates the
    /// model's stresses (it located the bore points).
    void
    initialize(std::unique_ptr<StressField> field);

    /// Fill state.fits and state.body_stresses; @p u: the displacement at
    /// the state's speed, ghosted.
    void
    record(StaticState &state, const dealii::PETScWrappers::MPI::Vector &u);

    /// The summary keys: per interface its interference, capacity, slip
    /// speed, stresses and mounting temperature; per body its largest
    /// stress and least safety against yield.
    void
    add_to_summary(Summary &summary) const;

  private:
    /// Safety against slip of interface @p f with resultants @p force,
    /// @p moment [-] (infinity without load).
    double
    slip_safety(const unsigned int f, const double force, const double moment) const;

    /// Where the safety of interface @p f falls below 1 on the piece from
    /// (w0, F0, M0) to (w1, F1, M1), affine between them (NaN: not there).
    double
    slip_w(const unsigned int f, const double w0, const double F0, const double M0,
           const double w1, const double F1, const double M1) const;

    const ContactPairs          &pairs;
    const ContactInterfaces     &interfaces;
    const Bodies                &bodies;
    std::unique_ptr<StressField> stress;

    /// per interface, at the last recorded speed: Omega^2 and resultants
    std::vector<double> last_w, last_force, last_moment;
    bool                first = true;
    /// per interface: slip speed, least slip safety and its speed, values at the first speed
    std::vector<double> slip_rpm, least_safety, least_safety_rpm;
    std::vector<FitRow> first_rows;
    /// per body: the largest von Mises stress and where, over the speeds
    std::vector<BodyStressRow> worst_body;
    std::vector<double>        worst_body_rpm;
    /// per interface and side: the largest nominal bore von Mises over the speeds
    std::vector<double> worst_hub_bore, worst_shaft_bore;
  };
} // namespace rotorfit
