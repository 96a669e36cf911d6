#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/run_control.h>
#include <rotorfit/output/results.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <spawn.h>
#include <sys/wait.h>

extern char **environ;

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
  Results::add_critical(const StaticState &state, const ModalResult &modes)
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
  Results::open(const Discretization &model, const bool with_modes, const bool response,
                const bool exact_path)
  {
    with_response = response;
    with_contact  = !model.interfaces().list().empty();
    if (write_paraview || (with_modes && write_shapes))
      paraview = std::make_unique<ParaViewOutput>(model, output_dir);
    if (!root)
      return;
    contact.open(output_dir);
    openings.open(output_dir);
    if (exact_path)
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
    events.add(state);
    if (write_paraview && paraview && paraview_at(state.index, state.rpm))
      paraview->write_static(state, "solution", state.index);
  }

  void
  Results::add(const StaticState &state, const ModalResult &modes)
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
    // missing, or a script fail: the tables stay complete, the log says
    // which picture failed and why
    std::vector<std::pair<std::string, std::string>> scripts;
    if (with_contact)
      scripts.emplace_back("plot_contact.py", "contact.png");
    if (with_modes && plot)
      scripts.emplace_back("plot_campbell.py" +
                              (campbell_fmax > 0 ? " --fmax " + format_number(campbell_fmax) : ""),
                            "campbell.png");
    if (with_modes && with_response)
      scripts.emplace_back("plot_response.py", "response_bode.png, response_polar.png");
    // the scripts run side by side (each its own python3 and matplotlib
    // start-up, about half a second), each into its own log, appended to
    // plot.log in order once all are done
    std::vector<pid_t> children;
    for (unsigned int i = 0; i < scripts.size(); ++i)
      {
        const auto       &script  = scripts[i].first;
        const std::string command = std::string(ROTORFIT_PYTHON) + " " + ROTORFIT_SCRIPT_DIR +
                                    "/" + script.substr(0, script.find(' ')) + " '" + output_dir +
                                    "'" + (script.find(' ') == std::string::npos ?
                                             "" :
                                             script.substr(script.find(' '))) +
                                    " > '" + output_dir + "/plot." + std::to_string(i) +
                                    ".log' 2> '" + output_dir + "/plot." + std::to_string(i) +
                                    ".err'";
        const char *argv[] = {"sh", "-c", command.c_str(), nullptr};
        pid_t       pid    = -1;
        if (posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char **>(argv), environ) != 0)
          pid = -1;
        children.push_back(pid);
      }
    std::ofstream plot_log(output_dir + "/plot.log", std::ios::app);
    for (unsigned int i = 0; i < scripts.size(); ++i)
      {
        int status = -1;
        if (children[i] > 0)
          while (waitpid(children[i], &status, 0) < 0 && errno == EINTR)
            ;
        // the script's output, then its errors, into plot.log; the last
        // line of its errors says why it failed
        std::string last_error;
        for (const char *kind : {".log", ".err"})
          {
            const std::string part = output_dir + "/plot." + std::to_string(i) + kind;
            {
              std::ifstream in(part);
              std::string   line;
              while (std::getline(in, line))
                {
                  plot_log << line << '\n';
                  if (kind == std::string(".err") && line.find_first_not_of(" \t\r") != std::string::npos)
                    last_error = line;
                }
            }
            std::error_code ignored; // (finish() never throws)
            std::filesystem::remove(part, ignored);
          }
        const auto       &files  = scripts[i].second;
        const std::string script = scripts[i].first.substr(0, scripts[i].first.find(' '));
        if (children[i] > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0)
          {
            log << "Picture: " << output_dir << "/" << files << '\n';
            continue;
          }
        // matplotlib is blamed only where its import failed (the scripts
        // say 'not importable'); any other failure is the script's own
        std::string why;
        if (children[i] <= 0)
          why = "/bin/sh could not be started";
        else if (last_error.find("not importable") != std::string::npos ||
                 last_error.rfind("ModuleNotFoundError", 0) == 0 ||
                 last_error.rfind("ImportError", 0) == 0)
          why = "python3-matplotlib (and numpy) are needed: " + last_error;
        else if (!last_error.empty())
          why = script + " failed: " + last_error;
        else if (WIFSIGNALED(status))
          why = script + " was killed by signal " + std::to_string(WTERMSIG(status));
        else
          why = script + " failed with exit code " + std::to_string(WEXITSTATUS(status));
        if (why.size() > 400)
          why = why.substr(0, 400) + " ...";
        log << "Warning: " << files << " could not be drawn: " << printable(why) << " (see "
            << output_dir << "/plot.log); the csv files are complete.\n";
      }
  }
} // namespace rotorfit
