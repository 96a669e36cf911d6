#pragma once

#include <deal.II/base/tensor.h>

#include <array>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * The six real fields of Fourier harmonic n of the displacement about the
   * spin axis (doc/theory.md 14.1), in cylindrical components (r, t, z):
   *
   *     u_r = a cos n theta + b sin n theta
   *     u_t = -d sin n theta + c cos n theta
   *     u_z = e cos n theta + f sin n theta
   *
   * Field k of a meridian shape function N(r, z) is the 3D vector field
   * phi = N g_k(theta) e_k(theta). The signs are chosen so that a rigid
   * lateral translation (X, Y) is a = d = X, b = c = Y: the cos set (a, d, e)
   * moves along x, the sin set (b, c, f) along y, and every 3D bilinear form
   * of doc/theory.md 1-5 is evaluated on these fields as it stands, in
   * Cartesian components, with the angle integral done by the trapezoidal
   * rule on angles() (exact: every integrand is a trigonometric polynomial
   * of degree at most 2n + 4).
   */
  class FourierBasis
  {
  public:
    /// The fields, in the component order of the meridian's FESystem.
    enum Field : unsigned int
    {
      a = 0, ///< u_r cos
      d = 1, ///< u_t -sin
      e = 2, ///< u_z cos
      b = 3, ///< u_r sin
      c = 4, ///< u_t cos
      f = 5  ///< u_z sin
    };
    static constexpr unsigned int n_fields = 6;

    /// Harmonic @p n on its angle rule (one point for n = 0, two for n >= 1).
    explicit FourierBasis(const unsigned int n);

    /// Harmonic @p n on the angle points of @p other (for the static
    /// field, harmonic 0, inside another harmonic's integrals).
    FourierBasis(const unsigned int n, const FourierBasis &other);

    unsigned int
    harmonic() const
    {
      return n;
    }

    /// Field @p k is not identically zero: for n = 0 only a, c, e (sin 0 = 0).
    bool
    active(const unsigned int k) const
    {
      return n > 0 || k == a || k == c || k == e;
    }

    /// Points of the angle rule and its weight 2 pi / N.
    unsigned int
    n_angles() const
    {
      return n_theta;
    }
    double
    angle_weight() const
    {
      return weight;
    }

    /// phi, its angle derivative at fixed (r, z) and its Cartesian gradient
    /// (grad[i][j] = d phi_i / d x_j) at angle point @p m.
    struct Sample
    {
      dealii::Tensor<1, 3> value, d_theta;
      dealii::Tensor<2, 3> grad;
    };

    /// Field @p k of the shape function with value @p N and gradient
    /// (dN/dr, dN/dz) = @p dN at radius @p r > 0 and angle point @p m.
    void
    evaluate(const unsigned int          k,
             const double                N,
             const dealii::Tensor<1, 2> &dN,
             const double                r,
             const unsigned int          m,
             Sample                     &s) const;

    /// Only the value (no radius needed: also on the axis).
    dealii::Tensor<1, 3>
    value(const unsigned int k, const double N, const unsigned int m) const;

    /// "a" ... "f".
    static std::string
    name(const unsigned int k);

  private:
    void
    set_angles(const std::vector<double> &theta);

    /// g_k and g_k' at angle point m, the direction e_k and d e_k / d theta.
    void
    factors(const unsigned int    k,
            const unsigned int    m,
            double               &g,
            double               &dg,
            dealii::Tensor<1, 3> &dir,
            dealii::Tensor<1, 3> &d_dir) const;

    unsigned int        n;
    unsigned int        n_theta;
    double              weight;
    std::vector<double> cos_t, sin_t, cos_nt, sin_nt;
  };
} // namespace rotorfit
