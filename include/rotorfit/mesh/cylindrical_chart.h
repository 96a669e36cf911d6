#pragma once

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/manifold.h>

#include <cmath>
#include <memory>

namespace rotorfit
{
  /// (r, theta, z): straight lines in the chart are cylinders' generators,
  /// circles and cones' generators, so the chart is exact on all sections.
  class CylindricalChart : public dealii::ChartManifold<3, 3, 3>
  {
  public:
    CylindricalChart()
      : dealii::ChartManifold<3, 3, 3>(dealii::Tensor<1, 3>({0., 2. * M_PI, 0.}))
    {}

    dealii::Point<3>
    pull_back(const dealii::Point<3> &p) const override
    {
      return dealii::Point<3>(std::hypot(p[0], p[1]), std::atan2(p[1], p[0]), p[2]);
    }

    dealii::Point<3>
    push_forward(const dealii::Point<3> &c) const override
    {
      return dealii::Point<3>(c[0] * std::cos(c[1]), c[0] * std::sin(c[1]), c[2]);
    }

    dealii::DerivativeForm<1, 3, 3>
    push_forward_gradient(const dealii::Point<3> &c) const override
    {
      dealii::DerivativeForm<1, 3, 3> d;
      d[0][0] = std::cos(c[1]);
      d[0][1] = -c[0] * std::sin(c[1]);
      d[1][0] = std::sin(c[1]);
      d[1][1] = c[0] * std::cos(c[1]);
      d[2][2] = 1;
      return d;
    }

    std::unique_ptr<dealii::Manifold<3, 3>>
    clone() const override
    {
      return std::make_unique<CylindricalChart>();
    }
  };
} // namespace rotorfit
