#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/model/discretization.h>

#include <mpi.h>

/**
 * The input checks that need the whole case at once (its mesh, fits,
 * bearings and speeds together), run by RotorProblem while it is set up.
 * Each refuses with InputError, naming the entries and the fix, or warns in
 * the log.
 */
namespace rotorfit::case_checks
{
  /// One physical surface carrying two features (two fits, a bearing on a
  /// fit) counts it twice: refused; an axial roller on a fit surface is
  /// warned.
  void
  surface_use(const Discretization &model, const Bearings &bearings, Log &log);

  /// The rim speed at the last speed @p rpm [r/min] against what any rotor
  /// survives (refused), and each body's against the burst range of metal
  /// disks (warned).
  void
  tip_speed(const Discretization &model, const double rpm, Log &log);

  /// Memory of the run's largest phase against the machine's: logged, and
  /// refused above 90 % of it.
  void
  resources(const Discretization          &model,
            const PrestressedEigenproblem &eigen,
            const MPI_Comm                 comm,
            Log                           &log);
} // namespace rotorfit::case_checks
