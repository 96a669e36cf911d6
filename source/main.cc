#include <rotorfit/app/application.h>
#include <rotorfit/base/resources.h>

#include <deal.II/base/mpi.h>

int
main(int argc, char **argv)
{
  // No transparent huge pages asked for: on TS they were measured 8 %
  // faster one day and 27 % slower another.
  rotorfit::resources::map_large_blocks();
  // one thread per rank: the machine has two cores, MPI uses them
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  return rotorfit::run_application(argc, argv);
}
