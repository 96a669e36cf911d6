#include <rotorfit/base/patterns.h>
#include <rotorfit/contact/contact_parameters.h>

namespace rotorfit
{
  using namespace dealii;

  void
  ContactParameters::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Contact");
    prm.declare_entry("Method",
                      "augmented Lagrangian",
                      Patterns::Selection("augmented Lagrangian|penalty"),
                      "Enforcement of the node-to-node contact constraints: "
                      "'penalty' leaves a penetration of about 1/(1 + Penalty "
                      "scale) of the interference; 'augmented Lagrangian' "
                      "(Uzawa) drives it to Uzawa tolerance on the same "
                      "factorisation.");
    prm.declare_entry("Penalty scale",
                      "10",
                      Patterns::Double(0.01, 1e8),
                      "alpha [-], 0.01 .. 1e8 (0 would switch the contact "
                      "off; 1e8 is measured to work on the thin-disk fit; beyond it the "
                      "penalty springs outweigh the elastic stiffness by more "
                      "than half of double precision's digits): each pair's "
                      "penalty is alpha times the mean "
                      "radial diagonal stiffness of its two nodes. 10..100 for "
                      "the augmented Lagrangian, 1e3..1e4 for pure penalty.");
    prm.declare_entry("Maximum active set iterations",
                      "30",
                      Patterns::Integer(1),
                      "Cap on active-set updates per speed.");
    prm.declare_entry("Maximum Uzawa iterations",
                      "100",
                      Patterns::Integer(1),
                      "Cap on multiplier updates per active set and load case "
                      "(augmented Lagrangian only).");
    prm.declare_entry("Uzawa tolerance",
                      "1e-8",
                      patterns::Positive(),
                      "Uzawa stops when max |gap| of the closed pairs is below "
                      "this times the interference [-].");
    prm.declare_entry("Low-rank update limit",
                      "0.25",
                      Patterns::Double(0., 1.),
                      "A changed active set is solved on the last "
                      "factorisation by a low-rank (Woodbury) update while the "
                      "changed pairs whose influence column is not known yet "
                      "are at most this fraction of all pairs; above it the "
                      "matrix is factorised again [-]. 0: factorise every "
                      "active set.");
    prm.declare_entry("Speed path",
                      "exact",
                      Patterns::Selection("exact|sampled"),
                      "'exact': the contact state follows the speed from event "
                      "to event (each pair's opening or closing speed solved from "
                      "its active set's affine law in Omega^2), so opening speeds "
                      "do not depend on the speed step; every influence column "
                      "is computed once and the factorisation is kept for the "
                      "run (memory: 2 n^2 doubles for n pairs). 'sampled': the "
                      "active set is settled at each requested speed only. With "
                      "Physics/Spin softening the law is not affine and the "
                      "path is sampled.");
    prm.declare_entry("Constraint error limit",
                      "0.01",
                      patterns::Positive(),
                      "Pure penalty: a speed whose constraint error max |gap| / "
                      "interference of the closed pairs exceeds this is flagged "
                      "converged = 0 [-] (the augmented Lagrangian uses 10 x "
                      "Uzawa tolerance).");
    prm.leave_subsection();
  }

  void
  ContactParameters::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Contact");
    method = (prm.get("Method") == "penalty" ? Method::penalty : Method::augmented_lagrangian);
    penalty_scale             = prm.get_double("Penalty scale");
    max_active_set_iterations = prm.get_integer("Maximum active set iterations");
    max_uzawa_iterations      = prm.get_integer("Maximum Uzawa iterations");
    uzawa_tolerance           = prm.get_double("Uzawa tolerance");
    update_limit              = prm.get_double("Low-rank update limit");
    penalty_error_limit       = prm.get_double("Constraint error limit");
    path = prm.get("Speed path") == "exact" ? Path::exact : Path::sampled;
    prm.leave_subsection();
  }
} // namespace rotorfit
