#include <rotorfit/app/application.h>
#include <rotorfit/app/fit_cases.h>
#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/log.h>
#include <rotorfit/base/parameter_file.h>
#include <rotorfit/base/run_control.h>
#include <rotorfit/base/version.h>
#include <rotorfit/problem/rotor_problem.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/revision.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    const char *usage =
      "Usage: rotorfit [--output DIR] [--set S/E=V] FILE.prm   run the case\n"
      "       rotorfit --validate [--output DIR] FILE.prm\n"
      "                                           parse and cross-check (mesh, pairs,\n"
      "                                           supports, output folder), no solve\n"
      "       rotorfit --print-parameters [json]  every entry with default, units and\n"
      "                                           meaning (json: with its pattern)\n"
      "       rotorfit --help | --version\n"
      "--output DIR: results into DIR instead of the file's Output/Directory\n"
      "--set 'Subsection/Entry=value' (repeatable): overrides an entry of the file\n";

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
      // .prm files are scanned (BOM, entries set twice); deal.II reads
      // .json and .xml itself
      const std::string ext  = std::filesystem::path(file).extension().string();
      const bool        prm_format = ext != ".json" && ext != ".xml";
      const std::string text = prm_format ? read_parameter_file(file) : "";
      if (!prm_format && !std::filesystem::exists(file))
        throw InputError("the parameter file '" + file + "' does not exist.");
      if (!prm_format)
        record_file(file);
      const auto read = [&](ParameterHandler &handler, const bool skip_undefined) {
        if (prm_format)
          {
            std::istringstream in(text);
            handler.parse_input(in, file, "", skip_undefined);
          }
        else
          handler.parse_input(file, "", skip_undefined);
      };
      CaseNames names;
      try
        {
          ParameterHandler first;
          RotorProblem::declare_parameters(first, {});
          read(first, true);
          const auto list = [&](const char *entry) {
            auto v = Utilities::split_string_list(first.get(entry), ',');
            check_unique(v, file + ": " + entry);
            return v;
          };
          names = {list("Bodies"), list("Interfaces"), list("Bearings"), list("Unbalances"),
                   list("Probes")};
          RotorProblem::declare_parameters(prm, names);
          read(prm, false);
        }
      catch (const ExceptionBase &e)
        {
          throw InputError(file + ": " + message_of(e));
        }
      if (names.bodies.empty())
        throw InputError(file + ": 'Bodies' is empty; name at least one body.");
    }

    /// --help, --version, --print-parameters: the exit code, or -1 when
    /// @p args ask for a case to be run.
    int
    information(const std::vector<std::string> &args, const bool root)
    {
      if (args.empty() || args[0] == "--help" || args[0] == "-h")
        {
          if (root)
            std::cout << usage;
          return args.empty() ? exit_code::input_error : exit_code::success;
        }
      if (args[0] == "--version")
        {
          if (root)
            std::cout << "rotorfit " << ROTORFIT_VERSION << " (git " << ROTORFIT_GIT_HASH << ", "
                      << ROTORFIT_BUILD_TYPE << "), deal.II " << DEAL_II_PACKAGE_VERSION << '\n';
          return exit_code::success;
        }
      if (args[0] != "--print-parameters")
        return -1;
      // text: a .prm with every default; json: with the patterns, for the
      // generated reference doc/parameters.md
      const std::string format = args.size() > 1 ? args[1] : "text";
      if (args.size() > 2 || (format != "text" && format != "json"))
        {
          if (root)
            std::cerr << "rotorfit: error: --print-parameters [text|json]\n";
          return exit_code::input_error;
        }
      ParameterHandler prm;
      RotorProblem::declare_parameters(
        prm, {{"<name>"}, {"<name>"}, {"<name>"}, {"<name>"}, {"<name>"}});
      if (root)
        prm.print_parameters(std::cout,
                             format == "json" ? ParameterHandler::JSON : ParameterHandler::Text);
      return exit_code::success;
    }

    /// --set overrides: a studied variant of a case without a copy of its
    /// .prm. The entry's pattern checks the value.
    void
    apply_sets(ParameterHandler                                       &prm,
               const std::vector<std::pair<std::string, std::string>> &sets)
    {
      for (const auto &[path, value] : sets)
        {
          const std::string argument = "--set '" + path + "=" + value + "'";
          // every part of the path named: an empty one ('=5', 'Speeds//End')
          // left no entry to set (an empty path crashed)
          std::vector<std::string> sections;
          std::size_t              a = 0;
          for (std::size_t b; (b = path.find('/', a)) != std::string::npos; a = b + 1)
            sections.push_back(Utilities::trim(path.substr(a, b - a)));
          sections.push_back(Utilities::trim(path.substr(a)));
          if (std::any_of(sections.begin(), sections.end(), [](const std::string &p) {
                return p.empty();
              }))
            throw InputError(argument + ": the entry '" + path + "' " +
                             (Utilities::trim(path).empty() ? "is empty" : "has an empty part") +
                             "; write --set 'Subsection/Entry=value', e.g. --set "
                             "'Speeds/End=20000'.");
          const std::string problem = unrepresentable_number(value);
          if (!problem.empty())
            throw InputError(argument + ": " + problem);
          try
            {
              for (std::size_t k = 0; k + 1 < sections.size(); ++k)
                prm.enter_subsection(sections[k]);
              prm.set(sections.back(), value);
              for (std::size_t k = 0; k + 1 < sections.size(); ++k)
                prm.leave_subsection();
            }
          catch (const ExceptionBase &e)
            {
              throw InputError(argument + ": " + message_of(e));
            }
          record_override(path, path + "=" + value);
        }
    }

    /// What the command line asks of a case.
    struct CaseOptions
    {
      std::string file, output_override;
      bool        validate = false;
      /// --set: (path "Subsection/Entry", value), applied after the file
      std::vector<std::pair<std::string, std::string>> sets;
    };

    /// Empty if @p args are [--validate] [--output DIR] [--set E=V]... FILE;
    /// otherwise what is wrong with them, naming the argument.
    std::string
    parse_case_options(const std::vector<std::string> &args, CaseOptions &options)
    {
      for (std::size_t i = 0; i < args.size(); ++i)
        if (args[i] == "--validate")
          options.validate = true;
        else if (args[i] == "--output")
          {
            if (i + 1 == args.size() || args[i + 1].empty())
              return "--output needs a directory.";
            if (!options.output_override.empty())
              return "--output is given twice ('" + options.output_override + "', '" +
                     args[i + 1] + "').";
            options.output_override = args[++i];
          }
        else if (args[i] == "--set")
          {
            if (i + 1 == args.size() || args[i + 1].find('=') == std::string::npos)
              return "--set " + (i + 1 == args.size() ? std::string("needs") :
                                                         "'" + args[i + 1] + "' has no '=': write") +
                     " 'Subsection/Entry=value'.";
            const std::string &a = args[++i];
            options.sets.emplace_back(a.substr(0, a.find('=')), a.substr(a.find('=') + 1));
          }
        else if (args[i].rfind("-", 0) == 0)
          return "unknown option '" + args[i] + "'.";
        else if (!options.file.empty())
          return "two parameter files ('" + options.file + "', '" + args[i] + "'); give one.";
        else
          options.file = args[i];
      return options.file.empty() ? "no parameter file given." : "";
    }

    /// The case's file with the command line's --set overrides, into @p prm.
    void
    read_case(ParameterHandler &prm, const CaseOptions &options)
    {
      parse_file(prm, options.file);
      apply_sets(prm, options.sets);
    }

    /// The case read into @p prm and parsed by a new problem.
    std::unique_ptr<RotorProblem>
    open_case(ParameterHandler &prm, const CaseOptions &options, const MPI_Comm comm, Log &log)
    {
      read_case(prm, options);
      const std::string dir     = std::filesystem::path(options.file).parent_path().string();
      auto              problem = std::make_unique<RotorProblem>(comm, log);
      try
        {
          problem->parse_parameters(prm, dir.empty() ? "." : dir, options.output_override);
        }
      catch (const ExceptionBase &e)
        {
          // a value deal.II's pattern passed and its conversion refused
          // (in a .json file, say): the input's fault, not the solver's
          throw InputError(options.file +
                           (options.sets.empty() ? "" : " (with its --set overrides)") + ": " +
                           message_of(e));
        }
      return problem;
    }

    /// Validate or run one case; every way out is an exit code, and once the
    /// output folder is ours, a status in its summary.txt.
    int
    run_case(const CaseOptions &options, const MPI_Comm comm, Log &log,
             std::string *loose_at_rest = nullptr)
    {
      const bool         root     = Utilities::MPI::this_mpi_process(comm) == 0;
      const std::string &file     = options.file;
      const bool         validate = options.validate;

      run_control::install_signal_handlers();
      // once the output folder is ours, every way out of the run leaves its
      // status in summary.txt (RotorProblem::finish)
      std::unique_ptr<RotorProblem> problem;
      bool                          output_ready = false;
      const auto                    stop = [&](const std::string &status, const int code,
                            const std::string &where, const std::string &message) {
        if (output_ready)
          problem->finish(status, code, where, message);
        return code;
      };
      try
        {
          ParameterHandler prm;
          problem = open_case(prm, options, comm, log);
          problem->check_output();
          if (!validate)
            {
              problem->prepare_output(prm);
              output_ready = true;
            }
          log << "rotorfit " << ROTORFIT_VERSION << " (git " << ROTORFIT_GIT_HASH << ", "
              << ROTORFIT_BUILD_TYPE << "), deal.II " << DEAL_II_PACKAGE_VERSION << ", "
              << Utilities::MPI::n_mpi_processes(comm) << " MPI rank(s)\n"
              << "Case: " << file << '\n';
          if (!validate)
            {
              // the cycles read the case again, as it was read here
              const int code = problem->refine_mesh(
                [&](ParameterHandler &cycle_prm) { read_case(cycle_prm, options); });
              if (code != exit_code::success)
                return stop(code == exit_code::interrupted ? "interrupted" : "failed",
                            code,
                            "mesh refinement",
                            "a refinement cycle stopped; its results are in its cycle_<k> folder");
            }
          problem->setup();
          if (validate)
            {
              log << file << ": valid.\n";
              return exit_code::success;
            }
          return problem->run_and_finish();
        }
      catch (const FitLooseAtRest &e)
        {
          // a case of a fit study: recorded there, and the study goes on
          if (loose_at_rest)
            {
              log << "Fit loose at rest: " << e.what() << '\n';
              *loose_at_rest = e.what();
              return stop("loose_at_rest", exit_code::success, "", e.what());
            }
          if (root)
            std::cerr << "rotorfit: error: " << e.what() << '\n';
          return stop("refused", exit_code::input_error, "", e.what());
        }
      catch (const InputError &e)
        {
          if (root)
            std::cerr << "rotorfit: error: " << e.what() << '\n';
          return stop("refused", exit_code::input_error, "", e.what());
        }
      catch (const Interrupted &e)
        {
          if (root)
            std::cerr << "rotorfit: " << e.what() << '\n';
          return stop("interrupted", exit_code::interrupted, "set-up", e.what());
        }
      catch (const ExceptionBase &e)
        {
          if (root)
            std::cerr << "rotorfit: error: " << message_of(e) << '\n';
          return stop("failed", exit_code::solver, "set-up", message_of(e));
        }
      catch (const std::exception &e)
        {
          if (root)
            std::cerr << "rotorfit: error: " << e.what() << '\n';
          return stop("failed", exit_code::solver, "set-up", e.what());
        }
    }

    /**
     * A fit study (a toleranced fit, temperature cases): every case one
     * after the other, each into its subfolder, then the study's
     * fit_cases.csv and summary.txt. Otherwise the one case.
     */
    int
    run_cases(const CaseOptions &options, const MPI_Comm comm, Log &log)
    {
      std::unique_ptr<FitCases> study;
      std::string               directory;
      try
        {
          ParameterHandler prm;
          Log              quiet(false);
          const auto       problem = open_case(prm, options, comm, quiet);
          study     = std::make_unique<FitCases>(problem->discretization());
          directory = problem->output_directory();
          if (study->list().size() > 1 && !options.validate &&
              Utilities::MPI::this_mpi_process(comm) == 0)
            {
              // the study as given: each case's folder has its own
              std::filesystem::create_directories(directory);
              std::ofstream out(directory + "/parameters.prm");
              prm.print_parameters(out, ParameterHandler::ShortPRM);
            }
        }
      catch (...)
        {
          // run_case reads the case again and reports what is wrong
          study.reset();
        }
      if (!study || study->list().size() <= 1)
        return run_case(options, comm, log);
      log << "Fit study: " << study->list().size() << " cases into " << directory << '/';
      for (const auto &c : study->list())
        log << ' ' << c.name;
      log << '\n';
      for (unsigned int k = 0; k < study->list().size(); ++k)
        {
          const auto &c    = study->list()[k];
          CaseOptions one  = options;
          one.sets.insert(one.sets.end(), c.sets.begin(), c.sets.end());
          one.output_override = directory + "/" + c.name;
          log << "\n=== Fit study case " << c.name << " (" << k + 1 << " of "
              << study->list().size() << ") ===\n";
          std::string loose;
          const int   code = run_case(one, comm, log, &loose);
          if (options.validate)
            {
              if (code != exit_code::success)
                return code;
              if (!loose.empty())
                log << "(the study records this case as loose at rest)\n";
              continue;
            }
          if (!loose.empty())
            study->record_loose(k, loose);
          else
            study->record(k, code, one.output_override);
          if (code == exit_code::interrupted)
            break;
        }
      if (options.validate)
        return exit_code::success;
      const int code = study->finish(directory, comm);
      log << "Fit study: fit_cases.csv and summary.txt in " << directory << '\n';
      if (code == exit_code::input_error && Utilities::MPI::this_mpi_process(comm) == 0)
        std::cerr << "rotorfit: error: the fit is loose at rest in every case of the study; "
                     "nothing was solved (fit_cases.csv).\n";
      return code;
    }
  } // namespace

  int
  run_application(int argc, char **argv)
  {
    const MPI_Comm                 comm = MPI_COMM_WORLD;
    const bool                     root = Utilities::MPI::this_mpi_process(comm) == 0;
    const std::vector<std::string> args(argv + 1, argv + argc);
    if (const int code = information(args, root); code >= 0)
      return code;
    CaseOptions options;
    if (const std::string wrong = parse_case_options(args, options); !wrong.empty())
      {
        if (root)
          std::cerr << "rotorfit: error: " << printable(wrong) << "\n" << usage;
        return exit_code::input_error;
      }
    Log log(root);
    return run_cases(options, comm, log);
  }
} // namespace rotorfit
