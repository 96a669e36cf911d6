#include <rotorfit/linear_algebra/blas.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#include <algorithm>

// Products and back-substitutions of blocks of replicated columns (every
// rank holds whole vectors; the matrices and factors are distributed).

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// Column j of the distributed dense @p Y (its local rows) gathered on
    /// every rank into out(j), a full-length column.
    template <typename Out>
    void
    gather_columns(Mat Y, const PetscInt n_local, const PetscInt columns, const MPI_Comm comm,
                   const Out &out)
    {
      const unsigned int ranks = Utilities::MPI::n_mpi_processes(comm);
      std::vector<int>   counts(ranks), displs(ranks);
      const int          local = n_local;
      MPI_Allgather(&local, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
      for (unsigned int r = 1; r < ranks; ++r)
        displs[r] = displs[r - 1] + counts[r - 1];
      const PetscScalar *a;
      PetscInt           ld;
      MatDenseGetLDA(Y, &ld);
      MatDenseGetArrayRead(Y, &a);
      for (PetscInt j = 0; j < columns; ++j)
        MPI_Allgatherv(a + j * ld, local, MPI_DOUBLE, out(j), counts.data(), displs.data(),
                       MPI_DOUBLE, comm);
      MatDenseRestoreArrayRead(Y, &a);
    }
  } // namespace

  void
  replicated_mmult(const PETScWrappers::MPI::SparseMatrix &A,
                   const double                           *x,
                   const unsigned int                      m,
                   double                                 *y)
  {
    // PETSc's sequential AIJ x dense product reads A once for four columns
    // (TS: 3.1 ms per column against 12 ms per sparse product); its MPI
    // product goes column by column. So each rank multiplies its diagonal
    // and off-diagonal blocks by the rows of the replicated columns they
    // need, and the rows are gathered.
    if (m == 0)
      return;
    const auto     range   = A.local_range();
    const PetscInt n_local = range.second - range.first, n = A.m(), columns = m;
    const MPI_Comm comm    = A.get_mpi_communicator();
    const auto     ok      = [](const PetscErrorCode code) {
      AssertThrow(code == 0, ExcMessage("PETSc sparse x dense product failed"));
    };
    Mat            Ad, Ao;
    const PetscInt *colmap;
    ok(MatMPIAIJGetSeqAIJ(A, &Ad, &Ao, &colmap));
    PetscInt n_ghost;
    ok(MatGetSize(Ao, nullptr, &n_ghost));
    // (decided by the communicator, the same on every rank: the other path
    // ends in a collective gather)
    if (Utilities::MPI::n_mpi_processes(comm) == 1)
      {
        // one rank: the columns are the dense operands as they lie (leading
        // dimension n), so nothing is copied, allocated or zeroed (fresh
        // blocks of tens of MB cost their page faults at every product)
        Mat X, Y;
        ok(MatCreateSeqDense(PETSC_COMM_SELF, n, columns, const_cast<double *>(x), &X));
        ok(MatCreateSeqDense(PETSC_COMM_SELF, n, columns, y, &Y));
        ok(MatProductCreateWithMat(Ad, X, nullptr, Y));
        ok(MatProductSetType(Y, MATPRODUCT_AB));
        ok(MatProductSetFromOptions(Y));
        ok(MatProductSymbolic(Y));
        ok(MatProductNumeric(Y));
        ok(MatDestroy(&X));
        ok(MatDestroy(&Y));
        return;
      }
    // rows of X: the local ones for Ad, the ghost ones (colmap) for Ao
    const auto dense = [&](const PetscInt rows, const auto &row_of) {
      Mat          X;
      PetscScalar *a;
      ok(MatCreateSeqDense(PETSC_COMM_SELF, rows, columns, nullptr, &X));
      ok(MatDenseGetArray(X, &a));
      for (PetscInt j = 0; j < columns; ++j)
        for (PetscInt i = 0; i < rows; ++i)
          a[j * rows + i] = x[j * n + row_of(i)];
      ok(MatDenseRestoreArray(X, &a));
      ok(MatAssemblyBegin(X, MAT_FINAL_ASSEMBLY));
      ok(MatAssemblyEnd(X, MAT_FINAL_ASSEMBLY));
      return X;
    };
    Mat Xd = dense(n_local, [&](const PetscInt i) { return range.first + i; });
    Mat Yd;
    ok(MatMatMult(Ad, Xd, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &Yd));
    if (n_ghost > 0)
      {
        Mat Xo = dense(n_ghost, [&](const PetscInt i) { return colmap[i]; });
        Mat Yo;
        ok(MatMatMult(Ao, Xo, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &Yo));
        ok(MatAXPY(Yd, 1., Yo, SAME_NONZERO_PATTERN));
        ok(MatDestroy(&Xo));
        ok(MatDestroy(&Yo));
      }
    gather_columns(Yd, n_local, columns, comm, [&](const PetscInt j) { return y + j * n; });
    ok(MatDestroy(&Xd));
    ok(MatDestroy(&Yd));
  }

  void
  replicated_mmult(const PETScWrappers::MPI::SparseMatrix    &A,
                   const std::vector<const Vector<double> *> &x,
                   std::vector<Vector<double>>               &y)
  {
    const std::size_t   n = A.m();
    std::vector<double> flat(n * x.size()), out(n * x.size());
    for (std::size_t j = 0; j < x.size(); ++j)
      std::copy(x[j]->begin(), x[j]->end(), flat.begin() + j * n);
    replicated_mmult(A, flat.data(), x.size(), out.data());
    y.assign(x.size(), Vector<double>(n));
    for (std::size_t j = 0; j < x.size(); ++j)
      std::copy(out.begin() + j * n, out.begin() + (j + 1) * n, y[j].begin());
  }

  namespace
  {
    /// X = A^-1 B for @p m replicated columns: in(j) points at column j of
    /// B, out(j) at column j of X (full length); one MUMPS pass over the
    /// factors for the whole block.
    template <typename In, typename Out>
    void
    solve_columns(const DirectSolver                     &solver,
                  const PETScWrappers::MPI::SparseMatrix &layout,
                  const PetscInt                          m,
                  const In                               &in,
                  const Out                              &out)
    {
      if (m == 0)
        return;
      const auto     range   = layout.local_range();
      const PetscInt n_local = range.second - range.first, n = layout.m();
      const MPI_Comm comm    = layout.get_mpi_communicator();
      Mat            B, X;
      // one rank (the same decision on every rank), columns one after another
      bool flat = Utilities::MPI::n_mpi_processes(comm) == 1;
      for (PetscInt j = 1; j < m && flat; ++j)
        flat = in(j) == in(0) + j * n && out(j) == out(0) + j * n;
      if (flat)
        {
          // the arrays as they lie: nothing allocated, zeroed or copied
          MatCreateDense(comm, n, PETSC_DECIDE, n, m, const_cast<double *>(in(0)), &B);
          MatCreateDense(comm, n, PETSC_DECIDE, n, m, out(0), &X);
          solver.solve(X, B);
          MatDestroy(&B);
          MatDestroy(&X);
          return;
        }
      MatCreateDense(comm, n_local, PETSC_DECIDE, n, m, nullptr, &B);
      MatCreateDense(comm, n_local, PETSC_DECIDE, n, m, nullptr, &X);
      PetscScalar *a;
      PetscInt     ld;
      MatDenseGetLDA(B, &ld);
      MatDenseGetArray(B, &a);
      for (PetscInt j = 0; j < m; ++j)
        std::copy(in(j) + range.first, in(j) + range.second, a + j * ld);
      MatDenseRestoreArray(B, &a);
      MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY);
      MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY);
      solver.solve(X, B);
      gather_columns(X, n_local, m, comm, out);
      MatDestroy(&B);
      MatDestroy(&X);
    }
  } // namespace

  void
  replicated_solve(const DirectSolver                     &solver,
                   const PETScWrappers::MPI::SparseMatrix &layout,
                   const double                           *b,
                   const unsigned int                      m,
                   double                                 *x)
  {
    const std::size_t n = layout.m();
    solve_columns(
      solver, layout, m, [&](const PetscInt j) { return b + j * n; },
      [&](const PetscInt j) { return x + j * n; });
  }

  void
  replicated_solve(const DirectSolver                          &solver,
                   const PETScWrappers::MPI::SparseMatrix      &layout,
                   const std::vector<const Vector<double> *>   &b,
                   std::vector<Vector<double>>                 &x)
  {
    x.assign(b.size(), Vector<double>(layout.m()));
    solve_columns(
      solver, layout, b.size(), [&](const PetscInt j) { return b[j]->data(); },
      [&](const PetscInt j) { return x[j].data(); });
  }

  namespace
  {
    /// X = A^-1 of the columns first .. first + c - 1 of @p P (kept by its
    /// rows), given to MUMPS as sparse right-hand sides: it skips the zeros
    /// of the forward substitution. One rank (DirectSolver::solve_sparse).
    void
    solve_kept_rows(const DirectSolver &solver,
                    const MPI_Comm      comm,
                    const RowBlock     &P,
                    const std::size_t   first,
                    const int           c,
                    double             *X)
    {
      const PetscInt               n = P.size(), r = P.n_rows();
      const auto                  &rows = P.kept_rows();
      std::vector<PetscInt>        columns(rows.begin(), rows.end());
      const std::vector<PetscInt>  nonzeros(c, r);
      Mat                          Bt, Y;
      const auto check = [](const PetscErrorCode code) {
        AssertThrow(code == 0, ExcMessage("PETSc failed on the sparse right-hand sides"));
      };
      check(MatCreateSeqAIJ(comm, c, n, 0, nonzeros.data(), &Bt));
      for (PetscInt j = 0; j < c; ++j)
        check(MatSetValues(Bt, 1, &j, r, columns.data(), P.data().data() + (first + j) * r,
                           INSERT_VALUES));
      check(MatAssemblyBegin(Bt, MAT_FINAL_ASSEMBLY));
      check(MatAssemblyEnd(Bt, MAT_FINAL_ASSEMBLY));
      check(MatCreateDense(comm, n, PETSC_DECIDE, n, c, X, &Y));
      solver.solve_sparse(Y, Bt);
      MatDestroy(&Bt);
      MatDestroy(&Y);
    }
  } // namespace

  namespace
  {
    /// The columns of the blocks P_1 .. P_b in one numbering: block k holds
    /// columns first[k] .. first[k + 1] - 1.
    struct ColumnNumbering
    {
      explicit ColumnNumbering(const std::vector<const RowBlock *> &blocks)
      {
        for (const auto *P : blocks)
          first.push_back(first.back() + P->n_columns());
      }

      /// all columns
      int
      size() const
      {
        return first.back();
      }

      /// the block of column @p j
      std::ptrdiff_t
      block_of(const int j) const
      {
        return std::upper_bound(first.begin(), first.end(), j) - first.begin() - 1;
      }

      std::vector<int> first{0};
    };

    /// replicated_inverse_gram(): blocks of right-hand sides (a block's
    /// back-substitution costs about a sixth of as many single ones on
    /// TS), each multiplied by every block. A chunk holds columns of either
    /// kind: those of a block kept by its rows go to MUMPS as sparse
    /// right-hand sides on one rank (no n-long copies), else expanded to n
    /// a few at a time.
    class InverseGram
    {
    public:
      InverseGram(const DirectSolver                     &solver,
                  const PETScWrappers::MPI::SparseMatrix &layout,
                  const std::vector<const RowBlock *>    &blocks,
                  const GramShortcut                     *shortcut);

      /// G, the same on every rank
      std::vector<double>
      compute();

    private:
      /// the columns of the chunk from @p start: of one kind, and sparse
      /// ones of one block
      int
      chunk_size(const int start) const;
      /// A^-1 of the chunk's sparse columns into X (one rank), or the
      /// columns expanded to n for solve_columns()
      void
      prepare_sparse(const int start, const int c);
      /// column @p j (full length) of the chunk from @p start
      const double *
      column(const int start, const int j) const;
      /// X = A^-1 of the chunk's columns @p solved (chunk positions)
      void
      solve(const int start, const std::vector<int> &solved);
      /// the shortcut's source columns kept, its target columns made
      void
      apply_shortcut(const int start, const std::vector<int> &solved, const std::vector<int> &known);
      /// G's columns start .. start + c - 1: every block's P_k^T X
      void
      multiply(const int start, const int c);

      bool
      sparse(const int j) const
      {
        return !blocks[numbering.block_of(j)]->dense();
      }

      const DirectSolver                     &solver;
      const PETScWrappers::MPI::SparseMatrix &layout;
      const std::vector<const RowBlock *>    &blocks;
      const GramShortcut                     *shortcut;
      const ColumnNumbering                   numbering;
      const int                               n, b;
      const bool                              one_rank;
      const int                               sparse_chunk;
      bool                                    use_shortcut;
      std::vector<double>                     G, X, expanded, rows_of_x;
      std::vector<double>                     kept_source; // A^-1 P_source, for the target's columns
      static constexpr int                    chunk = 32;
    };

    InverseGram::InverseGram(const DirectSolver                     &solver,
                             const PETScWrappers::MPI::SparseMatrix &layout,
                             const std::vector<const RowBlock *>    &blocks,
                             const GramShortcut                     *shortcut)
      : solver(solver)
      , layout(layout)
      , blocks(blocks)
      , shortcut(shortcut)
      , numbering(blocks)
      , n(layout.m())
      , b(numbering.size())
      , one_rank(Utilities::MPI::n_mpi_processes(layout.get_mpi_communicator()) == 1)
      , sparse_chunk(one_rank ? chunk : 8)
      , G(std::size_t(b) * b, 0.)
    {
      const auto &first = numbering.first;
      use_shortcut      = shortcut && shortcut->source < shortcut->target &&
                     shortcut->target < blocks.size() &&
                     first[shortcut->source + 1] - first[shortcut->source] ==
                       first[shortcut->target + 1] - first[shortcut->target] &&
                     blocks[shortcut->target]->dense() &&
                     shortcut->base->size() == blocks[shortcut->target]->data().size();
      if (use_shortcut)
        kept_source.resize(std::size_t(n) *
                           (first[shortcut->source + 1] - first[shortcut->source]));
    }

    std::vector<double>
    InverseGram::compute()
    {
      for (int start = 0, c = 0; start < b; start += c)
        {
          c = chunk_size(start);
          X.resize(std::size_t(n) * c);
          prepare_sparse(start, c);
          std::vector<int> solved, known;
          for (int j = 0; j < c; ++j)
            (use_shortcut && std::size_t(numbering.block_of(start + j)) == shortcut->target ?
               known :
               solved)
              .push_back(j);
          if (!(sparse(start) && one_rank))
            solve(start, solved);
          apply_shortcut(start, solved, known);
          multiply(start, c);
        }
      // every rank takes the same decisions from it
      MPI_Bcast(G.data(), G.size(), MPI_DOUBLE, 0, layout.get_mpi_communicator());
      return std::move(G);
    }

    int
    InverseGram::chunk_size(const int start) const
    {
      int c = std::min(chunk, b - start);
      if (sparse(start))
        c = std::min({sparse_chunk, c, numbering.first[numbering.block_of(start) + 1] - start});
      else
        for (int j = start + 1; j < start + c; ++j)
          if (sparse(j))
            return j - start;
      return c;
    }

    void
    InverseGram::prepare_sparse(const int start, const int c)
    {
      if (!sparse(start))
        return;
      const auto k = numbering.block_of(start);
      if (one_rank)
        solve_kept_rows(solver, layout.get_mpi_communicator(), *blocks[k],
                        start - numbering.first[k], c, X.data());
      else
        {
          expanded.resize(std::size_t(n) * c);
          for (int j = 0; j < c; ++j)
            blocks[k]->expand_column(start + j - numbering.first[k],
                                     expanded.data() + std::size_t(j) * n);
        }
    }

    const double *
    InverseGram::column(const int start, const int j) const
    {
      const auto k = numbering.block_of(j);
      return sparse(j) ? expanded.data() + std::size_t(j - start) * n :
                         blocks[k]->data().data() + std::size_t(j - numbering.first[k]) * n;
    }

    void
    InverseGram::solve(const int start, const std::vector<int> &solved)
    {
      solve_columns(
        solver, layout, solved.size(),
        [&](const PetscInt i) { return column(start, start + solved[i]); },
        [&](const PetscInt i) { return X.data() + std::size_t(solved[i]) * n; });
    }

    void
    InverseGram::apply_shortcut(const int               start,
                                const std::vector<int> &solved,
                                const std::vector<int> &known)
    {
      if (!use_shortcut)
        return;
      // (the source columns of this chunk first: they may be needed in it)
      const auto &first = numbering.first;
      for (const int j : solved)
        if (std::size_t(numbering.block_of(start + j)) == shortcut->source)
          std::copy(X.begin() + std::size_t(j) * n, X.begin() + std::size_t(j + 1) * n,
                    kept_source.begin() + std::size_t(start + j - first[shortcut->source]) * n);
      for (const int j : known)
        {
          const std::size_t i    = start + j - first[shortcut->target];
          const double     *base = shortcut->base->data() + i * n,
                       *source     = kept_source.data() + i * n;
          double *x                = X.data() + std::size_t(j) * n;
          for (int r = 0; r < n; ++r)
            x[r] = base[r] + shortcut->factor * source[r];
        }
    }

    void
    InverseGram::multiply(const int start, const int c)
    {
      const auto  &first = numbering.first;
      const double one = 1, zero = 0;
      for (std::size_t k = 0; k < blocks.size(); ++k)
        {
          const int columns = first[k + 1] - first[k], r = blocks[k]->n_rows();
          if (columns == 0)
            continue;
          blocks[k]->gather(X.data(), c, rows_of_x);
          dgemm_("T", "N", &columns, &c, &r, &one, blocks[k]->data().data(), &r,
                 blocks[k]->dense() ? X.data() : rows_of_x.data(), &r, &zero,
                 G.data() + first[k] + std::size_t(start) * b, &b);
        }
    }
  } // namespace

  std::vector<double>
  replicated_inverse_gram(const DirectSolver                     &solver,
                          const PETScWrappers::MPI::SparseMatrix &layout,
                          const std::vector<const RowBlock *>    &blocks,
                          const GramShortcut                     *shortcut)
  {
    return InverseGram(solver, layout, blocks, shortcut).compute();
  }

  std::vector<double>
  replicated_gram(const std::vector<const RowBlock *> &blocks, const MPI_Comm comm)
  {
    const ColumnNumbering numbering(blocks);
    const auto           &first = numbering.first;
    const int             b     = numbering.size();
    std::vector<double> G(std::size_t(b) * b, 0.), rows_of_other;
    const double        one = 1, zero = 0;
    for (std::size_t k = 0; k < blocks.size(); ++k)
      for (std::size_t l = k; l < blocks.size(); ++l)
        {
          const int mk = first[k + 1] - first[k], ml = first[l + 1] - first[l];
          if (mk == 0 || ml == 0)
            continue;
          // over the rows of the block that keeps fewer (the other's rows
          // there; zero where it keeps none): P_k^T P_l = P_l^T P_k ^T
          const bool own_rows = blocks[k]->n_rows() <= blocks[l]->n_rows();
          const RowBlock &a = own_rows ? *blocks[k] : *blocks[l],
                         &o = own_rows ? *blocks[l] : *blocks[k];
          const int       r = a.n_rows();
          const double   *other = o.data().data();
          if (!(a.dense() && o.dense()) && a.kept_rows() != o.kept_rows())
            {
              a.rows_of(o, rows_of_other);
              other = rows_of_other.data();
            }
          if (own_rows)
            dgemm_("T", "N", &mk, &ml, &r, &one, a.data().data(), &r, other, &r, &zero,
                   G.data() + first[k] + std::size_t(first[l]) * b, &b);
          else
            dgemm_("T", "N", &mk, &ml, &r, &one, other, &r, a.data().data(), &r, &zero,
                   G.data() + first[k] + std::size_t(first[l]) * b, &b);
        }
    for (int j = 0; j < b; ++j) // the lower triangle from the upper
      for (int i = j + 1; i < b; ++i)
        G[i + std::size_t(j) * b] = G[j + std::size_t(i) * b];
    MPI_Bcast(G.data(), G.size(), MPI_DOUBLE, 0, comm);
    return G;
  }

  double
  inverse_norm_sqr(const std::vector<double> &G, const std::vector<std::complex<double>> &x)
  {
    // x^H G x = re^T G re + im^T G im + i (re^T G im - im^T G re); the
    // imaginary part is rounding for a symmetric factorisation, not for
    // an LU of Q(sigma)
    const int           b = x.size();
    std::vector<double> parts(2 * std::size_t(b)), Gp(2 * std::size_t(b));
    for (int i = 0; i < b; ++i)
      parts[i] = x[i].real(), parts[b + i] = x[i].imag();
    const double one = 1, zero = 0;
    const int    two = 2;
    dgemm_("N", "N", &b, &two, &b, &one, G.data(), &b, parts.data(), &b, &zero, Gp.data(), &b);
    double re = 0, im = 0;
    for (int i = 0; i < b; ++i)
      {
        re += parts[i] * Gp[i] + parts[b + i] * Gp[b + i];
        im += parts[i] * Gp[b + i] - parts[b + i] * Gp[i];
      }
    return std::abs(std::complex<double>(re, im));
  }

} // namespace rotorfit
