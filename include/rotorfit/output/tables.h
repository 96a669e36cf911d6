#pragma once

#include <rotorfit/harmonic/harmonic_mode.h>

#include <rotorfit/modal/modal_analysis.h>
#include <rotorfit/modal/stability_onset.h>
#include <rotorfit/response/unbalance_response.h>
#include <rotorfit/statics/static_state.h>

#include <fstream>
#include <string>

namespace rotorfit
{
  /// @p text as a CSV field (RFC 4180): in double quotes, its quotes
  /// doubled, where it holds a comma, a quote or a line break (a status
  /// "... 0 pairs flipped back, at ... r/min" split its row); else as is.
  std::string
  csv_field(const std::string &text);

  /**
   * The result tables, one class per file. Each opens its file with the
   * header (units in the column names) and appends the rows of a speed as
   * soon as it is done, flushed: a run that stops keeps every finished
   * speed. Only the MPI rank that opened them (rank 0) writes.
   */
  class CsvTable
  {
  protected:
    /// Create @p path with its @p header line; numbers get @p digits digits.
    void
    create(const std::string &path, const char *header, const int digits);

    std::ofstream file;
  };

  /// campbell.csv of the harmonic model: one row per speed, harmonic and mode.
  class HarmonicCampbellTable : CsvTable
  {
  public:
    void
    open(const std::string &directory);
    void
    add(const StaticState &state, const std::vector<HarmonicMode> &modes);
  };

  /// contact.csv: one row per speed and interface.
  class ContactTable : CsvTable
  {
  public:
    void
    open(const std::string &directory);
    void
    add(const StaticState &state);

  };

  /// pair_openings.csv: every pair that opened, with its opening speed.
  class PairOpeningTable : CsvTable
  {
  public:
    void
    open(const std::string &directory);
    void
    add(const StaticState &state);

  };

  /// contact_events.csv: every change of a pair on the exact path.
  class ContactEventTable : CsvTable
  {
  public:
    void
    open(const std::string &directory);
    void
    add(const StaticState &state);
  };

  /// fit.csv: the fit designer's numbers, one row per speed and interface.
  class FitTable : CsvTable
  {
  public:
    void
    open(const std::string &directory);
    void
    add(const StaticState &state);
  };

  /// body_stress.csv: the largest von Mises stress of each body per speed.
  class BodyStressTable : CsvTable
  {
  public:
    void
    open(const std::string &directory);
    void
    add(const StaticState &state);
  };

  /// campbell.csv: one row per speed and elastic mode.
  class CampbellTable : CsvTable
  {
  public:
    void
    open(const std::string &directory);
    void
    add(const StaticState &state, const ModalResult &modes);

  };

  /// critical_speeds.csv: the crossings of the lines with k X.
  class CriticalSpeedTable : CsvTable
  {
  public:
    void
    /// @p harmonic_columns: the axisymmetric model's columns harmonic, travel
    open(const std::string &directory, const bool harmonic_columns = false);
    void
    add(const ModalResult &modes);


  private:
    bool harmonic_columns = false;
  };

  /// rigid_modes.csv: rigid-body, loose-body and overdamped eigenvalues.
  class RigidModeTable : CsvTable
  {
  public:
    /// @p harmonic_column: the axisymmetric model's column harmonic
    void
    open(const std::string &directory, const bool harmonic_column = false);
    void
    add(const ModalResult &modes);

  private:
    bool harmonic_column = false;
  };

  /// stability_onsets.csv: speeds where a line's damping ratio crosses zero.
  class StabilityOnsetTable : CsvTable
  {
  public:
    void
    /// @p harmonic_columns: the axisymmetric model's columns harmonic, travel
    open(const std::string &directory, const bool harmonic_columns = false);
    void
    add(const std::vector<StabilityOnset> &onsets);

  private:
    bool harmonic_columns = false;
  };

  /// response.csv: one row per speed and probe of the unbalance response.
  class ResponseTable : CsvTable
  {
  public:
    void
    open(const std::string &directory);
    void
    add(const ResponseAtSpeed &response);
  };

  /// response_peaks.csv: the resonance peaks, written once at the end.
  void
  write_response_peaks(const std::string &directory, const std::vector<ResponsePeak> &peaks);
} // namespace rotorfit
