#pragma once

#include <rotorfit/modal/modal_analysis.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/numerics/data_out.h>

#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * The ParaView files: per speed one solution_*.pvtu (displacement, von
   * Mises stress, body, contact status, pressure and gap) indexed by
   * solution.pvd, and one modes_*.pvtu (real and imaginary parts of every
   * elastic mode, the tied pairs) indexed by modes.pvd.
   */
  class ParaViewOutput
  {
  public:
    ParaViewOutput(const Discretization &model, const std::string &directory);

    void
    write_static(const StaticState &state);

    void
    write_modes(const ModalResult &modes);

  private:
    /// Write @p data_out as speed @p index of @p series (solution, modes).
    void
    write(const dealii::DataOut<3>                     &data_out,
          const std::string                            &series,
          const unsigned int                            index,
          const double                                  rpm,
          std::vector<std::pair<double, std::string>> &records) const;

    const Discretization                       &model;
    std::string                                 directory;
    std::vector<std::pair<double, std::string>> static_records, mode_records;
  };
} // namespace rotorfit
