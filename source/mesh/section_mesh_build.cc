#include <rotorfit/base/input_error.h>
#include <rotorfit/mesh/section_mesh.h>

#include <deal.II/grid/manifold.h>
#include <deal.II/grid/tria_description.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

// SectionMesh, part 2: the cells, the manifold and the named boundaries of
// the plan of part 1 (section_mesh.cc: parameters, fits, axial nodes and
// radial fractions), and the refinement of a mesh it built.

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// (r, theta, z): straight lines in the chart are cylinders' generators,
    /// circles and cones' generators, so the chart is exact on all sections.
    class CylindricalChart : public ChartManifold<3, 3, 3>
    {
    public:
      CylindricalChart()
        : ChartManifold<3, 3, 3>(Tensor<1, 3>({0., 2. * M_PI, 0.}))
      {}

      Point<3>
      pull_back(const Point<3> &p) const override
      {
        return Point<3>(std::hypot(p[0], p[1]), std::atan2(p[1], p[0]), p[2]);
      }

      Point<3>
      push_forward(const Point<3> &c) const override
      {
        return Point<3>(c[0] * std::cos(c[1]), c[0] * std::sin(c[1]), c[2]);
      }

      DerivativeForm<1, 3, 3>
      push_forward_gradient(const Point<3> &c) const override
      {
        DerivativeForm<1, 3, 3> d;
        d[0][0] = std::cos(c[1]);
        d[0][1] = -c[0] * std::sin(c[1]);
        d[1][0] = std::sin(c[1]);
        d[1][1] = c[0] * std::cos(c[1]);
        d[2][2] = 1;
        return d;
      }

      std::unique_ptr<Manifold<3, 3>>
      clone() const override
      {
        return std::make_unique<CylindricalChart>();
      }
    };

    constexpr types::manifold_id chart_id = 1;
    /// Half-width of the O-grid's square over the core radius: its corners
    /// at 0.75 r_c leave the transition cells a fair shape.
    constexpr double square_half_width = 0.53;
    std::string
    side_name(const SectionMesh::Side s)
    {
      switch (s)
        {
          case SectionMesh::Side::outer:
            return "outer";
          case SectionMesh::Side::inner:
            return "inner";
          case SectionMesh::Side::start:
            return "start";
          default:
            return "end";
        }
    }
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

  void
  SectionMesh::create(Triangulation<3>                                   &tria,
                      std::map<types::boundary_id, std::set<std::string>> &names) const
  {
    std::vector<std::pair<double, double>> zones;
    find_fits(zones);
    const std::vector<double> z      = axial_nodes(zones);
    const std::vector<Chain>  chains = make_chains();

    std::vector<Point<3>>    vertices;
    std::vector<CellData<3>> cells;
    for (unsigned int b = 0; b < sections.size(); ++b)
      add_body_cells(b, z, chains, vertices, cells);

    tria.create_triangulation(vertices, cells, SubCellData());
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->manifold_id() == chart_id)
        cell->set_all_manifold_ids(chart_id);
    tria.set_manifold(chart_id, CylindricalChart());

    name_boundaries(tria, names);
  }

  void
  SectionMesh::add_body_cells(const unsigned int        b,
                              const std::vector<double> &z,
                              const std::vector<Chain>  &chains,
                              std::vector<Point<3>>     &vertices,
                              std::vector<CellData<3>>  &cells) const
  {
    const unsigned int k = n_theta / 4;
    VertexTable  table(vertices, n_theta);
    const double a_sq = square_half_width * core_radius[b];
    for (unsigned int l = 0; l + 1 < z.size(); ++l)
      {
        const double zm = 0.5 * (z[l] + z[l + 1]);
        for (const auto &c : chains)
          {
            if (c.body != b || !(zm > sections[b][c.first].z0 && zm < sections[b][c.last].z1))
              continue;
            const Section &s = section_at(b, zm);
            const auto level = [&](const unsigned int j, const unsigned int ll) {
              const double f = c.fractions[j];
              return (1 - f) * inner_radius(c, s, z[ll]) + f * s.ro(z[ll]);
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
            const double rc = core_radius[b];
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

  std::optional<SectionMesh::Side>
  SectionMesh::face_side(const Triangulation<3>::face_iterator &face,
                         const unsigned int                     b,
                         double                                &zm) const
  {
    double z_lo = std::numeric_limits<double>::max(), z_hi = -z_lo, r = 0;
    for (const unsigned int v : face->vertex_indices())
      {
        z_lo = std::min(z_lo, face->vertex(v)[2]);
        z_hi = std::max(z_hi, face->vertex(v)[2]);
        r += std::hypot(face->vertex(v)[0], face->vertex(v)[1]) / 4;
      }
    zm               = 0.5 * (z_lo + z_hi);
    const double tol = 1e-9 * std::max(1., std::abs(zm));
    if (z_hi - z_lo <= tol) // an axial face: an end of the body, or a step (unnamed)
      {
        if (std::abs(zm - sections[b].front().z0) <= tol)
          return Side::start;
        if (std::abs(zm - sections[b].back().z1) <= tol)
          return Side::end;
        return std::nullopt;
      }
    const Section &s = section_at(b, zm);
    return std::abs(r - s.ro(zm)) < std::abs(r - s.ri(zm)) ? Side::outer : Side::inner;
  }

  void
  SectionMesh::name_boundaries(Triangulation<3>                                   &tria,
                               std::map<types::boundary_id, std::set<std::string>> &names) const
  {
    // boundary ids: one per distinct set of surface names
    std::map<std::set<std::string>, types::boundary_id> id_of{{{}, 0}};
    std::map<std::pair<std::string, unsigned int>, unsigned int> faces_of; // (surface, selector)
    for (const auto &cell : tria.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary())
          {
            const auto   face = cell->face(f);
            const auto   b    = cell->material_id();
            double       zm   = 0;
            const auto   side = face_side(face, b, zm);
            const double tol  = 1e-9 * std::max(1., std::abs(zm));
            std::set<std::string> set;
            for (const auto &[name, selectors] : surfaces)
              for (unsigned int i = 0; i < selectors.size(); ++i)
                {
                  const auto &sel = selectors[i];
                  if (side && sel.body == b && sel.side == *side && zm >= sel.z_from - tol &&
                      zm <= sel.z_to + tol)
                    {
                      set.insert(name);
                      ++faces_of[{name, i}];
                    }
                }
            const auto it = id_of.emplace(set, id_of.size()).first;
            face->set_boundary_id(it->second);
          }
    names.clear();
    for (const auto &[set, id] : id_of)
      names[id] = set;
    for (const auto &[name, selectors] : surfaces)
      for (unsigned int i = 0; i < selectors.size(); ++i)
        if (faces_of[{name, i}] == 0)
          {
            const auto        &sel = selectors[i];
            std::ostringstream m;
            m << "Geometry/Sections/Surfaces: the selector '" << body_names[sel.body] << " "
              << side_name(sel.side);
            if (sel.z_from > -std::numeric_limits<double>::max())
              m << " " << sel.z_from << " " << sel.z_to;
            m << "' of surface '" << name
              << "' selects no boundary face; check the side and the axial range against "
                 "the body's Sections (a body's start and end are its lowest and highest z).";
            throw InputError(m.str());
          }
  }

  SectionMesh::Refinement
  SectionMesh::refined(const Triangulation<3> &tria,
                       const Vector<float>    &indicator,
                       const double            fraction) const
  {
    std::vector<std::pair<double, double>> zones;
    find_fits(zones);
    const std::vector<double> z      = axial_nodes(zones);
    const std::vector<Chain>  chains = make_chains();

    // sums of indicator^2 over each axial layer and each radial interval
    std::vector<double>              layer(z.size() - 1, 0.);
    std::vector<std::vector<double>> interval(chains.size());
    for (unsigned int i = 0; i < chains.size(); ++i)
      interval[i].assign(chains[i].fractions.size() - 1, 0.);
    for (const auto &cell : tria.active_cell_iterators())
      {
        const double   eta2 = std::pow(indicator[cell->active_cell_index()], 2);
        const Point<3> x    = cell->center();
        const auto     l    = std::upper_bound(z.begin(), z.end(), x[2]) - z.begin() - 1;
        layer[std::clamp<long>(l, 0, layer.size() - 1)] += eta2;
        const unsigned int b = cell->material_id();
        for (unsigned int i = 0; i < chains.size(); ++i)
          {
            const auto &c = chains[i];
            if (c.body != b || !(x[2] > sections[b][c.first].z0 && x[2] < sections[b][c.last].z1))
              continue;
            const Section &s = section_at(b, x[2]);
            const double   a = inner_radius(c, s, x[2]);
            const double   f = (std::hypot(x[0], x[1]) - a) / (s.ro(x[2]) - a);
            if (f < 0) // the O-grid core: refined by the circumferential cells only
              break;
            const auto j = std::upper_bound(c.fractions.begin(), c.fractions.end(), f) -
                           c.fractions.begin() - 1;
            interval[i][std::clamp<long>(j, 0, interval[i].size() - 1)] += eta2;
            break;
          }
      }

    // split the largest share of each kind in the middle
    Refinement next = refinement;
    const auto top  = [fraction](const std::vector<double> &v) {
      std::vector<unsigned int> order(v.size());
      for (unsigned int i = 0; i < v.size(); ++i)
        order[i] = i;
      std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) { return v[a] > v[b]; });
      order.resize(std::min<std::size_t>(v.size(), std::max(1., std::round(fraction * v.size()))));
      return order;
    };
    for (const unsigned int l : top(layer))
      next.z.push_back(0.5 * (z[l] + z[l + 1]));
    next.layers_split = std::max(1., std::round(fraction * layer.size()));
    std::vector<double>                                      flat;
    std::vector<std::pair<unsigned int, unsigned int>>       where;
    for (unsigned int i = 0; i < chains.size(); ++i)
      for (unsigned int j = 0; j < interval[i].size(); ++j)
        {
          flat.push_back(interval[i][j]);
          where.emplace_back(i, j);
        }
    const auto marked    = top(flat);
    next.intervals_split = marked.size();
    for (const unsigned int k : marked)
      {
        const auto &[i, j] = where[k];
        const auto &c      = chains[i];
        next.fractions[{c.body, c.first}].push_back(0.5 * (c.fractions[j] + c.fractions[j + 1]));
      }
    next.layers_split = top(layer).size();
    return next;
  }

} // namespace rotorfit
