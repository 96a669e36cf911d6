#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /// One axial section of a body: a cylinder, annulus or cone (radii linear
  /// in z) [m].
  struct AxialSection
  {
    double z0, z1, ri0, ro0, ri1, ro1;
    /// Inner radius at @p z.
    double
    ri(const double z) const;
    /// Outer radius at @p z.
    double
    ro(const double z) const;
    /// Whether the section reaches the axis (no bore).
    bool
    solid() const
    {
      return ri0 == 0;
    }
  };

  /// The section of a body's @p sections (increasing z) that holds @p z:
  /// the first at a plane two sections share, the last beyond the end.
  const AxialSection &
  section_at(const std::vector<AxialSection> &sections, const double z);

  /**
   * Nodes added by adaptive refinement (doc/theory.md 1.4): axial nodes
   * (every body at that z) and radial fractions of a run of sections
   * (keyed by body and its first section). Whole rings are refined, so the
   * mesh stays conforming, hanging-node free and rotationally symmetric.
   */
  struct SectionRefinement
  {
    std::vector<double>                                                  z;
    std::map<std::pair<unsigned int, unsigned int>, std::vector<double>> fractions;
    unsigned int layers_split = 0, intervals_split = 0;
  };

  /**
   * The plan of the section mesh before any cell exists: the fit zones
   * (where two bodies share a radius), the axial nodes every body shares,
   * and the runs of sections with continuous radii ("chains"), each with
   * its radial fractions. Sizes grade from the fit element size at the fits
   * to the element size away from them; at a step the wider chain takes the
   * narrower one's radii, so vertices coincide. Refers to the sections it
   * was made from: it lives no longer than they do. Throws InputError for
   * bodies that overlap and for steps neither side of which contains the
   * other.
   */
  class SectionLayout
  {
  public:
    /// A run of sections of one body with continuous radii: one set of
    /// radial fractions between its inner boundary and its outer radius.
    struct Chain
    {
      unsigned int        body;
      unsigned int        first, last; ///< sections [first, last]
      bool                solid;
      bool                inner_fit = false, outer_fit = false;
      std::vector<double> fractions; ///< 0 .. 1, inner to outer
      std::vector<double> added;     ///< fractions of the refinement
    };

    /// The plan of @p sections (per body) with O-grid core radii
    /// @p core_radius (0: a bore), element sizes @p h_fit at the fits,
    /// @p h_edge at the fits' edges (the bonded joint's corners; h_fit or
    /// more: no grading of its own) and @p h_max away from them [m], and the
    /// nodes of @p refinement.
    SectionLayout(const std::vector<std::vector<AxialSection>> &sections,
                  const std::vector<double>                    &core_radius,
                  const std::vector<std::string>               &body_names,
                  const double                                  h_fit,
                  const double                                  h_edge,
                  const double                                  h_max,
                  const SectionRefinement                      &refinement);

    /// Axial ranges [z from, z to] where two bodies meet at one radius.
    const std::vector<std::pair<double, double>> &
    fit_zones() const
    {
      return zones;
    }

    /// The axial nodes, shared by every body, increasing [m].
    const std::vector<double> &
    axial_nodes() const
    {
      return z;
    }

    /// The chains of all bodies, body by body, in increasing z.
    const std::vector<Chain> &
    chains() const
    {
      return chain_list;
    }

    /// The sections of every body.
    const std::vector<std::vector<AxialSection>> &
    sections() const
    {
      return body_sections;
    }

    /// O-grid core radius of body @p b [m] (0: no solid section).
    double
    core_radius(const unsigned int b) const
    {
      return core_radii[b];
    }

    /// The section of @p body that holds @p z (the first at a shared plane).
    const AxialSection &
    section_at(const unsigned int body, const double z) const;

    /// Inner boundary of chain @p c at @p z in its section @p s [m]: the
    /// core radius of a solid chain.
    double
    inner_radius(const Chain &c, const AxialSection &s, const double z) const;

  private:
    void
    find_fits();
    std::vector<double>
    make_axial_nodes() const;
    std::vector<Chain>
    make_chains() const;
    void
    radial_fractions(std::vector<Chain> &chains) const;
    void
    merge_step_radii(std::vector<Chain> &chains) const;
    /// Element size at a distance @p d_fit from the nearest fit [m].
    /// Element size at distance @p d_fit from a fit and @p d_edge from a
    /// fit's edge.
    double
    size_at(const double d_fit, const double d_edge) const;

    const std::vector<std::vector<AxialSection>> &body_sections;
    const std::vector<double>                    &core_radii;
    const std::vector<std::string>               &body_names;
    const double                                  h_fit, h_edge, h_max;
    const SectionRefinement                      &refinement;

    std::vector<std::pair<double, double>> zones;
    std::vector<double>                    z;
    std::vector<Chain>                     chain_list;
  };
} // namespace rotorfit
