#pragma once

#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

namespace rotorfit
{
  /**
   * Writes to the terminal and to the run's log file, on MPI rank 0 only.
   * The log file is flushed after every line so that an interrupted run
   * keeps everything it printed.
   */
  class Log
  {
  public:
    explicit Log(const bool active)
      : active(active)
    {}

    /// Start copying everything into @p filename (rank 0 only), closing the
    /// file before; @p append: continue it (a refinement cycle wrote its own).
    void
    open_file(const std::string &filename, const bool append = false)
    {
      if (!active)
        return;
      if (file.is_open())
        file.close();
      file.open(filename, append ? std::ios::app : std::ios::out);
    }

    template <typename T>
    Log &
    operator<<(const T &t)
    {
      if (active)
        {
          std::cout << t;
          if (file.is_open())
            file << t << std::flush; // an interrupted run keeps its log
        }
      return *this;
    }

    Log &
    operator<<(std::ostream &(*manipulator)(std::ostream &))
    {
      if (active)
        {
          std::cout << manipulator;
          if (file.is_open())
            file << manipulator << std::flush;
        }
      return *this;
    }

  private:
    bool          active;
    std::ofstream file;
  };
} // namespace rotorfit
