#pragma once

#include <rotorfit/contact/contact_solver.h>

#include <deal.II/base/point.h>
#include <deal.II/base/timer.h>

#include <deal.II/lac/petsc_vector.h>

#include <memory>
#include <string>
#include <vector>

namespace rotorfit
{
  /// One interface at one speed: a row of contact.csv.
  struct InterfaceRow
  {
    std::string  name;
    unsigned int closed_pairs = 0, total_pairs = 0;
    double       contact_fraction = 0; ///< closed area / interface area
    double       mean_pressure = 0, max_pressure = 0; ///< [Pa]
    double       constraint_error = 0;  ///< max |g| / delta over closed pairs
    double       first_opening_rpm = 0; ///< NaN until a pair opened
    double       loss_of_fit_rpm   = 0; ///< found, or predicted by the active set's law
    double       asymmetry         = 0; ///< ContactPairs::asymmetry()
    std::string  status;                ///< "ok" or why not converged
  };

  /// The fit designer's numbers of one interface at one speed: a row of fit.csv.
  struct FitRow
  {
    std::string name;
    double radial_interference = 0; ///< effective, with the temperatures, at the mean radius [m]
    double mean_pressure = 0, edge_peak_ratio = 0; ///< [Pa], max / mean pressure [-]
    bool   with_friction = false; ///< a friction coefficient is given
    double torque_capacity = 0;   ///< mu sum N_i r_i [N m]
    double axial_capacity  = 0;   ///< mu sum N_i [N]
    double slip_safety     = 0;   ///< against the given torque and axial force [-] (inf: no load)
    double slip_rpm        = 0;   ///< where the safety fell to 1 (NaN: not yet)
    /// nominal stresses at the fit's mid-plane, innermost radius of each body [Pa]
    double hub_bore_von_mises = 0, shaft_bore_von_mises = 0;
    double hub_bore_hoop = 0, shaft_bore_hoop = 0;
    double hub_yield_safety = 0, shaft_yield_safety = 0; ///< Rp0.2 / nominal (NaN: no Rp0.2)
  };

  /// The largest stress of one body at one speed: a row of body_stress.csv.
  struct BodyStressRow
  {
    std::string      name;
    double           max_von_mises = 0; ///< over the cell quadrature points and the bore points [Pa]
    dealii::Point<3> location;
    double           yield_safety = 0; ///< Rp0.2 / max (NaN: no Rp0.2)
  };

  /// A pair that opened between two speeds: a row of pair_openings.csv.
  struct PairOpening
  {
    std::string      interface;
    dealii::Point<3> position;
    double           opening_rpm = 0, from_rpm = 0, to_rpm = 0;
  };

  /// A pair that opened or closed on the exact path: a row of contact_events.csv.
  struct ContactEventRow
  {
    std::string      interface;
    dealii::Point<3> position;
    double           rpm     = 0;
    bool             opening = true;
    unsigned int     closed_pairs     = 0; ///< of the interface, after the event
    double           contact_fraction = 0; ///< after the event
  };

  /**
   * The static state at one speed, as the rest of the run sees it: the
   * contact solution, its evaluation per interface and a read-only view of
   * the affine law behind it (the eigenproblem's stress stiffening and ties
   * are built from it). Made by StaticProblem::solve(); valid until the
   * next call.
   */
  class StaticState
  {
  public:
    double               rpm   = 0;
    unsigned int         index = 0; ///< position in the speed list
    ContactSolver::State contact;   ///< closed pairs, forces, gaps, pressures
    std::vector<InterfaceRow> interfaces;
    std::vector<PairOpening>  openings; ///< since the previous speed
    std::vector<ContactEventRow> events; ///< since the previous speed (exact path)
    std::vector<FitRow>          fits;   ///< per interface
    std::vector<BodyStressRow>   body_stresses; ///< per body
    std::string fit_state = "closed";   ///< closed / partial / open (any interface)

    bool
    converged() const
    {
      return contact.converged;
    }

    /// The contact state of @p contact at @p rpm, the @p index-th speed of
    /// the run, continuing from its last one (timed as "contact solve").
    static StaticState
    solve(ContactSolver &contact, const double rpm, const unsigned int index,
          dealii::TimerOutput &timer);

    /// Omega^2 [rad^2/s^2].
    double
    w() const;

    /// u = u_I + w u_C of the active set (or the tangent with spin softening).
    const ContactSolver::Decomposition &
    decomposition() const
    {
      return *law;
    }

    /// The law shared by every speed on it: its identity tells a keeper of
    /// things made from it (K_sigma of its parts) whether they still hold.
    const std::shared_ptr<const ContactSolver::Decomposition> &
    shared_law() const
    {
      return law;
    }

    /// Displacement at this speed, ghosted (all DoFs).
    void
    displacement(dealii::PETScWrappers::MPI::Vector &u) const
    {
      solver->displacement(*law, w(), u);
    }

    /// Penalty of pair @p i [N/m] and the scale it was made with.
    double
    pair_penalty(const unsigned int i) const
    {
      return solver->penalty(i);
    }
    double
    penalty_scale() const
    {
      return solver->penalty_scale();
    }

  private:
    const ContactSolver                                 *solver = nullptr;
    std::shared_ptr<const ContactSolver::Decomposition> law;
  };
} // namespace rotorfit
