#include <rotorfit/base/dof_utilities.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/bearing/bearings.h>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>

#include <deal.II/fe/fe_values.h>

#include <deal.II/lac/full_matrix.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    const char *names[8] = {"kxx", "kyy", "kxy", "kyx", "cxx", "cyy", "cxy", "cyx"};

    /// Direct coefficients (xx, yy) must be >= 0; cross-coupling may have
    /// either sign.
    void
    check_coefficients(const std::string &where, const double *v)
    {
      for (unsigned int i = 0; i < 8; ++i)
        if (!std::isfinite(v[i]))
          throw InputError(where + ": " + names[i] + " = " + std::to_string(v[i]) +
                           " is not a finite number.");
      for (const unsigned int i : {0u, 1u, 4u, 5u})
        if (!(v[i] >= 0))
          throw InputError(where + ": " + names[i] + " = " + std::to_string(v[i]) +
                           (i < 4 ? " N/m" : " N s/m") +
                           " is negative; direct bearing stiffness and damping "
                           "must be >= 0.");
    }

    std::vector<std::array<double, 9>>
    read_table(const std::string &file, const std::string &entry)
    {
      std::ifstream in(file);
      if (!in)
        throw InputError(entry + " = '" + file + "': the file cannot be read.");
      std::vector<std::array<double, 9>> rows;
      std::string                        line;
      unsigned int                       line_no = 0;
      while (std::getline(in, line))
        {
          ++line_no;
          if (line.find_first_not_of(" \t\r") == std::string::npos ||
              line[line.find_first_not_of(" \t")] == '#' ||
              line.find("speed") != std::string::npos)
            continue;
          std::replace(line.begin(), line.end(), ',', ' ');
          std::istringstream     s(line);
          std::array<double, 9> r;
          for (auto &x : r)
            if (!(s >> x))
              throw InputError(file + ":" + std::to_string(line_no) +
                               ": expected 9 numbers (speed_rpm, kxx, kyy, kxy, "
                               "kyx, cxx, cyy, cxy, cyx).");
          check_coefficients(file + ":" + std::to_string(line_no), r.data() + 1);
          if (!rows.empty() && !(r[0] > rows.back()[0]))
            throw InputError(file + ":" + std::to_string(line_no) +
                             ": speeds must increase from row to row.");
          rows.push_back(r);
        }
      if (rows.empty())
        throw InputError(entry + " = '" + file + "': no data rows.");
      return rows;
    }
  } // namespace

  void
  Bearings::declare_list(ParameterHandler &prm)
  {
    prm.declare_entry("Bearings",
                      "",
                      Patterns::List(Patterns::Anything(), 0),
                      "Names of the bearings (empty: free-free rotor). Each "
                      "needs a subsection 'Bearing <name>'.");
  }

  void
  Bearings::declare_parameters(ParameterHandler               &prm,
                               const std::vector<std::string> &list)
  {
    for (const auto &name : list)
      {
        prm.enter_subsection("Bearing " + name);
        Station::declare_parameters(prm, "the bearing");
        // direct terms (xx, yy) >= 0, cross terms any sign
        for (unsigned int i = 0; i < 8; ++i)
          prm.declare_entry(names[i],
                            "0",
                            names[i][1] == names[i][2] ? Patterns::Double(0) : Patterns::Double(),
                            i < 4 ? "Stiffness [N/m] (xx, yy >= 0; cross terms any sign)." :
                                    "Damping [N s/m] (xx, yy >= 0; cross terms any sign).");
        prm.declare_entry("Coefficient table",
                          "",
                          Patterns::Anything(),
                          "Optional CSV file (relative to the .prm) with rows "
                          "speed_rpm, kxx, kyy, kxy, kyx, cxx, cyy, cxy, cyx; "
                          "interpolated linearly in speed, held constant beyond "
                          "its ends. Replaces the constant coefficients.");
        prm.leave_subsection();
      }
  }

  void
  Bearings::parse_parameters(ParameterHandler &prm, const std::string &dir)
  {
    bearings.clear();
    for (const auto &name : Utilities::split_string_list(prm.get("Bearings"), ','))
      {
        prm.enter_subsection("Bearing " + name);
        Bearing b;
        b.name    = name;
        b.station.parse_parameters(prm, "Bearing " + name);
        double v[8];
        for (unsigned int i = 0; i < 8; ++i)
          v[i] = prm.get_double(names[i]);
        std::copy(v, v + 4, b.k.begin());
        std::copy(v + 4, v + 8, b.c.begin());
        b.table_file = prm.get("Coefficient table");
        if (!b.table_file.empty())
          {
            const std::filesystem::path p(b.table_file);
            const std::string file = p.is_absolute() ? b.table_file : dir + "/" + b.table_file;
            b.table = read_table(file, "Bearing " + name + "/Coefficient table");
          }
        prm.leave_subsection();
        bearings.push_back(b);
      }
  }

  void
  Bearings::setup(const Discretization &model, Log &log)
  {
    for (auto &b : bearings)
      b.station.setup(model, log);
  }

  void
  Bearings::add_sparsity(DynamicSparsityPattern &dsp) const
  {
    for (const auto &b : bearings)
      {
        std::vector<types::global_dof_index> all(b.station.dof_x);
        all.insert(all.end(), b.station.dof_y.begin(), b.station.dof_y.end());
        std::sort(all.begin(), all.end());
        for (const auto i : all)
          if (dsp.row_index_set().size() == 0 || dsp.row_index_set().is_element(i))
            dsp.add_entries(i, all.begin(), all.end(), true);
      }
  }

  bool
  Bearings::speed_dependent() const
  {
    for (const auto &b : bearings)
      if (b.table.size() > 1)
        return true;
    return false;
  }

  bool
  Bearings::symmetric(const double rpm, const bool damping_too) const
  {
    for (unsigned int n = 0; n < bearings.size(); ++n)
      {
        Coefficients k, c;
        coefficients(n, rpm, k, c);
        if (k[2] != k[3] || (damping_too && c[2] != c[3]))
          return false;
      }
    return true;
  }

  bool
  Bearings::isotropic(const double rpm) const
  {
    for (unsigned int n = 0; n < size(); ++n)
      {
        Coefficients k, c;
        coefficients(n, rpm, k, c);
        for (const auto &a : {k, c})
          if (a[0] != a[1] || a[2] != -a[3])
            return false;
      }
    return true;
  }

  void
  Bearings::coefficients(const unsigned int n,
                         const double       rpm,
                         Coefficients      &k,
                         Coefficients      &c) const
  {
    const Bearing &b = bearings[n];
    if (b.table.empty())
      {
        k = b.k;
        c = b.c;
        return;
      }
    std::array<double, 9> r = b.table.front();
    if (rpm >= b.table.back()[0])
      r = b.table.back();
    else if (rpm > b.table.front()[0])
      for (unsigned int i = 1; i < b.table.size(); ++i)
        if (rpm <= b.table[i][0])
          {
            const double t = (rpm - b.table[i - 1][0]) / (b.table[i][0] - b.table[i - 1][0]);
            for (unsigned int j = 0; j < 9; ++j)
              r[j] = (1 - t) * b.table[i - 1][j] + t * b.table[i][j];
            break;
          }
    std::copy(r.begin() + 1, r.begin() + 5, k.begin());
    std::copy(r.begin() + 5, r.end(), c.begin());
  }

  void
  Bearings::assemble(const double                      rpm,
                     PETScWrappers::MPI::SparseMatrix &k_matrix,
                     PETScWrappers::MPI::SparseMatrix &c_matrix) const
  {
    const auto range = k_matrix.local_range();
    for (unsigned int n = 0; n < bearings.size(); ++n)
      {
        const Station &b = bearings[n].station;
        Coefficients   k, c;
        coefficients(n, rpm, k, c);
        // (row direction, column direction) -> coefficient index
        const unsigned int index[2][2] = {{0, 2}, {3, 1}};
        const std::vector<types::global_dof_index> *dof[2] = {&b.dof_x, &b.dof_y};
        for (unsigned int a = 0; a < 2; ++a)
          for (unsigned int i = 0; i < b.weight.size(); ++i)
            {
              const auto row = (*dof[a])[i];
              if (row < range.first || row >= range.second)
                continue;
              for (unsigned int d = 0; d < 2; ++d)
                {
                  const double kk = k[index[a][d]], cc = c[index[a][d]];
                  if (kk == 0 && cc == 0)
                    continue;
                  for (unsigned int j = 0; j < b.weight.size(); ++j)
                    {
                      const double ww = b.weight[i] * b.weight[j];
                      if (kk != 0)
                        k_matrix.add(row, (*dof[d])[j], kk * ww);
                      if (cc != 0)
                        c_matrix.add(row, (*dof[d])[j], cc * ww);
                    }
                }
            }
      }
    k_matrix.compress(VectorOperation::add);
    c_matrix.compress(VectorOperation::add);
  }
} // namespace rotorfit
