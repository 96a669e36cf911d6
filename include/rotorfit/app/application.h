#pragma once

namespace rotorfit
{
  /**
   * The rotorfit command line: rotorfit FILE.prm | --validate FILE.prm |
   * --print-parameters | --help | --version. Returns the process exit code
   * (0 success, 1 bad input, 2 failure during the solve). MPI must be
   * initialised by the caller.
   */
  int
  run_application(int argc, char **argv);
} // namespace rotorfit
