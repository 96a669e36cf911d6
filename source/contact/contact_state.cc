#include <rotorfit/contact/contact_state.h>

namespace rotorfit
{
  void
  ContactDecomposition::evaluate(const double w, ContactState &state) const
  {
    const unsigned int n = force_I.size();
    state.force.resize(n);
    state.gap.resize(n);
    state.pressure.resize(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        state.force[i]    = force_I[i] + w * force_C[i];
        state.gap[i]      = gap_I[i] + w * gap_C[i];
        state.pressure[i] = pressure_I[i] + w * pressure_C[i];
      }
  }
} // namespace rotorfit
