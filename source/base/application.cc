#include <rotorfit/base/application.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/log.h>
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

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    const char *usage =
      "Usage: rotorfit FILE.prm             run the case\n"
      "       rotorfit --validate FILE.prm  parse and cross-check (mesh, pairs,\n"
      "                                     supports), no solve\n"
      "       rotorfit --print-parameters   every entry with default, pattern,\n"
      "                                     units and meaning\n"
      "       rotorfit --help | --version\n";

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

    /// Two passes: the body and interface names decide which subsections
    /// exist; the second pass is strict, so a misspelt entry is an error.
    void
    parse_file(ParameterHandler &prm, const std::string &file)
    {
      if (!std::filesystem::exists(file))
        throw InputError("the parameter file '" + file + "' does not exist.");
      std::vector<std::string> bodies, interfaces, bearings;
      try
        {
          ParameterHandler first;
          declare_all(first, {}, {}, {});
          first.parse_input(file, "", true);
          bodies = Utilities::split_string_list(first.get("Bodies"), ',');
          interfaces =
            Utilities::split_string_list(first.get("Interfaces"), ',');
          bearings = Utilities::split_string_list(first.get("Bearings"), ',');
          declare_all(prm, bodies, interfaces, bearings);
          prm.parse_input(file, "", false);
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

    bool        validate = false;
    std::string file;
    if (args[0] == "--validate" && args.size() == 2)
      {
        validate = true;
        file     = args[1];
      }
    else if (args.size() == 1 && args[0].rfind("-", 0) != 0)
      file = args[0];
    else
      {
        if (root)
          std::cerr << "rotorfit: error: unknown arguments.\n" << usage;
        return 1;
      }

    Log log(root);
    try
      {
        ParameterHandler prm;
        parse_file(prm, file);
        StaticProblem problem(comm, log);
        ModalProblem  modal(problem, log);
        const std::string dir =
          std::filesystem::path(file).parent_path().string();
        problem.parse_parameters(prm, dir.empty() ? "." : dir);
        modal.parse_parameters(prm, dir.empty() ? "." : dir);
        if (!validate)
          {
            std::string error;
            if (root)
              {
                std::error_code ec;
                std::filesystem::create_directories(problem.output_directory(), ec);
                if (ec)
                  error = "Output/Directory = '" + problem.output_directory() +
                          "' cannot be created: " + ec.message() + ".";
              }
            error = Utilities::MPI::broadcast(comm, error, 0);
            if (!error.empty())
              throw InputError(error);
            log.open_file(problem.output_directory() + "/log.txt");
            if (root)
              {
                std::ofstream out(problem.output_directory() + "/parameters.prm");
                prm.print_parameters(out, ParameterHandler::ShortPRM);
              }
          }
        log << "rotorfit " << ROTORFIT_VERSION << " (git " << ROTORFIT_GIT_HASH
            << ", " << ROTORFIT_BUILD_TYPE << "), deal.II "
            << DEAL_II_PACKAGE_VERSION << ", "
            << Utilities::MPI::n_mpi_processes(comm) << " MPI rank(s)\n"
            << "Case: " << file << '\n';
        problem.setup();
        modal.setup();
        if (validate)
          {
            log << file << ": valid.\n";
            return 0;
          }
        try
          {
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
        catch (const std::exception &e)
          {
            log << "rotorfit: failure during the solve: " << e.what()
                << "\nThe speeds already done are in "
                << problem.output_directory() << ".\n";
            modal.finish();
            return 2;
          }
        std::ostringstream timing;
        problem.print_timing(timing);
        log << timing.str();
      }
    catch (const InputError &e)
      {
        if (root)
          std::cerr << "rotorfit: error: " << e.what() << '\n';
        return 1;
      }
    catch (const ExceptionBase &e)
      {
        if (root)
          std::cerr << "rotorfit: error: " << message_of(e) << '\n';
        return 2;
      }
    return 0;
  }
} // namespace rotorfit
