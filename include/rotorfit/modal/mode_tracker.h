#pragma once

#include <rotorfit/modal/whirl.h>

#include <deal.II/base/parameter_handler.h>

#include <string>
#include <vector>

namespace rotorfit
{
  /// A tracked line crossing an excitation order k X: a row of critical_speeds.csv.
  struct CriticalSpeed
  {
    unsigned int tracked_id = 0;
    std::string  whirl;
    unsigned int order = 1;
    double       rpm = 0, frequency_hz = 0;
    double       damping_ratio = 0; ///< of the line at the crossing
    /// the speeds around it and f - k rpm / 60 there [Hz] (the root solve's bracket)
    double       from_rpm = 0, from_value = 0, to_rpm = 0, to_value = 0;
    unsigned int eigen_solves = 0;     ///< of the root solve
    bool         solved       = false; ///< by the root solve (else interpolated)
    /// axisymmetric model: the line's harmonic and travel direction (3D: -1),
    /// and its mode number within the harmonic at the crossing (0: unsolved)
    int          harmonic = -1;
    std::string  travel;
    unsigned int mode = 0;
  };

  /**
   * The lines of the Campbell diagram (doc/theory.md 9.4, 9.5): a mode continues
   * the line of the previous speed's mode it resembles most by the
   * mass-weighted complex MAC (forward and backward members of a family are
   * M-orthogonal, so they are never confused), greedily, best first, and
   * only between modes of the same whirl direction. A line that changes
   * sign against k X between two speeds crosses it between them: the
   * linearly interpolated speed here, solved by ModalAnalysis::solve_crossings.
   */
  class ModeTracker
  {
  public:
    ModeTracker() = default;
    /// From "MAC threshold" and "Excitation orders" of subsection
    /// Eigenproblem (declared by ModalAnalysis), the one @p prm is in.
    static ModeTracker
    from_parameters(const dealii::ParameterHandler &prm);
    ModeTracker(const std::vector<unsigned int> &orders, const double mac_threshold)
      : orders(orders)
      , threshold(mac_threshold)
    {}

    /// Set the tracked ids of @p modes; the crossings since the previous speed.
    std::vector<CriticalSpeed>
    track(const double rpm, std::vector<WhirlMode> &modes);

    /// Complex MAC with the mass matrix: |a^H M b|^2 / (a^H M a  b^H M b).
    static double
    mac(const ComplexVector &a, const ComplexVector &m_a,
        const ComplexVector &b, const ComplexVector &m_b);

  private:
    struct Line
    {
      unsigned int  id;
      double        frequency_hz;
      double        damping_ratio;
      std::string   whirl;
      /// the vector and phi^H M phi: the MAC with the next speed's modes
      /// needs M phi of those alone (a copy of M phi here was 12 MB on TS,
      /// held through every speed's eigen solve)
      ComplexVector phi;
      double        m_norm;
    };

    std::vector<Line>         previous;
    double                    previous_rpm = 0;
    unsigned int              next_id      = 1;
    std::vector<unsigned int> orders{1};
    double                    threshold = 0.8;
  };
} // namespace rotorfit
