#pragma once

#include <rotorfit/modal/modal_analysis.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/numerics/data_out.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * The ParaView files (zlib-compressed .vtu): per chosen speed one
   * solution_*.pvtu (displacement, von Mises, radial, hoop and axial stress, body, contact status,
   * pressure and gap on the curved cells) indexed by solution.pvd, and one
   * modes_*.pvtu (real and imaginary parts of every elastic mode, the tied
   * pairs; on the cells' vertices, a third of the size) indexed by
   * modes.pvd. The critical speeds get their own series,
   * critical_solution / critical_modes.
   */
  class ParaViewOutput
  {
  public:
    ParaViewOutput(const Discretization &model, const std::string &directory);

    /// @p series: "solution" or "critical_solution"; @p index: the file's number in it.
    void
    write_static(const StaticState &state, const std::string &series, const unsigned int index);

    /// @p series: "modes" or "critical_modes".
    void
    write_modes(const ModalResult &modes, const std::string &series, const unsigned int index);

  private:
    /// Write @p data_out as speed @p index of @p series (solution, modes).
    void
    write(dealii::DataOut<3>                           &data_out,
          const std::string                            &series,
          const unsigned int                            index,
          const double                                  rpm,
          std::vector<std::pair<double, std::string>> &records) const;

    const Discretization                       &model;
    std::string                                 directory;
    std::map<std::string, std::vector<std::pair<double, std::string>>> records;
  };
} // namespace rotorfit
