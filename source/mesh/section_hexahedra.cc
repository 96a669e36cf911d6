#include <rotorfit/mesh/section_hexahedra.h>
#include <rotorfit/mesh/cylindrical_chart.h>

#include <deal.II/grid/manifold.h>
#include <deal.II/grid/tria_description.h>

#include <array>
#include <cmath>
#include <map>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {

    constexpr types::manifold_id chart_id = 1;
    /// Half-width of the O-grid's square over the core radius: its corners
    /// at 0.75 r_c leave the transition cells a fair shape.
    constexpr double square_half_width = 0.53;
  } // namespace

  namespace
  {
    /// Vertices of one body, looked up by their place in the structure (so
    /// that the cells of neighbouring layers and chains share them); the two
    /// bodies of a fit keep separate copies.
    class VertexTable
    {
    public:
      VertexTable(std::vector<Point<3>> &vertices, const unsigned int n_theta)
        : vertices(vertices)
        , n_theta(n_theta)
      {}

      unsigned int
      ring(const unsigned int l, const unsigned int m, const double r, const double z)
      {
        auto &bucket = rings[{l, m % n_theta}];
        for (const auto &[radius, index] : bucket)
          if (std::abs(radius - r) <= 1e-9 * std::max(r, 1e-3))
            return index;
        const double theta = -0.75 * M_PI + 2 * M_PI * (m % n_theta) / n_theta;
        vertices.emplace_back(r * std::cos(theta), r * std::sin(theta), z);
        bucket.emplace_back(r, vertices.size() - 1);
        return vertices.size() - 1;
      }

      /// Point (i, j) of the core square (k cells a side, half-width a).
      unsigned int
      square(const unsigned int l, const unsigned int i, const unsigned int j,
             const unsigned int k, const double a, const double z)
      {
        const auto [it, added] = squares.emplace(std::array<unsigned int, 3>{{l, i, j}}, 0);
        if (added)
          {
            vertices.emplace_back(a * (-1. + 2. * i / k), a * (-1. + 2. * j / k), z);
            it->second = vertices.size() - 1;
          }
        return it->second;
      }

      /// The m-th point of the square's perimeter, counter-clockwise from
      /// the corner (-a, -a), at the angle of ring point m.
      unsigned int
      perimeter(const unsigned int l, const unsigned int m_in, const unsigned int k,
                const double a, const double z)
      {
        const unsigned int m = m_in % (4 * k);
        if (m <= k)
          return square(l, m, 0, k, a, z);
        if (m <= 2 * k)
          return square(l, k, m - k, k, a, z);
        if (m <= 3 * k)
          return square(l, 3 * k - m, k, k, a, z);
        return square(l, 0, 4 * k - m, k, a, z);
      }

    private:
      std::vector<Point<3>> &vertices;
      const unsigned int     n_theta;
      std::map<std::pair<unsigned int, unsigned int>, std::vector<std::pair<double, unsigned int>>>
        rings;
      std::map<std::array<unsigned int, 3>, unsigned int> squares;
    };

    CellData<3>
    hex(const std::array<unsigned int, 8> &v, const unsigned int body, const bool curved)
    {
      CellData<3> cell;
      for (unsigned int i = 0; i < 8; ++i)
        cell.vertices[i] = v[i];
      cell.material_id = body;
      cell.manifold_id = curved ? chart_id : numbers::flat_manifold_id;
      return cell;
    }
  } // namespace

  SectionHexahedra::SectionHexahedra(const SectionLayout &layout, const unsigned int n_theta)
    : layout(layout)
    , n_theta(n_theta)
  {}

  void
  SectionHexahedra::create(Triangulation<3> &tria) const
  {
    std::vector<Point<3>>    vertices;
    std::vector<CellData<3>> cells;
    for (unsigned int b = 0; b < layout.sections().size(); ++b)
      add_body_cells(b, vertices, cells);

    tria.create_triangulation(vertices, cells, SubCellData());
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->manifold_id() == chart_id)
        cell->set_all_manifold_ids(chart_id);
    tria.set_manifold(chart_id, CylindricalChart());
  }

  void
  SectionHexahedra::add_body_cells(const unsigned int        b,
                                   std::vector<Point<3>>    &vertices,
                                   std::vector<CellData<3>> &cells) const
  {
    const auto &z        = layout.axial_nodes();
    const auto &chains   = layout.chains();
    const auto &sections = layout.sections();
    const unsigned int k = n_theta / 4;
    VertexTable  table(vertices, n_theta);
    const double a_sq = square_half_width * layout.core_radius(b);
    for (unsigned int l = 0; l + 1 < z.size(); ++l)
      {
        const double zm = 0.5 * (z[l] + z[l + 1]);
        for (const auto &c : chains)
          {
            if (c.body != b || !(zm > sections[b][c.first].z0 && zm < sections[b][c.last].z1))
              continue;
            const AxialSection &s = layout.section_at(b, zm);
            const auto level = [&](const unsigned int j, const unsigned int ll) {
              const double f = c.fractions[j];
              return (1 - f) * layout.inner_radius(c, s, z[ll]) + f * s.ro(z[ll]);
            };
            for (unsigned int j = 0; j + 1 < c.fractions.size(); ++j)
              for (unsigned int m = 0; m < n_theta; ++m)
                {
                  std::array<unsigned int, 8> v;
                  for (unsigned int h = 0; h < 2; ++h)
                    {
                      const unsigned int ll = l + h;
                      v[4 * h + 0] = table.ring(ll, m, level(j, ll), z[ll]);
                      v[4 * h + 1] = table.ring(ll, m, level(j + 1, ll), z[ll]);
                      v[4 * h + 2] = table.ring(ll, m + 1, level(j, ll), z[ll]);
                      v[4 * h + 3] = table.ring(ll, m + 1, level(j + 1, ll), z[ll]);
                    }
                  cells.push_back(hex(v, b, true));
                }
            if (!c.solid)
              continue;
            const double rc = layout.core_radius(b);
            for (unsigned int m = 0; m < n_theta; ++m) // transition ring
              {
                std::array<unsigned int, 8> v;
                for (unsigned int h = 0; h < 2; ++h)
                  {
                    const unsigned int ll = l + h;
                    v[4 * h + 0] = table.perimeter(ll, m, k, a_sq, z[ll]);
                    v[4 * h + 1] = table.ring(ll, m, rc, z[ll]);
                    v[4 * h + 2] = table.perimeter(ll, m + 1, k, a_sq, z[ll]);
                    v[4 * h + 3] = table.ring(ll, m + 1, rc, z[ll]);
                  }
                cells.push_back(hex(v, b, false));
              }
            for (unsigned int i = 0; i < k; ++i) // core square
              for (unsigned int j = 0; j < k; ++j)
                {
                  std::array<unsigned int, 8> v;
                  for (unsigned int h = 0; h < 2; ++h)
                    {
                      const unsigned int ll = l + h;
                      v[4 * h + 0] = table.square(ll, i, j, k, a_sq, z[ll]);
                      v[4 * h + 1] = table.square(ll, i + 1, j, k, a_sq, z[ll]);
                      v[4 * h + 2] = table.square(ll, i, j + 1, k, a_sq, z[ll]);
                      v[4 * h + 3] = table.square(ll, i + 1, j + 1, k, a_sq, z[ll]);
                    }
                  cells.push_back(hex(v, b, false));
                }
          }
      }
  }

} // namespace rotorfit
