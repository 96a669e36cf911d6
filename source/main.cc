#include <rotorfit/app/application.h>
#include <rotorfit/base/resources.h>

#include <deal.II/base/mpi.h>

int
main(int argc, char **argv)
{
  // No transparent huge pages asked for: whether they pay depends on the
  // host's state, and asking means restarting the process.
  rotorfit::resources::map_large_blocks();
  // one thread per rank: the machine has two cores, MPI uses them
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  return rotorfit::run_application(argc, argv);
}
