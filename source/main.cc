#include <rotorfit/app/application.h>

#include <deal.II/base/mpi.h>

int
main(int argc, char **argv)
{
  // one thread per rank: the machine has two cores, MPI uses them
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  return rotorfit::run_application(argc, argv);
}
