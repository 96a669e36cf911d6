#pragma once

#include <rotorfit/base/log.h>

#include <fstream>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * The pictures of a run (contact.png, campbell.png, response_*.png),
   * drawn by the Python scripts shipped with rotorfit from the tables of the
   * output folder. The scripts are found next to the executable: the build
   * tree's scripts/ (CMake copies them there) or an install tree's
   * share/rotorfit/scripts. Each runs as python3 with an argument vector (no
   * shell), side by side with the others; a picture that fails is a warning
   * that quotes the script's error, never a failure of the run.
   */
  class Pictures
  {
  public:
    /// Pictures of the output folder @p output_dir, reported to @p log.
    Pictures(const std::string &output_dir, Log &log);

    /// Draw @p files (as the log names them) with @p script and its extra
    /// @p arguments (after the output folder).
    void
    add(const std::string &script, const std::vector<std::string> &arguments,
        const std::string &files);

    /// Run every script, wait for all, append their output to plot.log in
    /// order and log each picture or why it failed. Never throws.
    void
    draw();

    /// The folder of the plotting scripts: beside the executable (build
    /// tree) or in its ../share/rotorfit (install tree).
    static std::string
    script_directory();

  private:
    /// One script to run, and what it draws.
    struct Job
    {
      std::string              script;
      std::vector<std::string> arguments;
      std::string              files;
    };

    /// Start job @p i with its output into plot.<i>.log and .err: its pid,
    /// or -1 (with @p error set) if it could not be started.
    int
    start(const unsigned int i, std::string &error) const;

    /// Wait for job @p i (pid @p pid), move its output into @p plot_log and
    /// log the picture, or why it was not drawn.
    void
    collect(const unsigned int i, const int pid, const std::string &start_error,
            std::ofstream &plot_log) const;

    std::string      output_dir;
    Log             &log;
    std::vector<Job> jobs;
  };
} // namespace rotorfit
