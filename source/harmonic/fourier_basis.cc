#include <rotorfit/harmonic/fourier_basis.h>

#include <cmath>

namespace rotorfit
{
  using namespace dealii;

  FourierBasis::FourierBasis(const unsigned int n)
    : n(n)
  {
    if (n == 0)
      set_angles({0.});
    else
      set_angles({0., M_PI / (2. * n)});
  }

  FourierBasis::FourierBasis(const unsigned int n, const FourierBasis &other)
    : n(n)
  {
    std::vector<double> theta;
    for (unsigned int m = 0; m < other.n_theta; ++m)
      theta.push_back(std::atan2(other.sin_t[m], other.cos_t[m]));
    set_angles(theta);
  }

  void
  FourierBasis::set_angles(const std::vector<double> &theta)
  {
    n_theta = theta.size();
    weight  = 2 * M_PI / n_theta;
    cos_t.clear();
    sin_t.clear();
    cos_nt.clear();
    sin_nt.clear();
    for (const double t : theta)
      {
        cos_t.push_back(std::cos(t));
        sin_t.push_back(std::sin(t));
        cos_nt.push_back(std::cos(n * t));
        sin_nt.push_back(std::sin(n * t));
      }
  }

  void
  FourierBasis::factors(const unsigned int k,
                        const unsigned int m,
                        double            &g,
                        double            &dg,
                        Tensor<1, 3>      &dir,
                        Tensor<1, 3>      &d_dir) const
  {
    const double cn = cos_nt[m], sn = sin_nt[m];
    switch (k)
      {
        case a:
        case e:
        case c:
          g  = cn;
          dg = -(double)n * sn;
          break;
        case d:
          g  = -sn;
          dg = -(double)n * cn;
          break;
        default: // b, f
          g  = sn;
          dg = (double)n * cn;
      }
    const Tensor<1, 3> e_r({cos_t[m], sin_t[m], 0.}), e_t({-sin_t[m], cos_t[m], 0.}),
      e_z({0., 0., 1.});
    switch (k)
      {
        case a:
        case b:
          dir   = e_r;
          d_dir = e_t;
          break;
        case d:
        case c:
          dir   = e_t;
          d_dir = -e_r;
          break;
        default:
          dir   = e_z;
          d_dir = Tensor<1, 3>();
      }
  }

  void
  FourierBasis::evaluate(const unsigned int  k,
                         const double        N,
                         const Tensor<1, 2> &dN,
                         const double        r,
                         const unsigned int  m,
                         Sample             &s) const
  {
    double       g, dg;
    Tensor<1, 3> dir, d_dir;
    factors(k, m, g, dg, dir, d_dir);
    s.value   = N * g * dir;
    s.d_theta = N * (dg * dir + g * d_dir);
    const Tensor<1, 3> d_r = dN[0] * g * dir, d_z = dN[1] * g * dir;
    // d/dx = cos d/dr - sin/r d/dtheta, d/dy = sin d/dr + cos/r d/dtheta
    const Tensor<1, 3> d_x = cos_t[m] * d_r - sin_t[m] / r * s.d_theta;
    const Tensor<1, 3> d_y = sin_t[m] * d_r + cos_t[m] / r * s.d_theta;
    for (unsigned int i = 0; i < 3; ++i)
      {
        s.grad[i][0] = d_x[i];
        s.grad[i][1] = d_y[i];
        s.grad[i][2] = d_z[i];
      }
  }

  Tensor<1, 3>
  FourierBasis::value(const unsigned int k, const double N, const unsigned int m) const
  {
    double       g, dg;
    Tensor<1, 3> dir, d_dir;
    factors(k, m, g, dg, dir, d_dir);
    return N * g * dir;
  }

  std::string
  FourierBasis::name(const unsigned int k)
  {
    static const char *names[] = {"a", "d", "e", "b", "c", "f"};
    return names[k];
  }
} // namespace rotorfit
