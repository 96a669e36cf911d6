#pragma once

#include <deal.II/lac/vector.h>

#include <vector>

namespace rotorfit
{
  /// A complex vector as two real ones (replicated on every rank).
  struct ComplexVector
  {
    dealii::Vector<double> re, im; ///< real and imaginary parts
  };

  /// Pointers to each of @p list (the output columns of a block product).
  inline std::vector<ComplexVector *>
  column_pointers(std::vector<ComplexVector> &list)
  {
    std::vector<ComplexVector *> z;
    for (auto &x : list)
      z.push_back(&x);
    return z;
  }
} // namespace rotorfit
