#include <rotorfit/base/format.h>
#include <rotorfit/output/pictures.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

extern char **environ;

namespace rotorfit
{
  Pictures::Pictures(const std::string &output_dir, Log &log)
    : output_dir(output_dir)
    , log(log)
  {}

  void
  Pictures::add(const std::string              &script,
                const std::vector<std::string> &arguments,
                const std::string              &files)
  {
    jobs.push_back({script, arguments, files});
  }

  std::string
  Pictures::script_directory()
  {
    // the executable, not the source tree it was built from: a moved build
    // or an installed copy still finds its scripts
    std::error_code             ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::filesystem::path bin = ec ? std::filesystem::path(".") : exe.parent_path();
    for (const auto &dir : {bin / "scripts", bin.parent_path() / "share" / "rotorfit" / "scripts"})
      if (std::filesystem::exists(dir / "plot_common.py", ec))
        return dir.string();
    return (bin / "scripts").string(); // (python3's error then names the missing script)
  }

  int
  Pictures::start(const unsigned int i, std::string &error) const
  {
    const Job               &job    = jobs[i];
    const std::string        prefix = output_dir + "/plot." + std::to_string(i);
    std::vector<std::string> args{ROTORFIT_PYTHON, script_directory() + "/" + job.script,
                                  output_dir};
    args.insert(args.end(), job.arguments.begin(), job.arguments.end());
    std::vector<char *> argv;
    for (auto &a : args)
      argv.push_back(a.data());
    argv.push_back(nullptr);
    // the script's output and errors each into a file of their own
    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    const int flags = O_WRONLY | O_CREAT | O_TRUNC;
    posix_spawn_file_actions_addopen(&files, 1, (prefix + ".log").c_str(), flags, 0644);
    posix_spawn_file_actions_addopen(&files, 2, (prefix + ".err").c_str(), flags, 0644);
    pid_t     pid  = -1;
    const int code = posix_spawn(&pid, argv[0], &files, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&files);
    if (code == 0)
      return pid;
    error = std::string(ROTORFIT_PYTHON) + " could not be started (" + std::strerror(code) + ")";
    return -1;
  }

  void
  Pictures::draw()
  {
    // the scripts run side by side (each its own python3 and matplotlib
    // start-up, about half a second), each into its own log, appended to
    // plot.log in order once all are done
    std::vector<int>         children;
    std::vector<std::string> errors(jobs.size());
    for (unsigned int i = 0; i < jobs.size(); ++i)
      children.push_back(start(i, errors[i]));
    std::ofstream plot_log(output_dir + "/plot.log", std::ios::app);
    for (unsigned int i = 0; i < jobs.size(); ++i)
      collect(i, children[i], errors[i], plot_log);
  }

  void
  Pictures::collect(const unsigned int i,
                    const int          pid,
                    const std::string &start_error,
                    std::ofstream     &plot_log) const
  {
    int status = -1;
    if (pid > 0)
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    // the script's output, then its errors, into plot.log; the last line
    // of its errors says why it failed
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
        std::error_code ignored; // (draw() never throws)
        std::filesystem::remove(part, ignored);
      }
    const std::string &files  = jobs[i].files;
    const std::string &script = jobs[i].script;
    if (pid > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0)
      {
        log << "Picture: " << output_dir << "/" << files << '\n';
        return;
      }
    // matplotlib is blamed only where its import failed (the scripts say
    // 'not importable'); any other failure is the script's own
    std::string why;
    if (pid <= 0)
      why = start_error;
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
} // namespace rotorfit
