#pragma once

#include <rotorfit/contact/base_factorization.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/contact_parameters.h>
#include <rotorfit/contact/contact_state.h>
#include <rotorfit/contact/pair_operators.h>
#include <rotorfit/contact/pair_space_law.h>

#include <deal.II/base/index_set.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/petsc_vector.h>

#include <functional>
#include <vector>

namespace rotorfit
{
  /**
   * The exact path in Omega^2 (doc/theory.md 7.8): the contact state
   * followed from event to event, each pair's opening or closing speed
   * solved from the affine law of its active set, so that opening speeds
   * do not depend on the speed step. The base (every pair closed) is
   * factorised once with all its influence columns; every active set on
   * the way is then a PairSpaceLaw, and the displacements are made only
   * for the laws of the requested speeds.
   */
  class ExactPath
  {
  public:
    /// The active-set iteration at a speed: settles the current law there.
    using Settle = std::function<void(const double w, ContactState &state)>;

    /// What the path acts on (kept referenced).
    struct System
    {
      const ContactParameters                  &parameters;
      const ContactPairs                       &pairs;
      const PairOperators                      &operators;
      const dealii::AffineConstraints<double>  &constraints;
      const dealii::PETScWrappers::MPI::Vector &unit_centrifugal_load; ///< F_c
      const dealii::IndexSet                   &owned;
      MPI_Comm                                  comm;
      double w_max; ///< the largest Omega^2 of the run
    };

    /// @p base: the factorisation the path is built on.
    void
    initialize(const System &system, BaseFactorization &base);

    /// The path has begun (its base is factorised).
    bool
    started() const
    {
      return path_started;
    }

    /// finish() was called: every speed's state was made ahead.
    bool
    finished() const
    {
      return path_finished;
    }

    /**
     * Before the active-set iteration at @p w: start the path from
     * @p current's active set, or follow its events up to (not including)
     * @p w, settling @p current at each (events and failures into
     * @p state). Returns each pair's next root under the law reached (empty
     * when the path only started).
     */
    std::vector<double>
    approach(const double w, ContactState &state, const ContactDecomposition &current,
             const Settle &settle);

    /**
     * After the active-set iteration at @p w: the changes from @p before at
     * their @p roots (a pair pulled along by another one: at w) into
     * @p state, in order of w, and the displacements of @p current.
     */
    void
    arrive(const double w, const std::vector<bool> &before, const std::vector<double> &roots,
           ContactState &state, ContactDecomposition &current);

    /// The law of @p active in pair space (no sparse solve).
    ContactDecomposition
    decompose(const std::vector<bool> &active)
    {
      return law.decompose(active);
    }

    /// Every speed's state is made: free the pair-space matrices.
    void
    finish();

    /// Largest relative residual of a pair-space solve.
    double
    worst_residual() const
    {
      return law.worst_residual();
    }

    /// Active sets reached by updates of the pair-space inverse.
    unsigned int
    n_low_rank_updates() const
    {
      return law.n_low_rank_updates();
    }

  private:
    /// Factorise the base (every pair closed as in @p active), all
    /// influence columns and t_C: the pair-space problem of every active set.
    void
    start(const std::vector<bool> &active);

    /// Follow the events from the last speed up to (not including) @p w.
    void
    advance(const double w, ContactState &state, const ContactDecomposition &current,
            const Settle &settle);

    /// Smallest w' > @p w where pair @p i leaves its state under the law
    /// @p d (infinity: never).
    static double
    event_w(const ContactDecomposition &d, const unsigned int i, const double w);

    /// Per interface: sum N_i and sum N_i r_i of @p d's closed pairs at @p w.
    void
    resultants(const ContactDecomposition &d, const double w, std::vector<double> &force,
               std::vector<double> &moment) const;

    /// u_I, u_C of @p d (two back-substitutions), unless made already.
    void
    make_displacements(ContactDecomposition &d);

    const PairOperators                      *ops         = nullptr;
    const dealii::AffineConstraints<double>  *constraints = nullptr;
    const dealii::PETScWrappers::MPI::Vector *F_c         = nullptr;
    const ContactPairs                       *pairs       = nullptr;
    BaseFactorization                        *base        = nullptr;
    dealii::IndexSet                          owned;
    MPI_Comm                                  comm = MPI_COMM_SELF;

    PairSpaceLaw law;
    bool         path_started  = false;
    bool         path_finished = false;
    double       path_w        = 0; ///< Omega^2 the path has reached
  };
} // namespace rotorfit
