#include <rotorfit/linear_algebra/blas.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/eigen/reduced_basis.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/lapack_full_matrix.h>

#include <algorithm>
#include <cmath>

namespace rotorfit
{
  using namespace dealii;

  void
  ReducedBasis::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Eigenproblem");
    prm.declare_entry("Reduced model",
                      "true",
                      Patterns::Bool(),
                      "Solve speeds on a reduced model built from full solves at "
                      "anchor speeds (doc/theory.md 8.6; on the axisymmetric model "
                      "one per harmonic, with the unbalance response on harmonic "
                      "1's basis, 14.6); every reduced mode is "
                      "checked on the full matrices and a speed that fails the "
                      "check is solved in full. false: the full solve at every "
                      "speed.");
    prm.declare_entry("Reduced tolerance",
                      "1e-7",
                      patterns::Positive(),
                      "Estimated relative eigenvalue error |d lambda| / |lambda| "
                      "every wanted mode of a reduced solve must meet, from its "
                      "right and left residuals on the full matrices (doc/theory.md "
                      "8.6); damping ratios are then good to this absolute. A speed "
                      "whose modes miss it is solved in full and becomes an anchor [-].");
    prm.declare_entry("Reduced margin modes",
                      "6",
                      Patterns::Integer(1),
                      "Whirl pairs (damped anchors) or undamped modes (undamped "
                      "anchors) an anchor solves beyond the Number of modes: the "
                      "basis then covers the modes that can move into the wanted "
                      "range between anchors. A damped anchor skips them where the "
                      "tied pairs differ from the previous solve's and a fit is part "
                      "open, part closed (in a fit opening step by step such a basis "
                      "serves no second speed).");
    prm.declare_entry("Reduced slope bound",
                      "2",
                      patterns::Positive(),
                      "Largest |d omega / d Omega| assumed for any line, also those "
                      "above the basis [-]: a reduced solve is refused where a mode "
                      "outside the basis could have moved into the wanted range since "
                      "the nearest anchor (2 covers gyroscopic lateral modes, Ip / Id "
                      "<= 2; an n-diameter disc mode moves n times the spin).");
    prm.declare_entry("Reduced anchors",
                      "undamped",
                      Patterns::Selection("undamped|damped"),
                      "What a new basis is built from (doc/theory.md 8.7). undamped: "
                      "the lowest modes of K_t phi = omega^2 M phi at the anchor speed "
                      "(an LDL^T of K_t + sigma^2 M and symmetric Lanczos: half the "
                      "memory of the LU) with each mode's gyroscopic, damping and "
                      "stiffening directions; the anchor speed itself is then solved "
                      "on that basis with every check of a reduced speed, and in full "
                      "(damped) where they fail. damped: the full damped solve (LU of "
                      "Q(sigma), Arnoldi) at every anchor. Cross-coupled bearings "
                      "(k_xy != k_yx) always take the damped one, and so does the "
                      "axisymmetric model (the entry is not read there).");
    prm.declare_entry("Reduced anchor tie updates",
                      "256",
                      Patterns::Integer(0),
                      "Where a new contact segment needs an undamped anchor and its "
                      "ties differ from those of the last LDL^T of K_t + sigma^2 M "
                      "by at most this many tie springs (a pair opened or closed: "
                      "one spring, three on a bonded fit), the anchor solves on "
                      "that factorisation with a low-rank (Woodbury) update of the "
                      "changed ties instead of a new one (doc/theory.md 8.7): one "
                      "back-substitution per spring and n x springs numbers of "
                      "memory. Refused anchors are made again on a new LDL^T. "
                      "0: a new LDL^T for every anchor.");
    prm.leave_subsection();
  }

  void
  ReducedBasis::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Eigenproblem");
    use                = prm.get_bool("Reduced model");
    max_error = prm.get_double("Reduced tolerance");
    extra_modes        = prm.get_integer("Reduced margin modes");
    max_slope          = prm.get_double("Reduced slope bound");
    undamped           = prm.get("Reduced anchors") == "undamped";
    max_tie_updates    = prm.get_integer("Reduced anchor tie updates");
    prm.leave_subsection();
  }

  void
  ReducedBasis::clear()
  {
    std::vector<double>().swap(flat); // its memory too (add() sizes it exactly)
    columns = 0;
    anchors.clear();
    ++serial;
  }

  void
  ReducedBasis::subtract_projection(Vector<double> &v, const Vector<double> &mv) const
  {
    const int n = v.size(), m = columns, one = 1;
    if (m == 0)
      return;
    const double        plus = 1, minus = -1, zero = 0;
    std::vector<double> c(m);
    // v -= V V^T M v (V is M-orthonormal)
    dgemv_("T", &n, &m, &plus, flat.data(), &n, mv.data(), &one, &zero, c.data(), &one);
    dgemv_("N", &n, &m, &minus, flat.data(), &n, c.data(), &one, &plus, v.data(), &one);
  }

  std::vector<double>
  ReducedBasis::coefficients(const Vector<double> &x) const
  {
    std::vector<double> c(columns);
    if (columns == 0)
      return c;
    const int    n = rows, m = columns, one = 1;
    const double plus = 1, zero = 0;
    dgemv_("T", &n, &m, &plus, flat.data(), &n, x.data(), &one, &zero, c.data(), &one);
    return c;
  }

  std::vector<double>
  ReducedBasis::coefficients(const std::vector<const Vector<double> *> &x) const
  {
    const int           n = rows, m = columns, k = x.size();
    std::vector<double> c(std::size_t(m) * k, 0.);
    if (m == 0 || k == 0)
      return c;
    std::vector<double> X(std::size_t(n) * k);
    for (int j = 0; j < k; ++j)
      std::copy(x[j]->begin(), x[j]->end(), X.begin() + std::size_t(j) * n);
    const double one = 1, zero = 0;
    dgemm_("T", "N", &m, &k, &n, &one, flat.data(), &n, X.data(), &n, &zero, c.data(), &m);
    return c;
  }

  bool
  ReducedBasis::add(const Vector<double> &x, const PETScWrappers::MPI::SparseMatrix &M)
  {
    return add(std::vector<const Vector<double> *>{&x}, M) == 1;
  }

  unsigned int
  ReducedBasis::add(const std::vector<const Vector<double> *> &x,
                    const PETScWrappers::MPI::SparseMatrix    &M)
  {
    const int k = x.size();
    if (k == 0)
      return 0;
    const int           n = x[0]->size(), m = columns;
    const std::size_t   size = std::size_t(n) * k;
    std::vector<double> X(size), MX(size);
    for (int j = 0; j < k; ++j)
      std::copy(x[j]->begin(), x[j]->end(), X.begin() + std::size_t(j) * n);
    replicated_mmult(M, X.data(), k, MX.data());
    const auto dot = [n](const double *a, const double *b) {
      double s = 0;
      for (int i = 0; i < n; ++i)
        s += a[i] * b[i];
      return s;
    };
    std::vector<double> first(k);
    for (int j = 0; j < k; ++j)
      first[j] = std::sqrt(std::max(0., dot(X.data() + std::size_t(j) * n, MX.data() + std::size_t(j) * n)));
    // against the basis (V M-orthonormal): classical Gram-Schmidt twice,
    // the block at once, with M X made anew after each pass
    const double one = 1, minus = -1, zero = 0;
    if (m > 0)
      for (unsigned int pass = 0; pass < 2; ++pass)
        {
          std::vector<double> c(std::size_t(m) * k);
          dgemm_("T", "N", &m, &k, &n, &one, flat.data(), &n, MX.data(), &n, &zero, c.data(), &m);
          dgemm_("N", "N", &n, &k, &m, &minus, flat.data(), &n, c.data(), &m, &one, X.data(), &n);
          replicated_mmult(M, X.data(), k, MX.data());
        }
    // within the block, column after column; M X follows by the same
    // combinations, and the kept columns' norms come from a new product
    std::vector<int> kept;
    for (int j = 0; j < k; ++j)
      {
        double *v = X.data() + std::size_t(j) * n, *mv = MX.data() + std::size_t(j) * n;
        for (unsigned int pass = 0; pass < 2; ++pass)
          for (const int i : kept)
            {
              const double *u = X.data() + std::size_t(i) * n, *mu = MX.data() + std::size_t(i) * n;
              const double  c = dot(mu, v);
              for (int r = 0; r < n; ++r)
                v[r] -= c * u[r], mv[r] -= c * mu[r];
            }
        const double norm = std::sqrt(std::max(0., dot(v, mv)));
        // one decision for all ranks (their bases must stay the same size)
        if (Utilities::MPI::min(first[j] > 0 && norm > 1e-10 * first[j] ? 1 : 0,
                                M.get_mpi_communicator()) == 0)
          continue;
        for (int r = 0; r < n; ++r)
          v[r] /= norm, mv[r] /= norm;
        kept.push_back(j);
      }
    if (kept.empty())
      return 0;
    const int           added = kept.size();
    std::vector<double> K(std::size_t(n) * added), MK(K.size());
    for (int j = 0; j < added; ++j)
      std::copy(X.begin() + std::size_t(kept[j]) * n, X.begin() + std::size_t(kept[j] + 1) * n,
                K.begin() + std::size_t(j) * n);
    replicated_mmult(M, K.data(), added, MK.data());
    for (int j = 0; j < added; ++j)
      {
        double      *v = K.data() + std::size_t(j) * n;
        const double s = std::sqrt(std::max(0., dot(v, MK.data() + std::size_t(j) * n)));
        for (int r = 0; r < n; ++r)
          v[r] /= s;
      }
    rows = n;
    // to the exact size: insert() alone would double the capacity (65 MB
    // held for TS's 35 MB basis of 69 columns)
    flat.reserve(flat.size() + K.size());
    flat.insert(flat.end(), K.begin(), K.end());
    columns += added;
    ++serial;
    return added;
  }

  void
  ReducedBasis::multiply(const RowBlock                                       *P,
                         const std::vector<std::vector<std::complex<double>>> &y,
                         const double                                          a,
                         const std::vector<ComplexVector *>                   &z) const
  {
    const int m = columns, k = y.size();
    if (m == 0 || k == 0 || (P ? P->empty() : flat.empty()))
      return;
    // one pass over A: [A y_re | A y_im] = A [Y_re | Y_im] (dgemm) on the
    // rows A keeps, added into those rows of z
    const double *A = P ? P->data().data() : flat.data();
    const int     r = P ? P->n_rows() : rows, n = rows, two_k = 2 * k;
    const std::vector<unsigned int> *kept = P && !P->dense() ? &P->kept_rows() : nullptr;
    std::vector<double> b(static_cast<std::size_t>(m) * two_k), out(std::size_t(r) * two_k);
    for (int c = 0; c < k; ++c)
      for (int j = 0; j < m; ++j)
        {
          b[j + std::size_t(c) * m]     = y[c][j].real();
          b[j + std::size_t(k + c) * m] = y[c][j].imag();
        }
    const double one = 1, zero = 0;
    dgemm_("N", "N", &r, &two_k, &m, &one, A, &r, b.data(), &m, &zero, out.data(), &r);
    for (int c = 0; c < k; ++c)
      {
        ComplexVector &t = *z[c];
        if (t.re.size() != static_cast<std::size_t>(n))
          t = {Vector<double>(n), Vector<double>(n)};
        const double *re = out.data() + std::size_t(c) * r, *im = re + std::size_t(k) * r;
        for (int i = 0; i < r; ++i)
          {
            const std::size_t row = kept ? (*kept)[i] : i;
            t.re[row] += a * re[i];
            t.im[row] += a * im[i];
          }
      }
  }

  void
  ReducedBasis::apply_transpose(const RowBlock            &P,
                                const std::vector<double> &X,
                                const double               a,
                                std::vector<double>       &C) const
  {
    const int m = columns;
    if (m == 0 || P.empty() || X.empty())
      return;
    const int k = X.size() / rows, r = P.n_rows();
    if (C.size() != std::size_t(m) * k)
      C.assign(std::size_t(m) * k, 0.);
    std::vector<double> rows_of_x; // X at P's rows (X itself where P is dense)
    P.gather(X.data(), k, rows_of_x);
    const double  plus = 1;
    const double *x    = P.dense() ? X.data() : rows_of_x.data();
    dgemm_("T", "N", &m, &k, &r, &a, P.data().data(), &r, x, &r, &plus, C.data(), &m);
  }

  FullMatrix<double>
  ReducedBasis::project(const PETScWrappers::MPI::SparseMatrix &A, RowBlock *products) const
  {
    const int m = columns;
    FullMatrix<double> P(m, m);
    if (m == 0)
      return P;
    const int           n = rows;
    std::vector<double> av(flat.size());
    replicated_mmult(A, flat.data(), m, av.data());
    std::vector<double> p(static_cast<std::size_t>(m) * m);
    const double        one = 1, zero = 0;
    dgemm_("T", "N", &m, &m, &n, &one, flat.data(), &n, av.data(), &n, &zero, p.data(), &m);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        P(i, j) = p[i + std::size_t(j) * m];
    if (products)
      products->assign(std::move(av), n);
    return P;
  }

  bool
  ReducedBasis::solve(const FullMatrix<double> &Mr,
                      const FullMatrix<double> &Cr,
                      const FullMatrix<double> &Kr,
                      std::vector<Pair>        &pairs) const
  {
    // first companion form with Mr^-1 applied: z = (y, lambda y),
    // [0 I; -Mr^-1 Kr  -Mr^-1 Cr] z = lambda z
    const int m = Mr.m(), n2 = 2 * m;
    pairs.clear();
    if (m == 0)
      return true;
    LAPACKFullMatrix<double> inverse(m, m);
    inverse = Mr;
    inverse.invert();
    FullMatrix<double> mk(m, m), mc(m, m), mi(m, m);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        mi(i, j) = inverse(i, j);
    mi.mmult(mk, Kr);
    mi.mmult(mc, Cr);
    std::vector<double> a(static_cast<std::size_t>(n2) * n2, 0.); // column-major
    const auto at = [&](int i, int j) -> double & { return a[i + std::size_t(j) * n2]; };
    for (int i = 0; i < m; ++i)
      {
        at(i, m + i) = 1;
        for (int j = 0; j < m; ++j)
          {
            at(m + i, j)     = -mk(i, j);
            at(m + i, m + j) = -mc(i, j);
          }
      }
    std::vector<double> wr(n2), wi(n2), vr(static_cast<std::size_t>(n2) * n2), vl(vr.size()),
      work(1);
    int lwork = -1, info = 0;
    dgeev_("V", "V", &n2, a.data(), &n2, wr.data(), wi.data(), vl.data(), &n2, vr.data(), &n2,
           work.data(), &lwork, &info);
    lwork = static_cast<int>(work[0]);
    work.resize(std::max(1, lwork));
    dgeev_("V", "V", &n2, a.data(), &n2, wr.data(), wi.data(), vl.data(), &n2, vr.data(), &n2,
           work.data(), &lwork, &info);
    if (info != 0)
      return false;
    for (int j = 0; j < n2; ++j)
      {
        if (!std::isfinite(wr[j]) || !std::isfinite(wi[j]))
          return false;
        Pair p;
        p.lambda = {wr[j], wi[j]};
        p.y.resize(m);
        std::vector<std::complex<double>> b(m); // second block of the left vector
        const bool complex_pair = wi[j] != 0;
        // LAPACK: columns j, j + 1 hold Re and Im of the Im > 0 member
        for (int i = 0; i < m; ++i)
          {
            const std::size_t re = i + std::size_t(j) * n2, im = re + n2;
            p.y[i] = complex_pair ? std::complex<double>(vr[re], vr[im]) : vr[re];
            const std::size_t lre = m + re, lim = m + im;
            b[i] = complex_pair ? std::complex<double>(vl[lre], vl[lim]) : vl[lre];
          }
        // u^H A = lambda u^H with u = (a, b) gives b^H Mr^-1 Q_r(lambda) = 0
        p.w.assign(m, 0.);
        for (int i = 0; i < m; ++i)
          for (int k = 0; k < m; ++k)
            p.w[i] += mi(k, i) * b[k];
        if (complex_pair)
          ++j;
        pairs.push_back(std::move(p));
      }
    return true;
  }

  ComplexVector
  ReducedBasis::expand(const std::vector<std::complex<double>> &y) const
  {
    ComplexVector phi{Vector<double>(rows), Vector<double>(rows)};
    multiply(nullptr, {y}, 1., {&phi});
    return phi;
  }
} // namespace rotorfit
