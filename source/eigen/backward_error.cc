#include <rotorfit/eigen/backward_error.h>
#include <rotorfit/linear_algebra/replicated_vectors.h>

#include <cmath>
#include <limits>
#include <utility>

namespace rotorfit
{
  using namespace dealii;

  BackwardError::BackwardError(const PETScWrappers::MPI::SparseMatrix &M,
                               const PETScWrappers::MPI::SparseMatrix &C,
                               const PETScWrappers::MPI::SparseMatrix &K)
    : M(M)
    , C(C)
    , K(K)
    , norm_M(M.frobenius_norm())
    , norm_C(C.frobenius_norm())
    , norm_K(K.frobenius_norm())
  {}

  double
  BackwardError::operator()(const std::complex<double> l,
                            const ComplexVector       &phi,
                            ComplexVector             &Mp,
                            ComplexVector             *residual,
                            std::complex<double>      *derivative) const
  {
    ComplexVector Cp, Kp;
    replicated_vmult(M, phi, Mp);
    replicated_vmult(C, phi, Cp);
    replicated_vmult(K, phi, Kp);
    return (*this)(l, phi, Mp, Cp, Kp, residual, derivative);
  }

  double
  BackwardError::from_residual(const std::complex<double> l,
                               const ComplexVector       &phi,
                               const ComplexVector       &r) const
  {
    return relative(l, phi, std::sqrt(r.re.norm_sqr() + r.im.norm_sqr()));
  }

  double
  BackwardError::relative(const std::complex<double> l,
                          const ComplexVector       &phi,
                          const double               norm_r) const
  {
    const double scale = this->scale(l) * std::sqrt(phi.re.norm_sqr() + phi.im.norm_sqr());
    return scale > 0 ? norm_r / scale : 0.;
  }

  double
  BackwardError::mismatch(const ComplexVector &phi,
                          const ComplexVector &Mp,
                          const ComplexVector &Cp,
                          const ComplexVector &Kp,
                          const bool           transpose) const
  {
    double worst = 0;
    const std::pair<const PETScWrappers::MPI::SparseMatrix *, const ComplexVector *> given[3] = {
      {&M, &Mp}, {&C, &Cp}, {&K, &Kp}};
    for (const auto &[A, Ap] : given)
      {
        ComplexVector a;
        replicated_vmult(*A, phi, a, transpose);
        const double norm = std::sqrt(a.re.norm_sqr() + a.im.norm_sqr());
        a.re -= Ap->re;
        a.im -= Ap->im;
        const double d = std::sqrt(a.re.norm_sqr() + a.im.norm_sqr());
        if (!std::isfinite(d))
          return std::numeric_limits<double>::infinity();
        if (d > 0)
          worst = std::max(worst, d / norm);
      }
    return worst;
  }

  double
  BackwardError::operator()(const std::complex<double> l,
                            const ComplexVector       &phi,
                            const ComplexVector       &Mp,
                            const ComplexVector       &Cp,
                            const ComplexVector       &Kp,
                            ComplexVector             *residual,
                            std::complex<double>      *derivative) const
  {
    const std::size_t          n  = phi.re.size();
    const std::complex<double> l2 = l * l;
    Vector<double>             re(n), im(n);
    for (std::size_t i = 0; i < n; ++i)
      {
        const std::complex<double> r = l2 * std::complex<double>(Mp.re[i], Mp.im[i]) +
                                       l * std::complex<double>(Cp.re[i], Cp.im[i]) +
                                       std::complex<double>(Kp.re[i], Kp.im[i]);
        re[i] = r.real();
        im[i] = r.imag();
      }
    const double norm_r = std::sqrt(re.norm_sqr() + im.norm_sqr());
    if (derivative != nullptr)
      {
        const auto dot = [](const ComplexVector &a, const ComplexVector &b) { // a^H b
          return std::complex<double>(a.re * b.re + a.im * b.im, a.re * b.im - a.im * b.re);
        };
        *derivative = 2. * l * dot(phi, Mp) + dot(phi, Cp);
      }
    if (residual != nullptr)
      {
        residual->re = std::move(re);
        residual->im = std::move(im);
      }
    return relative(l, phi, norm_r);
  }
} // namespace rotorfit

