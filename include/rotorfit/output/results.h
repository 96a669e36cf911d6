#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/contact/contact_solver.h>
#include <rotorfit/modal/modal_analysis.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/output/paraview_output.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/output/tables.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/parameter_handler.h>

#include <memory>
#include <string>

namespace rotorfit
{
  /**
   * The output folder of a run and everything written into it: the tables
   * (one writer per file, each speed appended as soon as it is done), the
   * ParaView files, summary.txt (once, at the end) and campbell.png.
   *
   * Parameters: subsection "Output"; "Write mode shapes" and "Campbell
   * plot" of subsection "Eigenproblem".
   */
  class Results
  {
  public:
    Results(const MPI_Comm comm, Log &log);

    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// @p directory_override (the command line's --output) wins if not empty.
    void
    parse_parameters(dealii::ParameterHandler &prm, const std::string &directory_override);

    const std::string &
    directory() const
    {
      return output_dir;
    }

    /// Refuse a folder that cannot be created or written (no side effect).
    void
    check_writable() const;

    /// Create and lock the folder, remove an earlier run's results, write
    /// the effective parameters and start log.txt. Rank 0 acts, every rank
    /// learns the outcome (InputError).
    void
    prepare_directory(const dealii::ParameterHandler &prm);

    /// Continue log.txt (after refinement cycles wrote theirs).
    void
    reopen_log()
    {
      log.open_file(output_dir + "/log.txt", true);
    }

    /// What a run writes besides its contact tables.
    struct Contents
    {
      bool modes    = false; ///< the eigenproblem is solved (Eigenproblem/Compute modes)
      bool response = false; ///< an unbalance response is solved (Unbalances)
      /// exact: the contact events are written (contact_events.csv)
      ContactSolver::Path speed_path = ContactSolver::Path::sampled;
    };

    /// Open the tables: before the first speed.
    void
    open(const Discretization &model, const Contents &contents);

    /// A speed's static state: contact.csv, pair_openings.csv,
    /// contact_events.csv and the ParaView solution.
    void
    write_static_state(const StaticState &state);

    /// The modes of @p state's speed: campbell.csv, critical_speeds.csv,
    /// rigid_modes.csv and the ParaView mode shapes.
    void
    write_modes(const StaticState &state, const ModalResult &modes);

    /// Refuse Output/ParaView speeds that are not speeds of the run.
    void
    check_speeds(const std::vector<double> &run_speeds);

    /// The critical speeds get mode shapes (an eigen solve each).
    bool
    shapes_at_critical_speeds() const
    {
      return at_critical && (write_shapes || write_paraview);
    }

    /// The ParaView files of a critical speed: its static state and modes.
    void
    write_critical_shapes(const StaticState &state, const ModalResult &modes);

    /// Stability onsets found since the previous speed: stability_onsets.csv.
    void
    write_stability_onsets(const std::vector<StabilityOnset> &found)
    {
      stability.add(found);
    }

    /// The unbalance response of a speed: response.csv.
    void
    write_response(const ResponseAtSpeed &response)
    {
      responses.add(response);
    }

    /// The response peaks: response_peaks.csv, before finish().
    void
    write_response_peaks(const std::vector<ResponsePeak> &peaks);

    /// A run on the axisymmetric model writes its own tables: the contact
    /// picture is drawn of them (@p contact: the run has interfaces), the
    /// response pictures where it has unbalances (@p response), the fit
    /// picture not (no fit.csv).
    void
    draw_harmonic_tables(const bool contact, const bool response)
    {
      with_contact  = contact;
      with_fit      = contact;
      with_response = response;
    }

    /// Write summary.txt, then draw the pictures (which read it).
    void
    finish(const Summary &summary, const bool with_modes);

  private:
    /// summary.txt: one "key value" line per entry.
    void
    write_summary(const Summary &summary) const;

    /// The pictures of the tables written, with Output/Pictures.
    void
    draw_pictures(const bool with_modes);

    /// ParaView files at the @p index-th speed of the run, @p rpm.
    bool
    paraview_at(const unsigned int index, const double rpm) const;

  public:
    /// Whether the @p index-th speed, @p rpm, gets the ParaView solution and
    /// mode shapes (the harmonic model, which writes its own files).
    std::pair<bool, bool>
    paraview_files(const unsigned int index, const double rpm) const
    {
      const bool at = paraview_at(index, rpm);
      return {write_paraview && at, write_shapes && at};
    }
    /// The same at the critical speeds.
    std::pair<bool, bool>
    critical_files() const
    {
      return {write_paraview && at_critical, write_shapes && at_critical};
    }

  private:

    MPI_Comm    comm;
    Log        &log;
    bool        root;
    std::string output_dir;
    bool        prepared       = false;
    bool        write_paraview = true;
    bool        write_shapes   = true;
    bool        plot           = true;
    bool        pictures       = true;
    double      campbell_fmax  = 0;
    bool        at_all = false, at_ends = true, at_critical = true;
    std::vector<double> paraview_speeds; ///< listed speeds [r/min]
    unsigned int        last_index       = 0;
    unsigned int        n_critical_files = 0;

    ContactTable                    contact;
    PairOpeningTable                openings;
    ContactEventTable               events;
    FitTable                        fit;
    BodyStressTable                 body_stress;
    CampbellTable                   campbell;
    CriticalSpeedTable              critical;
    RigidModeTable                  rigid;
    ResponseTable                   responses;
    StabilityOnsetTable             stability;
    bool                            with_response = false;
    bool                            with_contact  = false;
    bool                            with_fit      = false; ///< fit.csv is written
    std::unique_ptr<ParaViewOutput> paraview;
  };
} // namespace rotorfit
