#include <rotorfit/base/application.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/log.h>
#include <rotorfit/base/parameter_file.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/base/run_control.h>
#include <rotorfit/base/version.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/eigen/modal_problem.h>
#include <rotorfit/material/bodies.h>
#include <rotorfit/statics/static_problem.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/revision.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    const char *usage =
      "Usage: rotorfit [--output DIR] FILE.prm     run the case\n"
      "       rotorfit --validate [--output DIR] FILE.prm\n"
      "                                           parse and cross-check (mesh, pairs,\n"
      "                                           supports, output folder), no solve\n"
      "       rotorfit --print-parameters         every entry with default, pattern,\n"
      "                                           units and meaning\n"
      "       rotorfit --help | --version\n"
      "--output DIR: results into DIR instead of the file's Output/Directory\n";

    void
    declare_all(ParameterHandler               &prm,
                const std::vector<std::string> &body_names,
                const std::vector<std::string> &interface_names,
                const std::vector<std::string> &bearing_names)
    {
      StaticProblem::declare_parameters(prm);
      ModalProblem::declare_parameters(prm);
      Bodies::declare_parameters(prm, body_names);
      ContactInterfaces::declare_parameters(prm, interface_names);
      Bearings::declare_parameters(prm, bearing_names);
    }

    /// deal.II's message without file/line/stack decoration.
    std::string
    message_of(const ExceptionBase &e)
    {
      std::ostringstream s;
      e.print_info(s);
      // one line: deal.II indents its messages over several
      std::string m, word;
      std::istringstream words(s.str());
      while (words >> word)
        m += (m.empty() ? "" : " ") + word;
      return m;
    }

    /**
     * One physical surface carrying two features counts it twice: two
     * interfaces on one surface halve the contact pressure, two bearings on
     * one face double the stiffness. Refused; an axial roller on a fit
     * surface is legitimate for verification set-ups and only warned.
     */
    void
    check_surface_use(const StaticProblem &problem, const ModalProblem &modal, Log &log)
    {
      std::map<std::string, std::string> owner; // surface -> first feature
      const auto claim = [&](const std::string &surface, const std::string &feature,
                             const std::string &fix) {
        const auto [it, inserted] = owner.emplace(surface, feature);
        if (!inserted && it->second != feature)
          throw InputError("physical surface '" + surface + "' is used by " + it->second +
                           " and by " + feature + "; " + fix);
      };
      for (const auto &f : problem.interface_list().list())
        {
          const std::string feature = "Interface " + f.name;
          claim(f.shaft_surface, feature,
                "each fit surface belongs to one interface (a second one would "
                "halve its contact pressure).");
          if (f.hub_surface != f.shaft_surface)
            claim(f.hub_surface, feature,
                  "each fit surface belongs to one interface (a second one would "
                  "halve its contact pressure).");
        }
      for (const auto &b : modal.bearing_list().list())
        claim(b.surface, "Bearing " + b.name,
              "a bearing acts on a shaft surface of its own (a fit surface is "
              "inside the assembly; two bearings on one face double its "
              "stiffness: add their coefficients into one bearing).");
      for (const auto &r : problem.roller_surface_list())
        {
          const auto it = owner.find(r);
          if (it != owner.end() && it->second.rfind("Interface", 0) == 0)
            log << "Warning: Supports/Axial roller surfaces: '" << r
                << "' is a fit surface of " << it->second
                << "; its nodes are held axially.\n";
        }
    }

    /// Memory of the run's largest phase against the machine's, after the
    /// mesh is known (before any matrix is assembled).
    void
    check_resources(const StaticProblem &problem, const ModalProblem &modal, Log &log)
    {
      using namespace resources;
      const double n          = problem.dofs().n_dofs();
      const double statics    = factorization_bytes(n, true) + 3 * sparse_matrix_bytes(n);
      double       eigen      = 0;
      if (modal.enabled())
        eigen = factorization_bytes(n, false) + 12 * sparse_matrix_bytes(n) +
                // the Arnoldi vectors are replicated on every rank
                Utilities::MPI::n_mpi_processes(problem.mpi_communicator()) *
                  modal.state_vectors_needed(n) * 2 * n * 8.;
      const double peak = std::max(statics, eigen);
      // rank 0 decides for all (ranks may see other environments or nodes)
      const double limit = Utilities::MPI::broadcast(problem.mpi_communicator(),
                                                     physical_memory_bytes(), 0);
      log << "Memory estimate: " << gigabytes(peak) << " at the peak ("
          << (eigen > statics ? "eigenproblem" : "static solve") << "), machine "
          << gigabytes(limit) << '\n';
      if (peak > 0.9 * limit)
        throw InputError(
          "the model (" + std::to_string(static_cast<long long>(n)) +
          " DOFs) needs about " + gigabytes(peak) + " at its peak (" +
          (eigen > statics ? "the eigenproblem's LU and Krylov space" :
                             "the static factorisation") +
          ") but this run may use " + gigabytes(limit) + " (the machine's memory, or ROTORFIT_MEMORY_GB)" +
          "; coarsen the mesh, or lower Eigenproblem/Number of modes or Krylov size factor.");
    }

    /// Two passes: the body and interface names decide which subsections
    /// exist; the second pass is strict, so a misspelt entry is an error.
    void
    parse_file(ParameterHandler &prm, const std::string &file)
    {
      // .prm files are scanned (BOM, entries set twice); deal.II reads
      // .json and .xml itself
      const std::string ext  = std::filesystem::path(file).extension().string();
      const bool        prm_format = ext != ".json" && ext != ".xml";
      const std::string text = prm_format ? read_parameter_file(file) : "";
      if (!prm_format && !std::filesystem::exists(file))
        throw InputError("the parameter file '" + file + "' does not exist.");
      const auto read = [&](ParameterHandler &handler, const bool skip_undefined) {
        if (prm_format)
          {
            std::istringstream in(text);
            handler.parse_input(in, file, "", skip_undefined);
          }
        else
          handler.parse_input(file, "", skip_undefined);
      };
      std::vector<std::string> bodies, interfaces, bearings;
      try
        {
          ParameterHandler first;
          declare_all(first, {}, {}, {});
          read(first, true);
          bodies = Utilities::split_string_list(first.get("Bodies"), ',');
          interfaces =
            Utilities::split_string_list(first.get("Interfaces"), ',');
          bearings = Utilities::split_string_list(first.get("Bearings"), ',');
          check_unique(interfaces, file + ": Interfaces");
          check_unique(bearings, file + ": Bearings");
          declare_all(prm, bodies, interfaces, bearings);
          read(prm, false);
        }
      catch (const ExceptionBase &e)
        {
          throw InputError(file + ": " + message_of(e));
        }
      if (bodies.empty())
        throw InputError(file + ": 'Bodies' is empty; name at least one body.");
    }
  } // namespace

  int
  run_application(int argc, char **argv)
  {
    const MPI_Comm comm = MPI_COMM_WORLD;
    const bool     root = Utilities::MPI::this_mpi_process(comm) == 0;
    std::vector<std::string> args(argv + 1, argv + argc);

    if (args.empty() || args[0] == "--help" || args[0] == "-h")
      {
        if (root)
          std::cout << usage;
        return args.empty() ? 1 : 0;
      }
    if (args[0] == "--version")
      {
        if (root)
          std::cout << "rotorfit " << ROTORFIT_VERSION << " (git "
                    << ROTORFIT_GIT_HASH << ", " << ROTORFIT_BUILD_TYPE
                    << "), deal.II " << DEAL_II_PACKAGE_VERSION << '\n';
        return 0;
      }
    if (args[0] == "--print-parameters")
      {
        ParameterHandler prm;
        declare_all(prm, {"<name>"}, {"<name>"}, {"<name>"});
        if (root)
          prm.print_parameters(std::cout, ParameterHandler::Text);
        return 0;
      }

    bool        validate = false, bad = false;
    std::string file, output_override;
    for (std::size_t i = 0; i < args.size() && !bad; ++i)
      if (args[i] == "--validate")
        validate = true;
      else if (args[i] == "--output" && i + 1 < args.size() && output_override.empty())
        output_override = args[++i];
      else if (args[i].rfind("-", 0) != 0 && file.empty())
        file = args[i];
      else
        bad = true;
    if (bad || file.empty())
      {
        if (root)
          std::cerr << "rotorfit: error: unknown arguments.\n" << usage;
        return 1;
      }

    Log log(root);
    run_control::install_signal_handlers();
    // set once the output folder is ours: from then on every way out of the
    // run leaves its status in summary.txt
    std::string output_dir;
    const auto  write_status = [&](const std::string &status, const int code,
                                  const std::string &where, const std::string &message) {
      if (!root || output_dir.empty())
        return;
      std::ofstream summary(output_dir + "/summary.txt", std::ios::app);
      summary << "run.status " << status << '\n' << "run.exit_code " << code << '\n';
      if (!where.empty())
        summary << "run.stopped_at " << where << '\n';
      if (!message.empty())
        {
          std::string line = message; // one line: summary.txt is key value
          std::replace(line.begin(), line.end(), '\n', ' ');
          summary << "run.message " << line << '\n';
        }
    };
    try
      {
        ParameterHandler prm;
        parse_file(prm, file);
        if (!output_override.empty())
          {
            // the command line wins over the file (tests and scripted
            // studies never edit a .prm)
            prm.enter_subsection("Output");
            prm.set("Directory", output_override);
            prm.leave_subsection();
          }
        StaticProblem problem(comm, log);
        ModalProblem  modal(problem, log);
        const std::string dir =
          std::filesystem::path(file).parent_path().string();
        problem.parse_parameters(prm, dir.empty() ? "." : dir);
        modal.parse_parameters(prm, dir.empty() ? "." : dir);
        check_surface_use(problem, modal, log);
        {
          std::string error;
          if (root)
            error = run_control::check_writable(problem.output_directory());
          error = Utilities::MPI::broadcast(comm, error, 0);
          if (!error.empty())
            throw InputError(error);
        }
        if (!validate)
          {
            std::string error;
            if (root)
              try
                {
                  std::error_code ec;
                  std::filesystem::create_directories(problem.output_directory(), ec);
                  if (ec)
                    throw InputError("Output/Directory = '" + problem.output_directory() +
                                     "' cannot be created: " + ec.message() + ".");
                  run_control::lock_output_directory(problem.output_directory());
                  // results of an earlier run into this folder must not be
                  // mistaken for this run's
                  for (const char *f : {"summary.txt", "contact.csv", "pair_openings.csv",
                                        "campbell.csv", "critical_speeds.csv",
                                        "rigid_modes.csv", "campbell.png", "plot.log"})
                    std::filesystem::remove(problem.output_directory() + "/" + f, ec);
                  std::ofstream out(problem.output_directory() + "/parameters.prm");
                  prm.print_parameters(out, ParameterHandler::ShortPRM);
                  std::ofstream summary(problem.output_directory() + "/summary.txt");
                  if (!out || !summary)
                    throw InputError("Output/Directory = '" + problem.output_directory() +
                                     "': files cannot be written there.");
                }
              catch (const InputError &e)
                {
                  error = e.what();
                }
            error = Utilities::MPI::broadcast(comm, error, 0);
            if (!error.empty())
              throw InputError(error);
            output_dir = problem.output_directory();
            log.open_file(output_dir + "/log.txt");
          }
        log << "rotorfit " << ROTORFIT_VERSION << " (git " << ROTORFIT_GIT_HASH
            << ", " << ROTORFIT_BUILD_TYPE << "), deal.II "
            << DEAL_II_PACKAGE_VERSION << ", "
            << Utilities::MPI::n_mpi_processes(comm) << " MPI rank(s)\n"
            << "Case: " << file << '\n';
        problem.setup();
        modal.setup();
        check_resources(problem, modal, log);
        if (validate)
          {
            log << file << ": valid.\n";
            return exit_code::success;
          }
        try
          {
            run_control::stop_if_interrupted(comm, "before the first speed");
            StaticProblem::SpeedCallback eigen_step;
            if (modal.enabled())
              eigen_step = [&](const unsigned int          step,
                               const double                rpm,
                               const ContactSolver::State &state) {
                modal.solve_speed(step, rpm, state);
              };
            problem.run(eigen_step);
            modal.finish();
          }
        catch (const InputError &)
          {
            throw;
          }
        catch (const Interrupted &e)
          {
            const std::string where = problem.progress();
            log << "rotorfit: " << e.what() << "; stopped " << where
                << ". The finished speeds are in " << output_dir << ".\n";
            write_status("interrupted", exit_code::interrupted, where, e.what());
            modal.finish();
            return exit_code::interrupted;
          }
        catch (const std::exception &e)
          {
            const std::string where = problem.progress();
            log << "rotorfit: failure during the solve (" << where << "): " << e.what()
                << "\nThe speeds already done are in " << output_dir << ".\n";
            write_status("failed", exit_code::solver, where, e.what());
            modal.finish();
            return exit_code::solver;
          }
        std::ostringstream timing;
        problem.print_timing(timing);
        log << timing.str();
        write_status("completed", exit_code::success, "", "");
      }
    catch (const InputError &e)
      {
        if (root)
          std::cerr << "rotorfit: error: " << e.what() << '\n';
        write_status("refused", exit_code::input_error, "", e.what());
        return exit_code::input_error;
      }
    catch (const Interrupted &e)
      {
        if (root)
          std::cerr << "rotorfit: " << e.what() << '\n';
        write_status("interrupted", exit_code::interrupted, "set-up", e.what());
        return exit_code::interrupted;
      }
    catch (const ExceptionBase &e)
      {
        if (root)
          std::cerr << "rotorfit: error: " << message_of(e) << '\n';
        write_status("failed", exit_code::solver, "set-up", message_of(e));
        return exit_code::solver;
      }
    catch (const std::exception &e)
      {
        if (root)
          std::cerr << "rotorfit: error: " << e.what() << '\n';
        write_status("failed", exit_code::solver, "set-up", e.what());
        return exit_code::solver;
      }
    return exit_code::success;
  }
} // namespace rotorfit
