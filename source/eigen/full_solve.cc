#include <rotorfit/base/input_error.h>
#include <rotorfit/eigen/full_solve.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// Set-apart modes counted as state-space eigenvalues: a rigid motion is
    /// a double zero that round-off splits into a tiny conjugate pair (one
    /// row) or two tiny real values (two rows).
    void
    count_set_apart(const EigenSolution &solution,
                    unsigned int        &n_rigid,
                    unsigned int        &n_loose,
                    unsigned int        &n_overdamped)
    {
      n_rigid = n_loose = n_overdamped = 0;
      for (const auto &r : solution.rigid)
        (r.kind == "loose" ? n_loose : r.kind == "rigid" ? n_rigid : n_overdamped) +=
          (r.lambda.imag() != 0 ? 2 : 1);
    }
  } // namespace

  FullSolve::FullSolve(const Discretization &model,
                       SpeedTangent         &operators,
                       DampedEigensolver    &eigensolver,
                       const ModeClassifier &classifier,
                       Log                  &log,
                       TimerOutput          &timer)
    : model(model)
    , operators(operators)
    , eigensolver(eigensolver)
    , classifier(classifier)
    , log(log)
    , timer(timer)
  {}

  double
  FullSolve::solve(const StaticState       &state,
                   const std::vector<bool> &loose_body,
                   unsigned int             nev,
                   UndampedAnchor          *anchor,
                   const bool               lasting,
                   EigenSolution           &solution)
  {
    const unsigned int            n_wanted    = classifier.n_wanted;
    unsigned int                  unconverged = 0;
    double                        worst       = 0;
    DampedEigensolver::Statistics stats;
    for (unsigned int attempt = 0;; ++attempt)
      {
        std::vector<EigenPair> pairs;
        {
          TimerOutput::Scope t(timer, "eigen: factorisation + ARPACK");
          pairs = eigensolver.solve(operators.mass(), operators.damping(), operators.stiffness(),
                                    nev, stats, attempt);
        }
        TimerOutput::Scope t(timer, "eigen: post-processing + output");
        unconverged = stats.unconverged_slots;
        std::vector<EigenPair> kept;
        if (anchor)
          kept = pairs; // sort_eigenpairs moves the vectors away
        if (classifier.sort_eigenpairs(pairs, loose_body, solution, unconverged, worst))
          {
            if (anchor)
              anchor->add_damped(state.rpm, kept, lasting);
            break;
          }
        const std::string  m = describe_failure(state, solution, stats, unconverged, worst);
        const unsigned int more =
          2 * (n_wanted - std::min<unsigned int>(n_wanted, solution.elastic.size()));
        if (attempt == 0 && nev + more + 3 <= 2 * model.dofs().n_dofs())
          {
            nev += more;
            ++retried_speeds;
            log << "  eigen: retry " << m << "; again with twice the Krylov space\n";
            continue;
          }
        throw SolverFailure(state.rpm,
                            "the eigensolver did not converge " + m +
                              (attempt > 0 ? " (after one retry with twice the Krylov space)" :
                                             " (no retry: the model has too few DOFs for more "
                                             "eigenvalues)") +
                              "; raise Eigenproblem/Maximum restarts or Krylov size factor, or "
                              "move the Shift");
      }
    ++solves;
    log_speed(solution, stats, worst);
    return worst;
  }

  std::string
  FullSolve::describe_failure(const StaticState                   &state,
                              const EigenSolution                 &solution,
                              const DampedEigensolver::Statistics &stats,
                              const unsigned int                   unconverged,
                              const double                         worst) const
  {
    unsigned int n_rigid, n_loose, n_overdamped;
    count_set_apart(solution, n_rigid, n_loose, n_overdamped);
    std::ostringstream m;
    m << "at " << state.rpm << " r/min: " << solution.elastic.size()
      << " elastic modes converged (" << classifier.n_wanted << " wanted; "
      << stats.unconverged_slots << " ARPACK slots unconverged, "
      << unconverged - stats.unconverged_slots
      << " eigenpairs with a backward error above Eigenproblem/Backward error limit = "
      << eigensolver.backward_error_limit() << ", worst " << std::setprecision(3) << worst
      << "; " << n_rigid << " rigid, " << n_loose << " loose-body, " << n_overdamped
      << " overdamped) with " << stats.requested << " eigenvalues, Krylov size "
      << stats.krylov_size << ", at most " << stats.max_restarts << " restarts";
    return m.str();
  }

  void
  FullSolve::log_speed(const EigenSolution                 &solution,
                       const DampedEigensolver::Statistics &stats,
                       const double                         worst) const
  {
    unsigned int n_rigid, n_loose, n_overdamped;
    count_set_apart(solution, n_rigid, n_loose, n_overdamped);
    const auto        &elastic = solution.elastic;
    const std::size_t  shown   = std::min<std::size_t>(classifier.n_wanted, elastic.size());
    std::ostringstream line;
    line << "  eigen: " << shown << " whirl modes";
    if (shown > 0)
      line << " " << std::setprecision(5) << elastic.front().lambda.imag() / (2 * M_PI)
           << " .. " << elastic[shown - 1].lambda.imag() / (2 * M_PI) << " Hz";
    if (elastic.size() > shown)
      line << " (+ " << elastic.size() - shown << " up to " << std::setprecision(5)
           << elastic.back().lambda.imag() / (2 * M_PI) << " Hz for the reduced basis)";
    line << ", " << n_rigid << " rigid, " << n_loose << " loose-body, " << n_overdamped
         << " overdamped (state-space eigenvalues); nev " << stats.requested << ", Krylov "
         << stats.krylov_size << ", " << stats.iterations << " restarts, "
         << stats.operator_applications << " solves, max backward error "
         << std::setprecision(2) << worst << "; " << std::setprecision(3)
         << stats.factorization_seconds << " s LU, " << stats.arnoldi_seconds
         << " s Arnoldi (" << stats.solve_seconds << " s back-substitutions), "
         << stats.check_seconds << " s checks\n";
    log << line.str();
  }
} // namespace rotorfit
