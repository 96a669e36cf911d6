#pragma once

// The Fortran BLAS / LAPACK routines the dense algebra calls directly
// (OpenBLAS at run time): the contact path's pair space and the reduced
// eigenproblem. deal.II 9.4's LAPACKFullMatrix returns no eigenvectors.
extern "C"
{
  void
  dgemv_(const char *, const int *, const int *, const double *, const double *, const int *,
         const double *, const int *, const double *, double *, const int *);
  void
  dger_(const int *, const int *, const double *, const double *, const int *, const double *,
        const int *, double *, const int *);
  void
  dgemm_(const char *, const char *, const int *, const int *, const int *, const double *,
         const double *, const int *, const double *, const int *, const double *, double *,
         const int *);
  void
  dgetrf_(const int *, const int *, double *, const int *, int *, int *);
  void
  dgetrs_(const char *, const int *, const int *, const double *, const int *, const int *,
          double *, const int *, int *);
  void
  dgeev_(const char *, const char *, const int *, double *, const int *, double *, double *,
         double *, const int *, double *, const int *, double *, const int *, int *);
}
