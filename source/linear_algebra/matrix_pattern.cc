#include <rotorfit/linear_algebra/matrix_pattern.h>

#include <petscmat.h>

#include <stdexcept>
#include <string>

namespace rotorfit
{
  namespace
  {
    void
    ok(const PetscErrorCode code, const char *what)
    {
      if (code != 0)
        throw std::runtime_error(std::string("PETSc error in ") + what + " (add_subset)");
    }

    /// One sequential AIJ block: Y += a X, the columns of each read through
    /// its map to global numbers (nullptr: its own numbers).
    void
    add_block(Mat Y, const double a, Mat X, const PetscInt *map_y, const PetscInt *map_x)
    {
      PetscInt        ny = 0, nx = 0;
      const PetscInt *iy = nullptr, *jy = nullptr, *ix = nullptr, *jx = nullptr;
      PetscBool       done_y = PETSC_FALSE, done_x = PETSC_FALSE;
      ok(MatGetRowIJ(Y, 0, PETSC_FALSE, PETSC_FALSE, &ny, &iy, &jy, &done_y), "MatGetRowIJ");
      ok(MatGetRowIJ(X, 0, PETSC_FALSE, PETSC_FALSE, &nx, &ix, &jx, &done_x), "MatGetRowIJ");
      PetscScalar       *vy = nullptr;
      const PetscScalar *vx = nullptr;
      ok(MatSeqAIJGetArray(Y, &vy), "MatSeqAIJGetArray");
      ok(MatSeqAIJGetArrayRead(X, &vx), "MatSeqAIJGetArrayRead");
      PetscInt missing = -1;
      if (!done_y || !done_x || nx != ny)
        missing = 0;
      else
        for (PetscInt r = 0; r < nx && missing < 0; ++r)
          {
            PetscInt k = iy[r];
            for (PetscInt p = ix[r]; p < ix[r + 1]; ++p)
              {
                const PetscInt col = map_x ? map_x[jx[p]] : jx[p];
                while (k < iy[r + 1] && (map_y ? map_y[jy[k]] : jy[k]) < col)
                  ++k;
                if (k == iy[r + 1] || (map_y ? map_y[jy[k]] : jy[k]) != col)
                  {
                    missing = r;
                    break;
                  }
                vy[k] += a * vx[p];
              }
          }
      ok(MatSeqAIJRestoreArrayRead(X, &vx), "MatSeqAIJRestoreArrayRead");
      ok(MatSeqAIJRestoreArray(Y, &vy), "MatSeqAIJRestoreArray");
      ok(MatRestoreRowIJ(X, 0, PETSC_FALSE, PETSC_FALSE, &nx, &ix, &jx, &done_x), "MatRestoreRowIJ");
      ok(MatRestoreRowIJ(Y, 0, PETSC_FALSE, PETSC_FALSE, &ny, &iy, &jy, &done_y), "MatRestoreRowIJ");
      if (missing >= 0)
        throw std::logic_error("add_subset: the pattern of the added matrix is not a subset of "
                               "the target's (local row " + std::to_string(missing) + ")");
    }
  } // namespace

  void
  add_subset(Mat Y, const double a, Mat X)
  {
    PetscBool seq = PETSC_FALSE;
    ok(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(Y), MATSEQAIJ, &seq),
       "PetscObjectTypeCompare");
    if (seq)
      add_block(Y, a, X, nullptr, nullptr);
    else
      {
        Mat             yd, yo, xd, xo;
        const PetscInt *gy = nullptr, *gx = nullptr;
        ok(MatMPIAIJGetSeqAIJ(Y, &yd, &yo, &gy), "MatMPIAIJGetSeqAIJ");
        ok(MatMPIAIJGetSeqAIJ(X, &xd, &xo, &gx), "MatMPIAIJGetSeqAIJ");
        add_block(yd, a, xd, nullptr, nullptr);
        add_block(yo, a, xo, gy, gx);
      }
    // (MatSeqAIJRestoreArray marks each block as changed; factorisations
    // and products read the blocks)
  }
} // namespace rotorfit
