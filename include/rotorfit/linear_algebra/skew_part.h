#pragma once

#include <deal.II/lac/full_matrix.h>

namespace rotorfit
{
  /// Keep only the skew part of a cell's gyroscopic matrix, G <- (G - G^T) / 2:
  /// the continuum G is skew (doc/theory.md 4.3); a boundary with t . n != 0
  /// (faceted) or the quadrature leaves a symmetric part that would act as
  /// damping of either sign (P4).
  inline void
  keep_skew_part(dealii::FullMatrix<double> &g)
  {
    for (unsigned int i = 0; i < g.m(); ++i)
      {
        for (unsigned int j = 0; j < i; ++j)
          {
            const double skew = 0.5 * (g(i, j) - g(j, i));
            g(i, j)           = skew;
            g(j, i)           = -skew;
          }
        g(i, i) = 0;
      }
  }
} // namespace rotorfit
