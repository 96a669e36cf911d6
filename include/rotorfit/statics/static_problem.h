#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/contact_solver.h>
#include <rotorfit/material/bodies.h>
#include <rotorfit/mesh/assembly_mesh.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/fe/fe_system.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>

#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * The static part of a rotorfit run: an assembly of bodies on a gmsh mesh,
   * shrink-fit interfaces with node-to-node frictionless contact, solved
   * under interference and centrifugal load at every speed of the sweep with
   * the contact state updated (THEORY 2, 6, 7). Writes contact.csv,
   * pair_openings.csv, summary.txt and ParaView files into the output
   * directory, each speed as soon as it is done.
   *
   * Parameters: subsections "Physics", "Supports", "Output" (and those of
   * the classes it owns).
   */
  class StaticProblem
  {
  public:
    StaticProblem(const MPI_Comm comm, Log &log);

    /// Everything but the per-name body/interface subsections.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm,
                     const std::string        &prm_directory);

    const std::string &
    output_directory() const
    {
      return output_dir;
    }

    /// Mesh, DoFs, contact pairs, constraints (the whole input check).
    void
    setup();

    /// Called after the static solve of each speed: (step, speed [r/min], state).
    using SpeedCallback =
      std::function<void(unsigned int, double, const ContactSolver::State &)>;

    /// Assemble and run the speed sweep; @p after_speed (if set) runs at
    /// every speed once the static results are written.
    void
    run(const SpeedCallback &after_speed = {});

    /// @name What the dynamics builds on (valid after setup())
    /// @{
    const AssemblyMesh &
    assembly_mesh() const
    {
      return mesh;
    }
    const dealii::DoFHandler<3> &
    dofs() const
    {
      return dof_handler;
    }
    const dealii::IndexSet &
    locally_owned_dofs() const
    {
      return owned;
    }
    const Bodies &
    body_list() const
    {
      return bodies;
    }
    const ContactPairs &
    contact_pairs() const
    {
      return pairs;
    }
    const ContactInterfaces &
    interface_list() const
    {
      return interfaces;
    }
    const ContactSolver &
    contact_solver() const
    {
      return contact;
    }
    const SpeedSchedule &
    speed_schedule() const
    {
      return speeds;
    }
    const std::vector<dealii::Point<3>> &
    dof_support_points() const
    {
      return support_points;
    }
    bool
    spin_softening_on() const
    {
      return spin_softening;
    }
    MPI_Comm
    mpi_communicator() const
    {
      return comm;
    }
    dealii::TimerOutput &
    timer_output()
    {
      return *timer;
    }
    /// @}

    const std::vector<std::string> &
    roller_surface_list() const
    {
      return roller_surfaces;
    }

    /// Where the sweep is, for a stop message: "at 12000 r/min (speed 13 of
    /// 31; 12 speeds finished)", or "during set-up".
    std::string
    progress() const;

    /// Timing summary for the log.
    void
    print_timing(std::ostream &out) const;

  private:
    void
    compute_support_points();
    /// Interference against the fit radius (small strain, elastic limit).
    void
    check_interference() const;
    /// The rim speed of the last speed against what any rotor survives.
    void
    check_tip_speed() const;
    void
    setup_system();
    void
    assemble();
    void
    sweep(const SpeedCallback &after_speed);
    void
    write_vtu(const unsigned int step, const double rpm,
              const ContactSolver::State &state,
              const std::vector<double>  &pressure);

    MPI_Comm comm;
    Log     &log;

    // parameters
    std::string              output_dir;
    bool                     write_paraview = true;
    bool                     spin_softening = false;
    bool                     stop_on_loss_of_fit = false;
    std::vector<std::string> roller_surfaces;

    AssemblyMesh      mesh;
    Bodies            bodies;
    ContactInterfaces interfaces;
    SpeedSchedule     speeds;
    ContactSolver     contact;

    std::unique_ptr<dealii::FESystem<3>>  fe;
    dealii::DoFHandler<3>                 dof_handler;
    dealii::IndexSet                      owned;
    std::vector<dealii::Point<3>>         support_points;
    ContactPairs                          pairs;
    dealii::AffineConstraints<double>     constraints;
    dealii::DynamicSparsityPattern        sparsity;

    dealii::PETScWrappers::MPI::SparseMatrix stiffness;
    dealii::PETScWrappers::MPI::SparseMatrix spin_softening_matrix;
    dealii::PETScWrappers::MPI::Vector       unit_centrifugal_load;
    dealii::Vector<double>                   stiffness_diagonal;

    std::vector<std::pair<double, std::string>> pvd_records;
    // sweep position (for progress())
    int          current_step   = -1;
    unsigned int finished_steps = 0;
    std::unique_ptr<dealii::TimerOutput>        timer;
    std::ostringstream                          timer_stream;
  };
} // namespace rotorfit
