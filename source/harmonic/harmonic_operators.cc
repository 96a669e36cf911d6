#include <rotorfit/harmonic/harmonic_operators.h>
#include <rotorfit/statics/speed_schedule.h>

#include <chrono>

namespace rotorfit
{
  using namespace dealii;

  HarmonicOperators::HarmonicOperators(const HarmonicAssembler         &assembler,
                                       const ContactSolver             &contact,
                                       const Bearings                  &bearings,
                                       const std::vector<unsigned int> &list,
                                       const std::vector<Station>      &stations,
                                       const Vector<double>            &stiffness_diagonal,
                                       const Settings                  &settings,
                                       const MPI_Comm                   comm)
    : assembler(assembler)
    , contact(contact)
    , bearings(bearings)
    , settings(settings)
  {
    const std::size_t n = list.size();
    matrices.resize(n);
    // (PETSc matrices cannot be moved: made in place)
    for (auto *p : {&petsc_m, &petsc_c, &petsc_k, &petsc_g, &petsc_k0, &petsc_k2})
      *p = std::vector<PETScWrappers::MPI::SparseMatrix>(n);
    law_k0 = std::vector<SparseMatrix<double>>(n);
    law_k2 = std::vector<SparseMatrix<double>>(n);
    law_number.assign(n, 0);
    bearing_directions.assign(n, {});
    for (unsigned int k = 0; k < n; ++k)
      {
        auto &h = matrices[k];
        assembler.assemble_harmonic(list[k], stations, h);
        // (M, K, G share the harmonic's pattern)
        copy_to_petsc(h.K,
                      {&petsc_m[k], &petsc_c[k], &petsc_k[k], &petsc_g[k], &petsc_k0[k],
                       &petsc_k2[k]},
                      comm);
        copy_values(h.M, petsc_m[k]);
        copy_values(h.G, petsc_g[k]);
        law_k0[k].reinit(h.pattern);
        law_k2[k].reinit(h.pattern);
        for (unsigned int b = 0; b < bearings.size() && h.n == 1; ++b)
          {
            bearing_directions[k].push_back(h.station_x[b]);
            bearing_directions[k].push_back(h.station_y[b]);
          }
      }
    // tie penalties from the radial stiffness of the two nodes (doc/theory.md 7.4)
    const auto &pairs = assembler.meridian().pairs().pairs();
    tie_penalty.resize(pairs.size());
    for (unsigned int i = 0; i < pairs.size(); ++i)
      tie_penalty[i] = settings.tie_scale * 0.5 *
                       (stiffness_diagonal[pairs[i].shaft_dofs[0]] +
                        stiffness_diagonal[pairs[i].hub_dofs[0]]);
  }

  void
  HarmonicOperators::prepare_prestress(const StaticState &s)
  {
    // K_sigma of the law's two parts, once per law (doc/theory.md 2.3, 3); a
    // tangent law (spin softening) is not affine: its whole field at w
    const bool   affine = s.decomposition().affine;
    const double omega  = SpeedSchedule::rpm_to_rad_per_s(s.rpm);
    if (!settings.prestress || (s.shared_law() == prestress_law && affine))
      return;
    PETScWrappers::MPI::Vector u0, u1;
    contact.displacement(s.decomposition(), affine ? 0. : omega * omega, u0);
    const Vector<double> u_I(u0);
    Vector<double>       u_C(u_I.size());
    if (affine && settings.centrifugal_prestress)
      {
        contact.displacement(s.decomposition(), 1., u1);
        u_C = Vector<double>(u1);
        u_C -= u_I;
      }
    k_sigma_I.resize(matrices.size());
    k_sigma_C.resize(matrices.size());
    for (unsigned int k = 0; k < matrices.size(); ++k)
      {
        k_sigma_I[k] = std::make_unique<SparseMatrix<double>>();
        k_sigma_C[k] = std::make_unique<SparseMatrix<double>>();
        assembler.assemble_prestress(matrices[k], u_I, *k_sigma_I[k]);
        assembler.assemble_prestress(matrices[k], u_C, *k_sigma_C[k]);
        n_prestress += 2;
      }
    prestress_law = s.shared_law();
  }

