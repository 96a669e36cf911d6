#include <rotorfit/base/input_error.h>
#include <rotorfit/mesh/section_layout.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace rotorfit
{
  namespace
  {
    /// Sizes grow away from a fit by this much per unit distance.
    constexpr double grading = 0.5;

    /// Nodes on [0, length] whose spacing follows @p size (a function of
    /// the position): n = round(integral of 1/size) cells.
    template <typename SizeFunction>
    std::vector<double>
    graded_nodes(const double length, const SizeFunction &size)
    {
      constexpr unsigned int samples = 400;
      std::vector<double>    cumulative(samples + 1, 0.);
      for (unsigned int i = 0; i < samples; ++i)
        cumulative[i + 1] =
          cumulative[i] + length / samples / size((i + 0.5) * length / samples);
      const unsigned int  n = std::max(1., std::round(cumulative.back()));
      std::vector<double> nodes{0.};
      unsigned int        i = 0;
      for (unsigned int k = 1; k < n; ++k)
        {
          const double target = cumulative.back() * k / n;
          while (cumulative[i + 1] < target)
            ++i;
          const double t = (target - cumulative[i]) / (cumulative[i + 1] - cumulative[i]);
          nodes.push_back((i + t) * length / samples);
        }
      nodes.push_back(length);
      return nodes;
    }

  } // namespace

  double
  AxialSection::ri(const double z) const
  {
    return ri0 + (z - z0) / (z1 - z0) * (ri1 - ri0);
  }

  double
  AxialSection::ro(const double z) const
  {
    return ro0 + (z - z0) / (z1 - z0) * (ro1 - ro0);
  }

  SectionLayout::SectionLayout(const std::vector<std::vector<AxialSection>> &sections,
                               const std::vector<double>                    &core_radius,
                               const std::vector<std::string>               &body_names,
                               const double                                  h_fit,
                               const double                                  h_edge,
                               const double                                  h_max,
                               const SectionRefinement                      &refinement)
    : body_sections(sections)
    , core_radii(core_radius)
    , body_names(body_names)
    , h_fit(h_fit)
    , h_edge(std::min(h_fit, h_edge))
    , h_max(h_max)
    , refinement(refinement)
  {
    find_fits();
    z          = make_axial_nodes();
    chain_list = make_chains();
  }

  double
  SectionLayout::size_at(const double d_fit, const double d_edge) const
  {
    return std::min({h_max, h_fit + grading * d_fit, h_edge + grading * d_edge});
  }

  const AxialSection &
  section_at(const std::vector<AxialSection> &sections, const double z)
  {
    for (const auto &s : sections)
      if (z <= s.z1)
        return s;
    return sections.back();
  }

  const AxialSection &
  SectionLayout::section_at(const unsigned int body, const double z) const
  {
    return rotorfit::section_at(body_sections[body], z);
  }

  double
  SectionLayout::inner_radius(const Chain &c, const AxialSection &s, const double z) const
  {
    // the section's own radius: at a plane two body_sections share, section_at
    // could return the neighbour's
    return c.solid ? core_radii[c.body] : s.ri(z);
  }

  void
  SectionLayout::find_fits()
  {
    double scale = 0;
    for (const auto &list : body_sections)
      for (const auto &s : list)
        scale = std::max({scale, std::abs(s.z0), std::abs(s.z1), s.ro0, s.ro1});
    const double tol = 1e-9 * scale;
    zones.clear();
    for (unsigned int b = 0; b < body_sections.size(); ++b)
      for (unsigned int c = 0; c < body_sections.size(); ++c)
        if (b != c)
          for (const auto &s : body_sections[b])
            for (const auto &t : body_sections[c])
              {
                const double zl = std::max(s.z0, t.z0), zr = std::min(s.z1, t.z1);
                if (zr - zl <= tol)
                  continue;
                for (const double z : {zl, 0.5 * (zl + zr), zr})
                  if (std::max(s.ri(z), t.ri(z)) < std::min(s.ro(z), t.ro(z)) - tol)
                    {
                      std::ostringstream m;
                      m << "Bodies " << body_names[b] << " and " << body_names[c]
                        << " overlap at z = " << z << " m (radii " << s.ri(z) << " .. "
                        << s.ro(z) << " and " << t.ri(z) << " .. " << t.ro(z)
                        << " m); check their Sections (a fit is meshed at one nominal "
                           "radius; the interference is set in its Interface).";
                      throw InputError(m.str());
                    }
                if (std::abs(s.ro(zl) - t.ri(zl)) < tol && std::abs(s.ro(zr) - t.ri(zr)) < tol)
                  zones.emplace_back(zl, zr);
              }
  }

  std::vector<double>
  SectionLayout::make_axial_nodes() const
  {
    std::vector<double> breaks;
    for (const auto &list : body_sections)
      for (const auto &s : list)
        breaks.insert(breaks.end(), {s.z0, s.z1});
    std::sort(breaks.begin(), breaks.end());
    const double tol = 1e-9 * std::max(std::abs(breaks.front()), std::abs(breaks.back()));
    breaks.erase(std::unique(breaks.begin(),
                             breaks.end(),
                             [tol](double a, double b) { return b - a <= tol; }),
                 breaks.end());
    // a fit's edges: the ends of its zones, less the planes where two zones
    // of one fit meet (no corner there)
    std::vector<double> edges;
    for (const auto &[a, b] : zones)
      for (const double e : {a, b})
        if (std::none_of(zones.begin(), zones.end(), [&](const auto &o) {
              return (e == a && std::abs(o.second - e) <= tol) ||
                     (e == b && std::abs(o.first - e) <= tol);
            }))
          edges.push_back(e);
    const auto size = [&](const double z) {
      double d = std::numeric_limits<double>::max(), d_edge = d;
      for (const auto &[a, b] : zones)
        d = std::min(d, std::max({0., a - z, z - b}));
      for (const double e : edges)
        d_edge = std::min(d_edge, std::abs(z - e));
      return zones.empty() ? h_max : size_at(d, d_edge);
    };
    std::vector<double> z{breaks.front()};
    for (unsigned int i = 0; i + 1 < breaks.size(); ++i)
      {
        const double a     = breaks[i];
        const auto   nodes = graded_nodes(breaks[i + 1] - a, [&](double x) { return size(a + x); });
        for (unsigned int k = 1; k < nodes.size(); ++k)
          z.push_back(k + 1 == nodes.size() ? breaks[i + 1] : a + nodes[k]);
      }
    z.insert(z.end(), refinement.z.begin(), refinement.z.end());
    std::sort(z.begin(), z.end());
    z.erase(std::unique(z.begin(), z.end(), [tol](double a, double b) { return b - a <= tol; }),
            z.end());
    return z;
  }

  std::vector<SectionLayout::Chain>
  SectionLayout::make_chains() const
  {
    std::vector<Chain> chains;
    for (unsigned int b = 0; b < body_sections.size(); ++b)
      for (unsigned int k = 0; k < body_sections[b].size(); ++k)
        {
          const auto &s = body_sections[b][k];
          const double tol = 1e-9 * std::max(s.ro0, s.ro1);
          if (k == 0 || chains.back().solid != s.solid() ||
              std::abs(body_sections[b][k - 1].ri1 - s.ri0) > tol ||
              std::abs(body_sections[b][k - 1].ro1 - s.ro0) > tol)
            chains.push_back({b, k, k, s.solid(), false, false, {}});
          chains.back().last = k;
        }
    // which chains' outer or inner boundary is a fit somewhere
    for (auto &c : chains)
      for (unsigned int k = c.first; k <= c.last; ++k)
        {
          const auto &s = body_sections[c.body][k];
          for (unsigned int o = 0; o < body_sections.size(); ++o)
            if (o != c.body)
              for (const auto &t : body_sections[o])
                {
                  const double zl = std::max(s.z0, t.z0), zr = std::min(s.z1, t.z1);
                  const double tol = 1e-9 * std::max(s.ro0, s.ro1);
                  if (zr - zl <= tol)
                    continue;
                  if (std::abs(s.ro(zl) - t.ri(zl)) < tol && std::abs(s.ro(zr) - t.ri(zr)) < tol)
                    c.outer_fit = true;
                  if (std::abs(s.ri(zl) - t.ro(zl)) < tol && std::abs(s.ri(zr) - t.ro(zr)) < tol)
                    c.inner_fit = true;
                }
        }
    radial_fractions(chains);
    return chains;
  }

  void
  SectionLayout::radial_fractions(std::vector<Chain> &chains) const
  {
    // base: graded towards the chain's fit boundaries, at its thickest end
    for (auto &c : chains)
      {
        double t = 0;
        for (unsigned int k = c.first; k <= c.last; ++k)
          {
            const auto &s = body_sections[c.body][k];
            t = std::max({t, s.ro0 - inner_radius(c, s, s.z0), s.ro1 - inner_radius(c, s, s.z1)});
          }
        const auto size = [&](const double d) {
          double d_fit = std::numeric_limits<double>::max();
          if (c.outer_fit)
            d_fit = std::min(d_fit, t - d);
          if (c.inner_fit)
            d_fit = std::min(d_fit, d);
          // (the layout is a tensor product: a fit's edge grades the whole chain radially)
          return (c.outer_fit || c.inner_fit) ? size_at(d_fit, d_fit) : h_max;
        };
        for (const double d : graded_nodes(t, size))
          c.fractions.push_back(d / t);
        const auto it = refinement.fractions.find({c.body, c.first});
        if (it != refinement.fractions.end())
          c.added = it->second;
      }

    merge_step_radii(chains);
  }

  void
  SectionLayout::merge_step_radii(std::vector<Chain> &chains) const
  {
    // steps: the wider chain takes the narrower one's radii at the plane
    // they share, so the vertices there coincide. Narrower chains first.
    std::vector<int> needs(chains.size(), -1); // chain i needs chain needs[i]'s radii
    std::vector<std::vector<unsigned int>> requires_of(chains.size());
    for (unsigned int i = 0; i + 1 < chains.size(); ++i)
      {
        auto &a = chains[i], &b = chains[i + 1];
        if (a.body != b.body)
          continue;
        const double z   = body_sections[a.body][a.last].z1;
        const auto  &sA  = body_sections[a.body][a.last];
        const auto  &sB  = body_sections[b.body][b.first];
        const double aA  = inner_radius(a, sA, z), oA = sA.ro1;
        const double aB  = inner_radius(b, sB, z), oB = sB.ro0;
        const double tol = 1e-9 * std::max(oA, oB);
        if (aA <= aB + tol && oA >= oB - tol)
          requires_of[i].push_back(i + 1);
        else if (aB <= aA + tol && oB >= oA - tol)
          requires_of[i + 1].push_back(i);
        else
          {
            std::ostringstream m;
            m << "Body " << body_names[a.body] << "/Sections: at z = " << z
              << " m the radial range " << aA << " .. " << oA << " m meets " << aB << " .. "
              << oB << " m and neither contains the other; the section mesher needs one "
                       "side of a step to contain the other. Split the body into two "
                       "bodies or add a short transition section.";
            throw InputError(m.str());
          }
      }
    std::vector<bool> done(chains.size(), false);
    for (unsigned int pass = 0; pass < chains.size(); ++pass)
      for (unsigned int i = 0; i < chains.size(); ++i)
        {
          if (done[i] || !std::all_of(requires_of[i].begin(),
                                      requires_of[i].end(),
                                      [&](unsigned int j) { return done[j]; }))
            continue;
          auto               &c = chains[i];
          std::vector<double> required{0., 1.}; // the ends and the steps' radii
          for (const unsigned int j : requires_of[i])
            {
              const auto  &o = chains[j];
              const double z = (j > i ? body_sections[c.body][c.last].z1 : body_sections[c.body][c.first].z0);
              const auto  &sc = body_sections[c.body][j > i ? c.last : c.first];
              const double a = inner_radius(c, sc, z), t = sc.ro(z) - a;
              const auto  &so = body_sections[o.body][j > i ? o.first : o.last];
              const double ao = inner_radius(o, so, z), oo = so.ro(z);
              for (const double s : o.fractions)
                required.push_back(((1 - s) * ao + s * oo - a) / t);
            }
          std::sort(required.begin(), required.end());
          // the neighbours' radii, without the chain's own ends
          std::vector<double> steps;
          for (const double r : required)
            if (r > 1e-12 && r < 1 - 1e-12)
              steps.push_back(r);
          std::vector<double> merged = required;
          merged.insert(merged.end(), c.added.begin(), c.added.end());
          // an own node gives way to a step radius closer than 0.4 of the
          // mean spacing (no sliver); the ends are the chain's own, so a
          // node graded towards a fit at an end stays
          const double spacing = 1. / std::max<std::size_t>(1, c.fractions.size() - 1);
          for (unsigned int k = 1; k + 1 < c.fractions.size(); ++k)
            {
              const double s  = c.fractions[k];
              const auto   it = std::lower_bound(steps.begin(), steps.end(), s);
              double       d       = std::numeric_limits<double>::max();
              if (it != steps.end())
                d = *it - s;
              if (it != steps.begin())
                d = std::min(d, s - *(it - 1));
              if (d > 0.4 * spacing)
                merged.push_back(s);
            }
          std::sort(merged.begin(), merged.end());
          merged.erase(std::unique(merged.begin(),
                                   merged.end(),
                                   [](double x, double y) { return y - x < 1e-12; }),
                       merged.end());
          c.fractions = merged;
          done[i]     = true;
        }
  }

} // namespace rotorfit
