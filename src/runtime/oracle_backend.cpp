#include "piezoshift/runtime/oracle_backend.hpp"

namespace piezoshift::runtime {

OracleBackend::OracleBackend(SimBackend& sim, const control::TransmissionMatrix& matrix,
                             const std::array<control::SignalScaling, control::kChannels>& scaling,
                             const control::OracleNotches& notches, double sample_time_s)
    : sim_(sim), matrix_(matrix), scaling_(scaling) {
  for (auto& channel : notch_)
    for (std::size_t n = 0; n < notches.size(); ++n)
      channel[n] = control::NotchFilter(notches[n], sample_time_s);
}

DaqStatus OracleBackend::read(const CycleTime& t, Vec3& ai_V) noexcept {
  const DaqStatus status = sim_.read(t, ai_V);
  if (status != DaqStatus::kOk)
    return status;
  Vec3 z{}, ifm{};
  sim_.truth(z, ifm);
  const Vec3 s = matrix_(z);
  for (std::size_t i = 0; i < ai_V.size(); ++i) {
    double fed_um = s[i];
    for (control::NotchFilter& f : notch_[i])
      fed_um = f.update(fed_um);
    ai_V[i] = scaling_[i].sgs_offset_V + fed_um / scaling_[i].sgs_um_per_V;
  }
  return status;
}

}  // namespace piezoshift::runtime
