#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/run_control.h>
#include <rotorfit/output/pictures.h>
#include <rotorfit/output/results.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <algorithm>
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
    prm.declare_entry("ParaView speeds",
                      "ends, critical",
                      Patterns::Anything(),
                      "Where the ParaView files (solution, and with Eigenproblem/Write "
                      "mode shapes the modes) are written: a comma-separated list of "
                      "'all' (every speed), 'ends' (the first and the last speed), "
                      "'critical' (at each critical speed: one more eigen solve there, "
                      "series critical_solution / critical_modes) and speeds of the run "
                      "[r/min]. 'none' writes none.");
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
                      "One .pvtu per speed of Output/ParaView speeds with every "
                      "elastic mode (real and imaginary parts, on the cells' "
                      "vertices) and the tied pairs, indexed by modes.pvd.");
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
    paraview_speeds.clear();
    at_all = at_ends = at_critical = false;
    for (const auto &token : Utilities::split_string_list(prm.get("ParaView speeds"), ','))
      if (token == "all")
        at_all = true;
      else if (token == "ends")
        at_ends = true;
      else if (token == "critical")
        at_critical = true;
      else if (token == "none")
        continue;
      else
        try
          {
            std::size_t end = 0;
            paraview_speeds.push_back(std::stod(token, &end));
            if (end != token.size() || !(paraview_speeds.back() >= 0))
              throw std::invalid_argument(token);
          }
        catch (const std::exception &)
          {
            throw InputError("Output/ParaView speeds: '" + token +
                             "' is neither all, ends, critical, none nor a speed in r/min.");
          }
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
  Results::check_speeds(const std::vector<double> &run_speeds)
  {
    // a listed speed must be one of the run's: a file "near" 12,000 r/min
    // would silently show another speed
    for (const double v : paraview_speeds)
      {
        double nearest = run_speeds.front();
        for (const double r : run_speeds)
          if (std::abs(r - v) < std::abs(nearest - v))
            nearest = r;
        if (!(std::abs(nearest - v) <= 1e-9 * std::max(1., v)))
          throw InputError("Output/ParaView speeds: " + format_number(v) +
                           " r/min is not a speed of the run (the nearest is " +
                           format_number(nearest) + " r/min).");
      }
    last_index = run_speeds.size() - 1;
  }

  bool
  Results::paraview_at(const unsigned int index, const double rpm) const
  {
    if (at_all || (at_ends && (index == 0 || index == last_index)))
      return true;
    for (const double v : paraview_speeds)
      if (std::abs(v - rpm) <= 1e-9 * std::max(1., v))
        return true;
    return false;
  }

  void
  Results::write_critical_shapes(const StaticState &state, const ModalResult &modes)
  {
    if (!paraview)
      return;
    if (write_paraview)
      paraview->write_static(state, "critical_solution", n_critical_files);
    if (write_shapes)
      paraview->write_modes(modes, "critical_modes", n_critical_files);
    ++n_critical_files;
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
          for (const char *f : {"summary.txt", "contact.csv", "pair_openings.csv", "contact_events.csv",
                                "campbell.csv", "critical_speeds.csv", "rigid_modes.csv",
                                "campbell.png", "plot.log", "response.csv",
                                "response_peaks.csv", "stability_onsets.csv", "contact.png",
                                "response_bode.png", "response_polar.png", "fit.csv",
                                "body_stress.csv", "fit.png"})
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
  Results::open(const Discretization &model, const Contents &contents)
  {
    const bool with_modes = contents.modes;
    with_response         = contents.response;
    with_contact  = !model.interfaces().list().empty();
    with_fit      = with_contact;
    if (write_paraview || (with_modes && write_shapes))
      paraview = std::make_unique<ParaViewOutput>(model, output_dir);
    if (!root)
      return;
    contact.open(output_dir);
    openings.open(output_dir);
    if (with_contact)
      fit.open(output_dir);
    body_stress.open(output_dir);
    if (contents.speed_path == ContactSolver::Path::exact)
      events.open(output_dir);
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
  Results::write_response_peaks(const std::vector<ResponsePeak> &peaks)
  {
    if (root && prepared && with_response)
      rotorfit::write_response_peaks(output_dir, peaks);
  }

  void
  Results::write_static_state(const StaticState &state)
  {
    contact.add(state);
    openings.add(state);
    events.add(state);
    fit.add(state);
    body_stress.add(state);
    if (write_paraview && paraview && paraview_at(state.index, state.rpm))
      paraview->write_static(state, "solution", state.index);
  }

  void
  Results::write_modes(const StaticState &state, const ModalResult &modes)
  {
    rigid.add(modes);
    campbell.add(state, modes);
    critical.add(modes);
    if (write_shapes && paraview && paraview_at(modes.index, modes.rpm))
      paraview->write_modes(modes, "modes", modes.index);
  }

  void
  Results::finish(const Summary &summary, const bool with_modes)
  {
    if (!prepared || !root)
      return;
    write_summary(summary);
    if (pictures)
      draw_pictures(with_modes);
  }

  void
  Results::write_summary(const Summary &summary) const
  {
    std::ofstream out(output_dir + "/summary.txt");
    for (const auto &[key, value] : summary.list())
      {
        std::string line = value; // one line per entry: summary.txt is key value
        std::replace(line.begin(), line.end(), '\n', ' ');
        out << key << ' ' << line << '\n';
      }
  }

  void
  Results::draw_pictures(const bool with_modes)
  {
    // the pictures read the files just closed; python3-matplotlib may be
    // missing, or a script fail: the tables stay complete, the log says
    // which picture failed and why
    Pictures drawn(output_dir, log);
    if (with_contact)
      {
        drawn.add("plot_contact.py", {}, "contact.png");
        if (with_fit)
          drawn.add("plot_fit.py", {}, "fit.png");
      }
    if (with_modes && plot)
      drawn.add("plot_campbell.py",
                campbell_fmax > 0 ? std::vector<std::string>{"--fmax", format_number(campbell_fmax)} :
                                    std::vector<std::string>{},
                "campbell.png");
    if (with_modes && with_response)
      drawn.add("plot_response.py", {}, "response_bode.png, response_polar.png");
    drawn.draw();
  }
} // namespace rotorfit
