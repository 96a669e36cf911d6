#pragma once

#include <cstddef>
#include <vector>

namespace rotorfit
{
  /// Columns of n-long replicated vectors (column-major), kept by their
  /// nonzero rows alone where few rows are nonzero. The reduced model keeps
  /// products A V of the basis V; the bearings' damping C_b is nonzero only
  /// on the bearings' DoFs, and its product, stored dense, was 35 MB of TS's
  /// memory peak (a hundredth of its rows are nonzero).
  class RowBlock
  {
  public:
    /// Takes the dense n x m block @p dense (column-major) and keeps only
    /// its rows that are nonzero in some column if they are at most a
    /// quarter of n; a block that is zero everywhere keeps nothing (empty()).
    void
    assign(std::vector<double> &&dense, std::size_t n);
    /// Back to an empty block.
    void
    clear();

    bool
    empty() const
    {
      return values.empty();
    }
    /// all n rows kept
    bool
    dense() const
    {
      return kept.empty();
    }
    /// the rows kept: n, or kept_rows().size()
    std::size_t
    n_rows() const
    {
      return dense() ? n : kept.size();
    }
    /// the columns (0 where empty())
    std::size_t
    n_columns() const
    {
      return empty() ? 0 : values.size() / n_rows();
    }
    /// length of a full column
    std::size_t
    size() const
    {
      return n;
    }
    /// the kept rows, ascending (empty where dense())
    const std::vector<unsigned int> &
    kept_rows() const
    {
      return kept;
    }
    /// n_rows() x n_columns(), column-major
    const std::vector<double> &
    data() const
    {
      return values;
    }
    /// this += a other (any layouts). A dense result keeps only its nonzero
    /// rows if they are few; one of the same kept rows keeps those.
    void
    add(double a, const RowBlock &other);
    /// full[0..n) = column j
    void
    expand_column(std::size_t j, double *full) const;
    /// out (r x k, column-major) = the rows of the dense n x k block @p x
    /// (leading dimension n) at kept_rows(), r = n_rows(): what this block's
    /// transpose multiplies (x itself where dense(): then out is left empty)
    void
    gather(const double *x, std::size_t k, std::vector<double> &out) const;
    /// out (r x other.n_columns()) = the rows of @p other at this block's
    /// rows (zero where other keeps none): so that this^T other is one dgemm
    void
    rows_of(const RowBlock &other, std::vector<double> &out) const;

  private:
    std::size_t               n = 0;
    std::vector<unsigned int> kept;
    std::vector<double>       values;
  };
} // namespace rotorfit
