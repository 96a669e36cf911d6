#include <rotorfit/linear_algebra/row_block.h>

#include <algorithm>
#include <stdexcept>

namespace rotorfit
{
  void
  RowBlock::assign(std::vector<double> &&block, const std::size_t n_)
  {
    std::vector<double> dense = std::move(block); // (block may be this->values)
    n = n_;
    kept.clear();
    values.clear();
    if (n == 0 || dense.empty())
      return;
    if (dense.size() % n != 0)
      throw std::logic_error("RowBlock::assign: block size is not a multiple of the column length");
    const std::size_t m = dense.size() / n;
    std::vector<char> used(n, 0); // (column by column: one pass in memory order)
    for (std::size_t j = 0; j < m; ++j)
      for (std::size_t i = 0; i < n; ++i)
        used[i] |= dense[i + j * n] != 0;
    std::vector<unsigned int> nonzero;
    for (std::size_t i = 0; i < n; ++i)
      if (used[i])
        nonzero.push_back(i);
    if (nonzero.empty())
      return; // zero everywhere: nothing kept
    if (4 * nonzero.size() > n)
      {
        values = std::move(dense);
        return;
      }
    kept = std::move(nonzero);
    gather(dense.data(), m, values);
  }

  void
  RowBlock::clear()
  {
    std::vector<unsigned int>().swap(kept);
    std::vector<double>().swap(values);
  }

  void
  RowBlock::expand_column(const std::size_t j, double *full) const
  {
    const std::size_t r = n_rows();
    const double     *c = values.data() + j * r;
    if (dense())
      {
        std::copy(c, c + n, full);
        return;
      }
    std::fill(full, full + n, 0.);
    for (std::size_t i = 0; i < r; ++i)
      full[kept[i]] = c[i];
  }

  void
  RowBlock::add(const double a, const RowBlock &other)
  {
    if (other.empty())
      return;
    if (!empty() && n != other.n)
      throw std::logic_error("RowBlock::add: blocks of different column lengths");
    if (!empty() && kept == other.kept && values.size() == other.values.size())
      {
        for (std::size_t i = 0; i < values.size(); ++i)
          values[i] += a * other.values[i];
        if (dense()) // (rows may have cancelled)
          assign(std::move(values), n);
        return;
      }
    const std::size_t   m = other.n_columns();
    if (!empty() && n_columns() != m)
      throw std::logic_error("RowBlock::add: blocks of different column counts");
    const std::size_t   length = other.n;
    std::vector<double> sum(length * m, 0.), column(length);
    for (std::size_t j = 0; j < m; ++j)
      {
        if (!empty())
          expand_column(j, sum.data() + j * length);
        other.expand_column(j, column.data());
        for (std::size_t i = 0; i < length; ++i)
          sum[i + j * length] += a * column[i];
      }
    assign(std::move(sum), length);
  }

  void
  RowBlock::gather(const double *x, const std::size_t k, std::vector<double> &out) const
  {
    out.clear();
    if (dense())
      return;
    const std::size_t r = kept.size();
    out.resize(r * k);
    for (std::size_t j = 0; j < k; ++j)
      for (std::size_t i = 0; i < r; ++i)
        out[i + j * r] = x[kept[i] + j * n];
  }

  void
  RowBlock::rows_of(const RowBlock &other, std::vector<double> &out) const
  {
    const std::size_t r = n_rows(), m = other.n_columns(), ro = other.n_rows();
    out.assign(r * m, 0.);
    for (std::size_t i = 0; i < r; ++i)
      {
        const std::size_t row = dense() ? i : kept[i];
        std::size_t       at  = row; // its index in other's rows
        if (!other.dense())
          {
            const auto it = std::lower_bound(other.kept.begin(), other.kept.end(), row);
            if (it == other.kept.end() || *it != row)
              continue;
            at = it - other.kept.begin();
          }
        for (std::size_t j = 0; j < m; ++j)
          out[i + j * r] = other.values[at + j * ro];
      }
  }
} // namespace rotorfit
