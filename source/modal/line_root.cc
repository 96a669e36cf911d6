#include <rotorfit/base/input_error.h>
#include <rotorfit/modal/line_root.h>
#include <rotorfit/modal/mode_tracker.h>

#include <cmath>

namespace rotorfit
{
  LineRoot
  solve_line_root(const WhirlMode                                           &line,
                  double                                                     a,
                  double                                                     ga,
                  double                                                     b,
                  double                                                     gb,
                  const std::function<double(std::complex<double>, double)> &g,
                  const double                                               g_tolerance,
                  const StaticState                                         &state,
                  PrestressedEigenproblem                                   &eigen,
                  Log                                                       &log,
                  const std::string                                         &what)
  {
    LineRoot root;
    root.rpm    = b;
    root.lambda = line.lambda;
    int side    = 0; // Illinois: halve the weight of an end kept twice
    for (root.evaluations = 0; root.evaluations < 40; ++root.evaluations)
      {
        if (std::abs(b - a) <= 1e-6 * std::abs(b) || gb == 0)
          {
            root.converged = true;
            break;
          }
        const double c     = (a * gb - b * ga) / (gb - ga);
        StaticState  trial = state;
        trial.rpm          = c;
        EigenSolution s;
        try
          {
            s = eigen.solve(trial);
          }
        catch (const SolverFailure &e)
          {
            log << "Warning: " << what << ": the eigensolver failed at " << c << " r/min ("
                << e.what() << "); the bracket is kept.\n";
            break;
          }
        double               best = -1;
        std::complex<double> lambda;
        for (const auto &p : s.elastic)
          {
            const double mac = ModeTracker::mac(line.phi, line.m_phi, p.phi, p.m_phi);
            if (mac > best)
              best = mac, lambda = p.lambda;
          }
        const double gc = g(lambda, c);
        root.rpm        = c;
        root.lambda     = lambda;
        if (std::abs(gc) <= g_tolerance)
          {
            root.converged = true;
            ++root.evaluations;
            break;
          }
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
    return root;
  }
} // namespace rotorfit
