#include <rotorfit/contact/low_rank_update.h>

#include <deal.II/lac/vector.h>

namespace rotorfit
{
  using namespace dealii;

  bool
  LowRankUpdate::reinit(const std::vector<unsigned int>        &changed,
                        const std::vector<double>              &springs,
                        const std::vector<std::vector<double>> &column)
  {
    d = changed;
    s = springs;
    const unsigned int m = d.size();
    capacitance.reinit(m, m);
    for (unsigned int a = 0; a < m; ++a)
      {
        for (unsigned int b = 0; b < m; ++b)
          capacitance(a, b) = column[d[b]][d[a]];
        capacitance(a, a) += 1. / s[a];
      }
    if (m > 0)
      try
        {
          capacitance.compute_lu_factorization();
        }
      catch (...)
        {
          clear(); // singular: the caller factorises K_A instead
          return false;
        }
    return true;
  }

  void
  LowRankUpdate::clear()
  {
    d.clear();
    s.clear();
    capacitance.reinit(0, 0);
  }

  std::vector<double>
  LowRankUpdate::apply(std::vector<double>                    &t,
                       const std::vector<std::vector<double>> &column) const
  {
    const unsigned int  m = d.size();
    std::vector<double> c(m);
    if (m == 0)
      return c;
    Vector<double> rhs(m);
    for (unsigned int a = 0; a < m; ++a)
      rhs[a] = t[d[a]];
    capacitance.solve(rhs);
    for (unsigned int a = 0; a < m; ++a)
      {
        c[a]          = rhs[a];
        const auto &f = column[d[a]];
        for (unsigned int i = 0; i < t.size(); ++i)
          t[i] -= f[i] * c[a];
      }
    return c;
  }
} // namespace rotorfit
