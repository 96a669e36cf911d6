#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/run_control.h>
#include <rotorfit/output/results.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace rotorfit
{
  using namespace dealii;

  Results::Results(const MPI_Comm comm, Log &log)
    : comm(comm)
    , log(log)
    , root(Utilities::MPI::this_mpi_process(comm) == 0)
  {}

  void
  Results::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Output");
    prm.declare_entry("Directory",
                      "output",
                      Patterns::DirectoryName(),
                      "Where results go (created if missing; relative to the "
                      "working directory). The command line's --output DIR wins.");
    prm.declare_entry("Write ParaView files",
                      "true",
                      Patterns::Bool(),
                      "One .pvtu per speed (displacement, von Mises stress, "
                      "body, contact status, pressure and gap) and a .pvd "
                      "index.");
    prm.declare_entry("Pictures",
                      "true",
                      Patterns::Bool(),
                      "Draw the pictures at the end of the run (python3 + "
                      "matplotlib): contact.png, and with modes campbell.png, "
                      "with unbalances response_bode.png and response_polar.png.");
    prm.declare_entry("Campbell frequency range",
                      "0",
                      Patterns::Double(0),
                      "Top of campbell.png's frequency axis [Hz] (0: 1.15 x the "
                      "highest excitation line at the top speed, at least 1.1 x "
                      "the lowest mode).");
    prm.leave_subsection();
    prm.enter_subsection("Eigenproblem");
    prm.declare_entry("Write mode shapes",
                      "true",
                      Patterns::Bool(),
                      "One .pvtu per speed with every elastic mode (real and "
                      "imaginary parts) and the tied pairs, indexed by modes.pvd.");
    prm.declare_entry("Campbell plot",
                      "true",
                      Patterns::Bool(),
                      "Draw campbell.png at the end of the run (with "
                      "Output/Pictures).");
    prm.leave_subsection();
  }

  void
  Results::parse_parameters(ParameterHandler &prm, const std::string &directory_override)
  {
    prm.enter_subsection("Output");
    // the command line wins, and parameters.prm records what was used
    if (!directory_override.empty())
      prm.set("Directory", directory_override);
    output_dir     = prm.get("Directory");
    write_paraview = prm.get_bool("Write ParaView files");
    pictures       = prm.get_bool("Pictures");
    campbell_fmax  = prm.get_double("Campbell frequency range");
    prm.leave_subsection();
    prm.enter_subsection("Eigenproblem");
    write_shapes = prm.get_bool("Write mode shapes");
    plot         = prm.get_bool("Campbell plot");
    prm.leave_subsection();
    if (output_dir.empty())
      throw InputError("Output/Directory is empty; give a directory name.");
  }

  void
  Results::check_writable() const
  {
    std::string error;
    if (root)
      error = run_control::check_writable(output_dir);
    error = Utilities::MPI::broadcast(comm, error, 0);
    if (!error.empty())
      throw InputError(error);
  }

  void
  Results::prepare_directory(const ParameterHandler &prm)
  {
    std::string error;
    if (root)
      try
        {
          std::error_code ec;
          std::filesystem::create_directories(output_dir, ec);
          if (ec)
            throw InputError("Output/Directory = '" + output_dir +
                             "' cannot be created: " + ec.message() + ".");
          run_control::lock_output_directory(output_dir);
          // results of an earlier run into this folder must not be
          // mistaken for this run's
          for (const char *f : {"summary.txt", "contact.csv", "pair_openings.csv",
                                "campbell.csv", "critical_speeds.csv", "rigid_modes.csv",
                                "campbell.png", "plot.log", "response.csv",
                                "response_peaks.csv", "stability_onsets.csv", "contact.png",
                                "response_bode.png", "response_polar.png"})
            std::filesystem::remove(output_dir + "/" + f, ec);
          std::ofstream out(output_dir + "/parameters.prm");
          prm.print_parameters(out, ParameterHandler::ShortPRM);
          if (!out)
            throw InputError("Output/Directory = '" + output_dir +
                             "': files cannot be written there.");
        }
      catch (const InputError &e)
        {
          error = e.what();
        }
    error = Utilities::MPI::broadcast(comm, error, 0);
    if (!error.empty())
      throw InputError(error);
    prepared = true;
    log.open_file(output_dir + "/log.txt");
  }

  void
  Results::open(const Discretization &model, const bool with_modes, const bool response)
  {
    with_response = response;
    with_contact  = !model.interfaces().list().empty();
    if (write_paraview || (with_modes && write_shapes))
      paraview = std::make_unique<ParaViewOutput>(model, output_dir);
    if (!root)
      return;
    contact.open(output_dir);
    openings.open(output_dir);
    if (with_modes)
      {
        campbell.open(output_dir);
        critical.open(output_dir);
        rigid.open(output_dir);
        stability.open(output_dir);
      }
    if (with_response)
      responses.open(output_dir);
  }

  void
  Results::add(const std::vector<ResponsePeak> &peaks)
  {
    if (root && prepared && with_response)
      write_response_peaks(output_dir, peaks);
  }

  void
  Results::add(const StaticState &state)
  {
    contact.add(state);
    openings.add(state);
    if (write_paraview && paraview)
      paraview->write_static(state);
  }

  void
  Results::add(const StaticState &state, const ModalResult &modes)
  {
    rigid.add(modes);
    campbell.add(state, modes);
    critical.add(modes);
    if (write_shapes && paraview)
      paraview->write_modes(modes);
  }

  void
  Results::finish(const Summary &summary, const bool with_modes)
  {
    if (!prepared || !root)
      return;
    {
      std::ofstream out(output_dir + "/summary.txt");
      for (const auto &[key, value] : summary.list())
        {
          std::string line = value; // one line per entry: summary.txt is key value
          std::replace(line.begin(), line.end(), '\n', ' ');
          out << key << ' ' << line << '\n';
        }
    }
    if (!pictures)
      return;
    // the pictures read the files just closed; python3-matplotlib may be
    // missing: the tables stay complete, the log says which picture failed
    std::vector<std::pair<std::string, std::string>> scripts;
    if (with_contact)
      scripts.emplace_back("plot_contact.py", "contact.png");
    if (with_modes && plot)
      scripts.emplace_back("plot_campbell.py" +
                              (campbell_fmax > 0 ? " --fmax " + format_number(campbell_fmax) : ""),
                            "campbell.png");
    if (with_modes && with_response)
      scripts.emplace_back("plot_response.py", "response_bode.png, response_polar.png");
    for (const auto &[script, files] : scripts)
      {
        const std::string command = std::string(ROTORFIT_PYTHON) + " " + ROTORFIT_SCRIPT_DIR +
                                    "/" + script.substr(0, script.find(' ')) + " '" + output_dir +
                                    "'" + (script.find(' ') == std::string::npos ?
                                             "" :
                                             script.substr(script.find(' '))) +
                                    " >> '" + output_dir + "/plot.log' 2>&1";
        if (std::system(command.c_str()) == 0)
          log << "Picture: " << output_dir << "/" << files << '\n';
        else
          log << "Warning: " << files << " could not be drawn (see " << output_dir
              << "/plot.log; needs python3-matplotlib); the csv files are complete.\n";
      }
  }
} // namespace rotorfit
