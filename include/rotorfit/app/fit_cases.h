#pragma once

#include <rotorfit/base/summary.h>

#include <deal.II/base/mpi.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  class Discretization;

  /**
   * The cases a fit study runs in one invocation: each end of a toleranced
   * fit's interference band (Fit design/Interference cases) times each
   * temperature case (the bodies' Temperature lists). One case is one full
   * run, into its own subfolder of the output folder; the case is carried
   * by two overrides of its parameters (Fit design/Interference cases,
   * Fit design/Temperature case), so its parameters.prm reruns it alone.
   * After the last case the study's folder gets fit_cases.csv (one row per
   * case) and summary.txt, which names the governing case of each check:
   * the least slip speed, loss of fit and slip safety, the largest stress
   * and the least safety against yield.
   */
  class FitCases
  {
  public:
    /// One case: its folder name and the overrides that make it.
    struct Case
    {
      std::string                                      name;
      std::vector<std::pair<std::string, std::string>> sets;
    };

    /// The cases of @p model's parsed bodies and interfaces (one case: no study).
    explicit FitCases(const Discretization &model);

    const std::vector<Case> &
    list() const
    {
      return cases;
    }

    /// Record how case @p k ended: its exit code and status, and its
    /// summary.txt's keys (read from @p directory).
    void
    record(const unsigned int k, const int exit_code, const std::string &directory);

    /// A case that was refused because its fit is loose at rest.
    void
    record_loose(const unsigned int k, const std::string &message);

    /// fit_cases.csv and summary.txt in @p directory (rank 0 writes);
    /// returns the study's exit code (the first failing case's).
    int
    finish(const std::string &directory, const MPI_Comm comm) const;

  private:
    struct Outcome
    {
      int                                code = -1; ///< -1: not run
      std::string                        status, message;
      std::map<std::string, std::string> keys;
    };
    std::vector<Case>        cases;
    std::vector<Outcome>     outcomes;
    std::vector<std::string> interfaces, bodies;
  };
} // namespace rotorfit
