#include <rotorfit/material/elasticity.h>

namespace rotorfit
{
  using namespace dealii;

  void
  add_elastic_stiffness(const FEValues<3>                  &fe_values,
                        const unsigned int                  q,
                        const double                        lambda,
                        const double                        mu,
                        FullMatrix<double>                 &cell_matrix,
                        std::vector<SymmetricTensor<2, 3>> &eps)
  {
    const FEValuesExtractors::Vector disp(0);
    const unsigned int               n   = cell_matrix.m();
    const double                     JxW = fe_values.JxW(q);
    eps.resize(n);
    for (unsigned int i = 0; i < n; ++i)
      eps[i] = fe_values[disp].symmetric_gradient(i, q);
    for (unsigned int i = 0; i < n; ++i)
      {
        const double div_i = trace(eps[i]);
        for (unsigned int j = 0; j <= i; ++j)
          {
            const double k =
              (lambda * div_i * trace(eps[j]) + 2 * mu * scalar_product(eps[i], eps[j])) * JxW;
            cell_matrix(i, j) += k;
            if (j != i)
              cell_matrix(j, i) += k;
          }
      }
  }
} // namespace rotorfit
