#include <rotorfit/base/input_error.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/mesh/section_mesh.h>

#include <deal.II/base/utilities.h>

#include <deal.II/grid/manifold.h>
#include <deal.II/grid/tria_description.h>

#include <algorithm>
#include <array>
#include <optional>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

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
  SectionMesh::Section::ri(const double z) const
  {
    return ri0 + (z - z0) / (z1 - z0) * (ri1 - ri0);
  }

  double
  SectionMesh::Section::ro(const double z) const
  {
    return ro0 + (z - z0) / (z1 - z0) * (ro1 - ro0);
  }

  void
  SectionMesh::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Sections");
    prm.declare_entry("Circumferential cells",
                      "24",
                      Patterns::Integer(8, 512),
                      "Cells around the circumference, a multiple of 4 (the O-grid "
                      "core of a solid section has N/4 cells a side). The ring part "
                      "of the mesh maps onto itself under a rotation of 2 pi / N.");
    prm.declare_entry("Element size",
                      "8e-3",
                      patterns::Positive(),
                      "Axial and radial element size away from the fits [m].");
    prm.declare_entry("Fit element size",
                      "4e-3",
                      patterns::Positive(),
                      "Axial and radial element size at the fits [m]; sizes grow "
                      "from it by half the distance to the fit, up to Element size.");
    prm.declare_entry("Surfaces",
                      "",
                      Patterns::Anything(),
                      "Named surfaces for interfaces, bearings, probes and rollers: "
                      "'name: selector + selector, name: ...'. A selector is "
                      "'<body> outer|inner [z from] [z to]' (the radial boundary, "
                      "optionally between two axial positions [m]) or "
                      "'<body> start|end' (the end face at the body's lowest or "
                      "highest z). Example: 'fit: shaft outer 0.11 0.15 + sleeve "
                      "inner, bearing_left: shaft start'.");
    prm.leave_subsection();
  }

  void
  SectionMesh::declare_body_parameters(ParameterHandler               &prm,
                                       const std::vector<std::string> &bodies)
  {
    for (const auto &name : bodies)
      {
        prm.enter_subsection("Body " + name);
        prm.declare_entry("Sections",
                          "",
                          Patterns::Anything(),
                          "With Geometry/Mesher = sections: the body as axial "
                          "sections 'z from, z to, inner radius, outer radius at z "
                          "from, inner radius, outer radius at z to; ...' [m], "
                          "following each other in z. Inner radius 0 at both ends: "
                          "a solid section. Cylinders, annuli and cones.");
        prm.leave_subsection();
      }
  }

  void
  SectionMesh::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Sections");
    n_theta = prm.get_integer("Circumferential cells");
    if (n_theta % 4 != 0)
      throw InputError("Geometry/Sections/Circumferential cells = " +
                       std::to_string(n_theta) +
                       " must be a multiple of 4 (the O-grid core of a solid "
                       "section has N/4 cells a side).");
    h_max         = prm.get_double("Element size");
    h_fit         = std::min(h_max, prm.get_double("Fit element size"));
    surfaces_text = prm.get("Surfaces");
    prm.leave_subsection();
  }

  void
  SectionMesh::parse_body_parameters(ParameterHandler               &prm,
                                     const std::vector<std::string> &bodies)
  {
    body_names = bodies;
    sections.assign(bodies.size(), {});
    for (unsigned int b = 0; b < bodies.size(); ++b)
      {
        prm.enter_subsection("Body " + bodies[b]);
        const std::string text = prm.get("Sections");
        prm.leave_subsection();
        read_sections(b, text);
        check_sections(b);
      }
    set_core_radii();
    parse_surfaces();
  }

  void
  SectionMesh::read_sections(const unsigned int b, const std::string &text)
  {
    const std::string entry = "Body " + body_names[b] + "/Sections";
    if (Utilities::trim(text).empty())
      throw InputError(entry + " is not set; with Geometry/Mesher = sections every "
                               "body is given as axial sections.");
    unsigned int k = 0;
    for (const auto &item : Utilities::split_string_list(text, ';'))
      {
        ++k;
        std::vector<double> v;
        try
          {
            for (const auto &word : Utilities::split_string_list(item, ','))
              v.push_back(Utilities::string_to_double(word));
          }
        catch (...)
          {
            v.clear();
          }
        if (v.size() != 6 ||
            !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }))
          throw InputError(entry + ": section " + std::to_string(k) + " '" + item +
                           "' needs six numbers: z from, z to, inner and outer "
                           "radius at z from, inner and outer radius at z to [m].");
        sections[b].push_back({v[0], v[1], v[2], v[3], v[4], v[5]});
      }
  }

  void
  SectionMesh::set_core_radii()
  {
    // the core radius of each body: inside every solid section and inside
    // every bore of the body (a bore's radii must be nodes of the core's rings)
    core_radius.assign(sections.size(), 0.);
    for (unsigned int b = 0; b < sections.size(); ++b)
      {
        double rc    = std::numeric_limits<double>::max();
        bool   solid = false;
        for (const auto &s : sections[b])
          if (s.solid())
            {
              solid = true;
              rc    = std::min(rc, 0.5 * std::min(s.ro0, s.ro1));
            }
        for (const auto &s : sections[b])
          if (!s.solid())
            rc = std::min(rc, 0.8 * std::min(s.ri0, s.ri1));
        core_radius[b] = solid ? rc : 0.;
      }
  }

  void
  SectionMesh::parse_surfaces()
  {
    surfaces.clear();
    const std::string entry = "Geometry/Sections/Surfaces";
    for (const auto &item : Utilities::split_string_list(surfaces_text, ','))
      {
        const auto colon = item.find(':');
        if (colon == std::string::npos)
          throw InputError(entry + ": '" + item + "' is not 'name: selector + ...'.");
        const std::string name = Utilities::trim(item.substr(0, colon));
        if (name.empty() || surfaces.count(name))
          throw InputError(entry + ": the surface name '" + name +
                           "' is empty or given twice.");
        for (const auto &sel : Utilities::split_string_list(item.substr(colon + 1), '+'))
          surfaces[name].push_back(parse_selector(sel, name));
      }
  }

  SectionMesh::Selector
  SectionMesh::parse_selector(const std::string &sel, const std::string &name) const
  {
    const std::string entry = "Geometry/Sections/Surfaces";
    std::vector<std::string> w;
    for (const auto &x : Utilities::split_string_list(sel, ' '))
      if (!x.empty())
        w.push_back(x);
    const auto body = std::find(body_names.begin(), body_names.end(), w.empty() ? "" : w[0]);
    const std::string usage =
      "; a selector is '<body> outer|inner [z from z to]' or '<body> start|end'.";
    if (w.size() < 2 || body == body_names.end())
      throw InputError(entry + ": '" + sel + "' of surface '" + name +
                       "' does not start with a body of Bodies" + usage);
    Selector s{static_cast<unsigned int>(body - body_names.begin()),
               Side::outer,
               -std::numeric_limits<double>::max(),
               std::numeric_limits<double>::max()};
    if (w[1] == "outer" || w[1] == "inner")
      s.side = (w[1] == "outer" ? Side::outer : Side::inner);
    else if (w[1] == "start" || w[1] == "end")
      s.side = (w[1] == "start" ? Side::start : Side::end);
    else
      throw InputError(entry + ": '" + sel + "' of surface '" + name + "': '" + w[1] +
                       "' is no side" + usage);
    const bool radial = (s.side == Side::outer || s.side == Side::inner);
    if (w.size() == 4 && radial)
      try
        {
          s.z_from = Utilities::string_to_double(w[2]);
          s.z_to   = Utilities::string_to_double(w[3]);
        }
      catch (...)
        {
          throw InputError(entry + ": '" + sel + "': the axial range is not two numbers" + usage);
        }
    else if (w.size() != 2)
      throw InputError(entry + ": '" + sel + "' of surface '" + name +
                       "' has the wrong number of words" + usage);
    if (!(s.z_to > s.z_from))
      throw InputError(entry + ": '" + sel + "': z to must exceed z from.");
    return s;
  }

  void
  SectionMesh::check_sections(const unsigned int b) const
  {
    const std::string entry = "Body " + body_names[b] + "/Sections";
    const auto       &list  = sections[b];
    for (unsigned int k = 0; k < list.size(); ++k)
      {
        const auto        &s = list[k];
        std::ostringstream where;
        where << entry << ": section " << k + 1 << " (z " << s.z0 << " .. " << s.z1 << ")";
        if (!(s.z1 > s.z0))
          throw InputError(where.str() + ": z to must exceed z from.");
        if (!(s.ri0 >= 0 && s.ri1 >= 0 && s.ro0 > s.ri0 && s.ro1 > s.ri1))
          throw InputError(where.str() + ": the radii need 0 <= inner < outer at both ends.");
        if ((s.ri0 == 0) != (s.ri1 == 0))
          throw InputError(where.str() +
                           ": the inner radius is 0 at one end only; a bore that closes "
                           "onto the axis cannot be meshed without degenerate cells. "
                           "Split the section or give the bore a radius at both ends.");
        if (k > 0)
          {
            const double gap = s.z0 - list[k - 1].z1;
            if (std::abs(gap) > 1e-12 * std::max(1., std::abs(s.z0)))
              {
                where << " does not start where section " << k << " ends (z "
                      << list[k - 1].z1
                      << "): sections follow each other in increasing z without gaps "
                         "or overlaps.";
                throw InputError(where.str());
              }
          }
      }
  }

  double
  SectionMesh::size_at(const double d_fit) const
  {
    return std::min(h_max, h_fit + grading * d_fit);
  }

  const SectionMesh::Section &
  SectionMesh::section_at(const unsigned int body, const double z) const
  {
    for (const auto &s : sections[body])
      if (z <= s.z1)
        return s;
    return sections[body].back();
  }

  double
  SectionMesh::inner_radius(const Chain &c, const Section &s, const double z) const
  {
    // the section's own radius: at a plane two sections share, section_at
    // could return the neighbour's
    return c.solid ? core_radius[c.body] : s.ri(z);
  }

  void
  SectionMesh::find_fits(std::vector<std::pair<double, double>> &zones) const
  {
    double scale = 0;
    for (const auto &list : sections)
      for (const auto &s : list)
        scale = std::max({scale, std::abs(s.z0), std::abs(s.z1), s.ro0, s.ro1});
    const double tol = 1e-9 * scale;
    zones.clear();
    for (unsigned int b = 0; b < sections.size(); ++b)
      for (unsigned int c = 0; c < sections.size(); ++c)
        if (b != c)
          for (const auto &s : sections[b])
            for (const auto &t : sections[c])
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
  SectionMesh::axial_nodes(const std::vector<std::pair<double, double>> &zones) const
  {
    std::vector<double> breaks;
    for (const auto &list : sections)
      for (const auto &s : list)
        breaks.insert(breaks.end(), {s.z0, s.z1});
    std::sort(breaks.begin(), breaks.end());
    const double tol = 1e-9 * std::max(std::abs(breaks.front()), std::abs(breaks.back()));
    breaks.erase(std::unique(breaks.begin(),
                             breaks.end(),
                             [tol](double a, double b) { return b - a <= tol; }),
                 breaks.end());
    const auto size = [&](const double z) {
      double d = std::numeric_limits<double>::max();
      for (const auto &[a, b] : zones)
        d = std::min(d, std::max({0., a - z, z - b}));
      return zones.empty() ? h_max : size_at(d);
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

  std::vector<SectionMesh::Chain>
  SectionMesh::make_chains() const
  {
    std::vector<std::pair<double, double>> zones;
    find_fits(zones);
    std::vector<Chain> chains;
    for (unsigned int b = 0; b < sections.size(); ++b)
      for (unsigned int k = 0; k < sections[b].size(); ++k)
        {
          const auto &s = sections[b][k];
          const double tol = 1e-9 * std::max(s.ro0, s.ro1);
          if (k == 0 || chains.back().solid != s.solid() ||
              std::abs(sections[b][k - 1].ri1 - s.ri0) > tol ||
              std::abs(sections[b][k - 1].ro1 - s.ro0) > tol)
            chains.push_back({b, k, k, s.solid(), false, false, {}});
          chains.back().last = k;
        }
    // which chains' outer or inner boundary is a fit somewhere
    for (auto &c : chains)
      for (unsigned int k = c.first; k <= c.last; ++k)
        {
          const auto &s = sections[c.body][k];
          for (unsigned int o = 0; o < sections.size(); ++o)
            if (o != c.body)
              for (const auto &t : sections[o])
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
  SectionMesh::radial_fractions(std::vector<Chain> &chains) const
  {
    // base: graded towards the chain's fit boundaries, at its thickest end
    for (auto &c : chains)
      {
        double t = 0;
        for (unsigned int k = c.first; k <= c.last; ++k)
          {
            const auto &s = sections[c.body][k];
            t = std::max({t, s.ro0 - inner_radius(c, s, s.z0), s.ro1 - inner_radius(c, s, s.z1)});
          }
        const auto size = [&](const double d) {
          double d_fit = std::numeric_limits<double>::max();
          if (c.outer_fit)
            d_fit = std::min(d_fit, t - d);
          if (c.inner_fit)
            d_fit = std::min(d_fit, d);
          return (c.outer_fit || c.inner_fit) ? size_at(d_fit) : h_max;
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
  SectionMesh::merge_step_radii(std::vector<Chain> &chains) const
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
        const double z   = sections[a.body][a.last].z1;
        const auto  &sA  = sections[a.body][a.last];
        const auto  &sB  = sections[b.body][b.first];
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
              const double z = (j > i ? sections[c.body][c.last].z1 : sections[c.body][c.first].z0);
              const auto  &sc = sections[c.body][j > i ? c.last : c.first];
              const double a = inner_radius(c, sc, z), t = sc.ro(z) - a;
              const auto  &so = sections[o.body][j > i ? o.first : o.last];
              const double ao = inner_radius(o, so, z), oo = so.ro(z);
              for (const double s : o.fractions)
                required.push_back(((1 - s) * ao + s * oo - a) / t);
            }
          std::sort(required.begin(), required.end());
          const double spacing = 1. / std::max<std::size_t>(1, c.fractions.size() - 1);
          std::vector<double> merged = required;
          merged.insert(merged.end(), c.added.begin(), c.added.end());
          for (const double s : c.fractions)
            {
              const auto   it = std::lower_bound(required.begin(), required.end(), s);
              double       d  = std::numeric_limits<double>::max();
              if (it != required.end())
                d = *it - s;
              if (it != required.begin())
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

  double
  SectionMesh::n_cells() const
  {
    std::vector<std::pair<double, double>> zones;
    find_fits(zones);
    const auto   z      = axial_nodes(zones);
    const auto   chains = make_chains();
    const double k      = n_theta / 4;
    double       n      = 0;
    for (unsigned int l = 0; l + 1 < z.size(); ++l)
      {
        const double zm = 0.5 * (z[l] + z[l + 1]);
        for (const auto &c : chains)
          if (zm > sections[c.body][c.first].z0 && zm < sections[c.body][c.last].z1)
            n += n_theta * (c.fractions.size() - 1) + (c.solid ? k * k + n_theta : 0);
      }
    return n;
  }

  std::string
  SectionMesh::describe() const
  {
    std::vector<std::pair<double, double>> zones;
    find_fits(zones);
    const auto         z      = axial_nodes(zones);
    const auto         chains = make_chains();
    std::ostringstream s;
    s << std::setprecision(3) << "Section mesh: " << n_theta << " cells around, "
      << z.size() - 1 << " axial layers, element size " << h_max * 1e3 << " mm, "
      << h_fit * 1e3 << " mm at the " << zones.size() << " fit zone(s)\n";
    for (unsigned int b = 0; b < sections.size(); ++b)
      {
        s << "  " << body_names[b] << ": " << sections[b].size() << " section(s), radial cells";
        for (const auto &c : chains)
          if (c.body == b)
            s << " " << c.fractions.size() - 1;
        if (core_radius[b] > 0)
          s << ", O-grid core r " << core_radius[b] * 1e3 << " mm";
        s << "\n";
      }
    return s.str();
  }
} // namespace rotorfit
