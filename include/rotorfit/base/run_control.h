#pragma once

#include <mpi.h>

#include <string>

namespace rotorfit
{
  /**
   * What keeps two runs and a signal from corrupting a result folder.
   *
   * - A lock in the output folder: a second run into it is refused with the
   *   process id of the run that holds it (flock: the lock goes with the
   *   process, also when it is killed).
   * - SIGINT and SIGTERM set a flag; the run stops at the next safe point
   *   (between speeds), says where in the log and exits with
   *   exit_code::interrupted. A second signal ends the process at once.
   */
  namespace run_control
  {
    /// Catch SIGINT and SIGTERM (call once, early).
    void
    install_signal_handlers();

    /// The signal received so far (0: none), agreed on by all ranks.
    int
    pending_signal(const MPI_Comm comm);

    /// Name of a signal number ("SIGTERM").
    std::string
    signal_name(const int signal);

    /// Throws Interrupted if a signal arrived; @p where says what was done.
    void
    stop_if_interrupted(const MPI_Comm comm, const std::string &where);

    /**
     * Lock @p directory for this process (rank 0 only, held until exit).
     * Throws InputError naming the holder's process id if another run holds
     * it, or the path if the directory cannot be written.
     */
    void
    lock_output_directory(const std::string &directory);

    /**
     * Would @p directory be writable (created if missing) and free (no
     * other run holding its lock)? Returns an empty string if so, else the
     * reason with the path: what the run itself would refuse. Creates
     * nothing.
     */
    std::string
    check_writable(const std::string &directory);
  } // namespace run_control
} // namespace rotorfit
