#pragma once

#include <deal.II/base/symmetric_tensor.h>

#include <deal.II/fe/fe_values.h>

#include <deal.II/lac/full_matrix.h>

#include <vector>

namespace rotorfit
{
  /**
   * Adds the isotropic linear-elastic stiffness at quadrature point @p q,
   * (lambda div phi_i div phi_j + 2 mu eps(phi_i) : eps(phi_j)) JxW, to
   * @p cell_matrix (doc/theory.md 1). The one kernel of the static and the dynamic
   * stiffness. @p eps is scratch space of the cell's size.
   */
  void
  add_elastic_stiffness(const dealii::FEValues<3>                      &fe_values,
                        const unsigned int                              q,
                        const double                                    lambda,
                        const double                                    mu,
                        dealii::FullMatrix<double>                     &cell_matrix,
                        std::vector<dealii::SymmetricTensor<2, 3>>     &eps);
} // namespace rotorfit
