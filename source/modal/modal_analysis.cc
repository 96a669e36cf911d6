#include <rotorfit/base/input_error.h>
#include <rotorfit/modal/line_root.h>
#include <rotorfit/modal/modal_analysis.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <deal.II/base/utilities.h>

namespace rotorfit
{
  using namespace dealii;

  void
  ModalAnalysis::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Eigenproblem");
    prm.declare_entry("Whirl stations",
                      "10",
                      Patterns::Integer(1),
                      "Axial slices whose mass-averaged lateral motion decides "
                      "forward / backward whirl.");
    prm.declare_entry("MAC threshold",
                      "0.8",
                      Patterns::Double(0., 1.),
                      "Least mass-weighted MAC for a mode to continue a line "
                      "of the previous speed.");
    prm.declare_entry("Excitation orders",
                      "1",
                      Patterns::List(Patterns::Integer(1)),
                      "Orders k of the k X lines whose crossings are critical "
                      "speeds.");
    prm.leave_subsection();
  }

  void
  ModalAnalysis::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Eigenproblem");
    n_stations    = prm.get_integer("Whirl stations");
    tracker = ModeTracker::from_parameters(prm);
    prm.leave_subsection();
  }

  void
  ModalAnalysis::setup(const Discretization &model)
  {
    stations.build(model, n_stations);
    linear_elements = model.element_order() == 1;
  }

  ModalResult
  ModalAnalysis::classify(EigenSolution &&solution) const
  {
    ModalResult r;
    r.rpm   = solution.rpm;
    r.index = solution.index;
    r.rigid = std::move(solution.rigid);
    r.tied  = std::move(solution.tied);
    r.isotropic_supports = solution.isotropic_supports;
    for (auto &pair : solution.elastic)
      r.modes.emplace_back(std::move(pair));
    stations.separate_degenerate_pairs(r.modes);
    for (auto &m : r.modes)
      stations.classify(m);
    return r;
  }

  const ModalResult &
  ModalAnalysis::analyse(EigenSolution &&solution)
  {
    for (const auto &p : solution.elastic)
      sweep_worst_estimate = std::max(sweep_worst_estimate, p.error_estimate);
    result = classify(std::move(solution));
    check_doublets();
    result.crossings = tracker.track(result.rpm, result.modes);
    n_critical += result.crossings.size();
    return result;
  }

  void
  ModalAnalysis::solve_crossings(const StaticState                                         &state,
                                 SpeedEigenproblem                             &eigen,
                                 const std::function<void(unsigned int, EigenSolution &&)> &solved)
  {
    for (unsigned int i = 0; i < result.crossings.size(); ++i)
      {
        auto      &c    = result.crossings[i];
        const auto line = std::find_if(result.modes.begin(), result.modes.end(),
                                       [&](const WhirlMode &m) { return m.tracked_id == c.tracked_id; });
        if (line == result.modes.end())
          {
            if (solved) // (its shapes are solved at its interpolated speed)
              solved(i, EigenSolution());
            continue;
          }
        LineRoot root = solve_crossing(c, *line, state, eigen, log);
        if (!c.solved)
          ++n_unsolved;
        if (solved)
          solved(i, !root.solution.elastic.empty() && root.solution.rpm == c.rpm ?
                      std::move(root.solution) :
                      EigenSolution());
      }
  }

  void
  ModalAnalysis::check_doublets() const
  {
    // At rest on isotropic bearings an axisymmetric rotor's lateral modes
    // are doublets. A lateral mode without its partner below the highest
    // one reported means the eigensolver missed an eigenvalue (a far shift,
    // too small a Krylov space): the Campbell diagram would lack a line.
    if (result.rpm != 0 || !result.isotropic_supports)
      return;
    std::vector<double> f;
    for (const auto &m : result.modes)
      if (m.whirl != "non-lateral")
        f.push_back(std::abs(m.lambda.imag()) / (2 * M_PI));
    std::sort(f.begin(), f.end());
    std::ostringstream lone;
    for (unsigned int i = 0; i < f.size();)
      if (i + 1 < f.size() && f[i + 1] - f[i] <= 1e-2 * f[i])
        i += 2;
      else
        {
          if (i + 1 < f.size()) // the highest may have its partner beyond the modes asked
            lone << (lone.str().empty() ? "" : ", ") << f[i];
          ++i;
        }
    if (!lone.str().empty())
      throw SolverFailure(0,
                          "at 0 r/min the lateral mode(s) at " + lone.str() +
                            " Hz came without the second member of their doublet (equal "
                            "frequency within 1 %): the eigensolver missed eigenvalues. Keep "
                            "Eigenproblem/Shift below the lowest frequency of interest, or raise "
                            "Krylov size factor" +
                            std::string(linear_elements ?
                                          "; with Geometry/Element order = 1 the locking of "
                                          "the linear elements can also split a doublet by more "
                                          "than 1 %: use order 2" :
                                          ""));
  }

  void
  ModalAnalysis::finish(Summary &summary) const
  {
    summary.add("eigen.critical_speeds", n_critical);
    summary.add("eigen.critical_speeds_unsolved", n_unsolved);
    summary.add("eigen.sweep_worst_error_estimate", sweep_worst_estimate, 12);
    log << "Critical speeds: " << n_critical << " crossing(s) in critical_speeds.csv\n";
  }
} // namespace rotorfit