  std::size_t
  HarmonicOperators::law_matrices(const unsigned int hk, const StaticState &s)
  {
    const bool affine = s.decomposition().affine;
    if (s.shared_law() != law_of_matrices || (!affine && s.rpm != law_rpm) || n_laws == 0)
      {
        law_of_matrices = s.shared_law();
        law_rpm         = affine ? -1 : s.rpm;
        ++n_laws;
      }
    if (law_number[hk] == n_laws)
      return n_laws;
    prepare_prestress(s);
    const auto &h  = matrices[hk];
    auto       &k0 = law_k0[hk];
    auto       &k2 = law_k2[hk];
    k0.copy_from(h.K);
    k2 = 0;
    if (settings.prestress)
      {
        k0.add(1., *k_sigma_I[hk]);
        if (affine && settings.centrifugal_prestress)
          k2.add(1., *k_sigma_C[hk]);
        if (settings.centrifugal_prestress && settings.convective)
          k2.add(-1., h.K_theta);
      }
    assembler.add_ties(h, s.contact.active, tie_penalty, k0);
    copy_values(k0, petsc_k0[hk]);
    copy_values(k2, petsc_k2[hk]);
    law_number[hk] = n_laws;
    return n_laws;
  }

  std::vector<HarmonicReducedModel::Coupling>
  HarmonicOperators::bearing_couplings(const unsigned int hk, const double rpm) const
  {
    std::vector<HarmonicReducedModel::Coupling> list;
    for (unsigned int b = 0; b < bearings.size() && matrices[hk].n == 1; ++b)
      {
        Bearings::Coefficients kb, cb;
        bearings.coefficients(b, rpm, kb, cb);
        // (row direction, column direction) -> coefficient index
        const unsigned int index[2][2] = {{0, 2}, {3, 1}};
        for (unsigned int p = 0; p < 2; ++p)
          for (unsigned int q = 0; q < 2; ++q)
            if (kb[index[p][q]] != 0 || cb[index[p][q]] != 0)
              list.push_back({2 * b + p, 2 * b + q, kb[index[p][q]], cb[index[p][q]]});
      }
    return list;
  }

  HarmonicReducedModel::Operators
  HarmonicOperators::law_operators(const unsigned int hk) const
  {
    const auto &h = matrices[hk];
    return {&h.M,         &h.G,          &law_k0[hk],   &law_k2[hk], &petsc_m[hk],
            &petsc_g[hk], &petsc_k0[hk], &petsc_k2[hk], &bearing_directions[hk]};
  }

  void
  HarmonicOperators::speed_matrices(const unsigned int    hk,
                                  const StaticState    &s,
                                  SparseMatrix<double> &k,
                                  SparseMatrix<double> &c)
  {
    const double omega = SpeedSchedule::rpm_to_rad_per_s(s.rpm);
    law_matrices(hk, s);
    k.copy_from(law_k0[hk]);
    k.add(omega * omega, law_k2[hk]);
    c.copy_from(matrices[hk].G);
    c *= omega;
    const auto &a = bearing_directions[hk];
    for (const auto &cp : bearing_couplings(hk, s.rpm))
      for (const auto &[I, wi] : a[cp.p])
        for (const auto &[J, wj] : a[cp.q])
          {
            if (cp.k != 0)
              k.add(I, J, cp.k * wi * wj);
            if (cp.c != 0)
              c.add(I, J, cp.c * wi * wj);
          }
  }

  double
  HarmonicOperators::assemble_speed(const unsigned int k, const StaticState &s)
  {
    const auto           t0 = std::chrono::steady_clock::now();
    SparseMatrix<double> stiff(matrices[k].pattern), damp(matrices[k].pattern);
    speed_matrices(k, s, stiff, damp);
    copy_values(damp, petsc_c[k]);
    copy_values(stiff, petsc_k[k]);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
} // namespace rotorfit
