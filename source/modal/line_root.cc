#include <rotorfit/base/input_error.h>
#include <rotorfit/modal/line_root.h>
#include <rotorfit/modal/mode_tracker.h>

#include <cmath>
#include <iomanip>

namespace rotorfit
{
  namespace
  {
    /// The eigenvalue of the mode of @p s most like @p line (mass MAC).
    std::complex<double>
    line_lambda(const WhirlMode &line, const EigenSolution &s)
    {
      double               best = -1;
      std::complex<double> lambda;
      for (const auto &p : s.elastic)
        {
          const double mac = ModeTracker::mac(line.phi, line.m_phi, p.phi, p.m_phi);
          if (mac > best)
            best = mac, lambda = p.lambda;
        }
      return lambda;
    }

    /// Illinois regula falsi on [a, b]: the next trial speed and, once a
    /// trial's value is known, the bracket kept.
    struct Bracket
    {
      double a, ga, b, gb;
      int    side = 0; // halve the weight of an end kept twice

      bool
      closed() const
      {
        return std::abs(b - a) <= 1e-6 * std::abs(b) || gb == 0;
      }
      double
      trial() const
      {
        return (a * gb - b * ga) / (gb - ga);
      }
      void
      keep(const double c, const double gc)
      {
        if ((gc > 0) == (gb > 0))
          {
            b = c, gb = gc;
            if (side == -1)
              ga /= 2;
            side = -1;
          }
        else
          {
            a = c, ga = gc;
            if (side == 1)
              gb /= 2;
            side = 1;
          }
      }
    };
  } // namespace

  LineRoot
  solve_line_root(const WhirlMode                                           &line,
                  const double                                               a,
                  const double                                               ga,
                  const double                                               b,
                  const double                                               gb,
                  const std::function<double(std::complex<double>, double)> &g,
                  const double                                               g_tolerance,
                  const StaticState                                         &state,
                  SpeedEigenproblem                             &eigen,
                  Log                                                       &log,
                  const std::string                                         &what)
  {
    LineRoot root;
    root.rpm    = b;
    root.lambda = line.lambda;

    // 1. The root of the line on the reduced model without its full-space
    //    checks (the projected problem alone: a fraction of a checked solve)
    double guess = std::nan("");
    for (Bracket k{a, ga, b, gb}; root.trials < 40 && !k.closed(); ++root.trials)
      {
        StaticState trial = state;
        trial.rpm         = k.trial();
        EigenSolution s;
        if (!eigen.solve_trial(trial, s))
          break;
        const double gc = g(line_lambda(line, s), trial.rpm);
        if (!std::isfinite(gc))
          break; // the checked stage decides from the last good trial
        guess = trial.rpm;
        if (std::abs(gc) <= g_tolerance)
          {
            ++root.trials;
            break;
          }
        k.keep(trial.rpm, gc);
      }

    // 2. Checked solves, the first at that root: where it holds there, one
    //    solve; otherwise regula falsi goes on from the bracket it leaves
    Bracket k{a, ga, b, gb};
    for (root.evaluations = 0; root.evaluations < 40; ++root.evaluations)
      {
        const bool at_guess = root.evaluations == 0 && guess > std::min(a, b) &&
                              guess < std::max(a, b);
        if (!at_guess && k.closed())
          {
            root.converged = true;
            break;
          }
        StaticState trial = state;
        trial.rpm         = at_guess ? guess : k.trial();
        try
          {
            root.solution = eigen.solve(trial);
          }
        catch (const SolverFailure &e)
          {
            log << "Warning: " << what << ": the eigensolver failed at " << trial.rpm
                << " r/min (" << e.what() << "); the bracket is kept.\n";
            root.solution = EigenSolution();
            break;
          }
        const std::complex<double> lambda = line_lambda(line, root.solution);
        const double               gc     = g(lambda, trial.rpm);
        root.rpm                          = trial.rpm;
        root.lambda                       = lambda;
        if (std::abs(gc) <= g_tolerance)
          {
            root.converged = true;
            ++root.evaluations;
            break;
          }
        k.keep(trial.rpm, gc);
      }
    return root;
  }

  LineRoot
  solve_crossing(CriticalSpeed     &c,
                 const WhirlMode   &line,
                 const StaticState &state,
                 SpeedEigenproblem &eigen,
                 Log               &log)
  {
    const unsigned int k = c.order;
    LineRoot           root =
      solve_line_root(line, c.from_rpm, c.from_value, c.to_rpm, c.to_value,
                      [k](const std::complex<double> l, const double rpm) {
                        return l.imag() / (2 * M_PI) - k * rpm / 60.;
                      },
                      1e-9 * std::abs(c.frequency_hz), state, eigen, log,
                      "critical speed of line " + std::to_string(c.tracked_id));
    c.eigen_solves = root.evaluations;
    c.solved       = root.converged;
    if (root.evaluations > 0)
      {
        c.rpm           = root.rpm;
        c.frequency_hz  = root.lambda.imag() / (2 * M_PI);
        c.damping_ratio = -root.lambda.real() / std::abs(root.lambda);
      }
    log << "  critical speed: line " << c.tracked_id << " (" << c.whirl << ") meets " << k
        << "X at " << std::setprecision(8) << c.rpm << " r/min, " << c.frequency_hz
        << " Hz, damping ratio " << std::setprecision(4) << c.damping_ratio << " ("
        << root.evaluations << " eigen solves, " << root.trials << " unchecked trials"
        << (c.solved ? "" : "; NOT converged, the last trial is kept") << ")\n"
        << std::setprecision(6);
    return root;
  }
} // namespace rotorfit
