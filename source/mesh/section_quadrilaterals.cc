#include <rotorfit/mesh/section_quadrilaterals.h>

#include <deal.II/grid/tria_description.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace rotorfit
{
  using namespace dealii;

  SectionQuadrilaterals::SectionQuadrilaterals(const SectionLayout &layout)
    : layout(layout)
  {}

  void
  SectionQuadrilaterals::create(Triangulation<2> &tria) const
  {
    const auto &z        = layout.axial_nodes();
    const auto &sections = layout.sections();
    std::vector<Point<2>>    vertices;
    std::vector<CellData<2>> cells;
    for (unsigned int b = 0; b < sections.size(); ++b)
      {
        // vertices of body b by (axial node, radius): neighbouring layers and
        // chains share them; other bodies keep their own copies
        std::map<unsigned int, std::vector<std::pair<double, unsigned int>>> at_node;
        const auto vertex = [&](const unsigned int l, const double r) {
          auto &bucket = at_node[l];
          for (const auto &[radius, index] : bucket)
            if (std::abs(radius - r) <= 1e-9 * std::max(r, 1e-3))
              return index;
          vertices.emplace_back(r, z[l]);
          bucket.emplace_back(r, vertices.size() - 1);
          return static_cast<unsigned int>(vertices.size() - 1);
        };
        for (const auto &c : layout.chains())
          {
            if (c.body != b)
              continue;
            // the core strip of a solid chain: cells as wide as its first ring cell
            unsigned int n_core = 0;
            if (c.solid)
              {
                const AxialSection &s  = sections[b][c.first];
                const double        rc = layout.core_radius(b);
                const double first = (c.fractions[1] - c.fractions[0]) * (s.ro(s.z0) - rc);
                n_core = std::max(1u, static_cast<unsigned int>(std::lround(rc / first)));
              }
            for (unsigned int l = 0; l + 1 < z.size(); ++l)
              {
                const double zm = 0.5 * (z[l] + z[l + 1]);
                if (!(zm > sections[b][c.first].z0 && zm < sections[b][c.last].z1))
                  continue;
                const AxialSection &s = layout.section_at(b, zm);
                std::vector<std::array<double, 2>> radii; // at l and l + 1, inner to outer
                for (unsigned int i = 0; i < n_core; ++i)
                  {
                    const double r = layout.core_radius(b) * i / n_core;
                    radii.push_back({{r, r}});
                  }
                for (const double f : c.fractions)
                  {
                    std::array<double, 2> r;
                    for (unsigned int h = 0; h < 2; ++h)
                      r[h] = (1 - f) * layout.inner_radius(c, s, z[l + h]) + f * s.ro(z[l + h]);
                    radii.push_back(r);
                  }
                for (unsigned int j = 0; j + 1 < radii.size(); ++j)
                  {
                    CellData<2> cell;
                    cell.vertices[0] = vertex(l, radii[j][0]);
                    cell.vertices[1] = vertex(l, radii[j + 1][0]);
                    cell.vertices[2] = vertex(l + 1, radii[j][1]);
                    cell.vertices[3] = vertex(l + 1, radii[j + 1][1]);
                    cell.material_id = b;
                    cells.push_back(cell);
                  }
              }
          }
      }
    tria.create_triangulation(vertices, cells, SubCellData());
  }
} // namespace rotorfit
