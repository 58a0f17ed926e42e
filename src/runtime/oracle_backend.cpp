#include "piezoshift/runtime/oracle_backend.hpp"

namespace piezoshift::runtime {

OracleBackend::OracleBackend(SimBackend& sim, const control::TransmissionMatrix& matrix,
                             const std::array<control::SignalScaling, control::kChannels>& scaling)
    : sim_(sim), matrix_(matrix), scaling_(scaling) {}

DaqStatus OracleBackend::read(const CycleTime& t, Vec3& ai_V) noexcept {
  const DaqStatus status = sim_.read(t, ai_V);
  if (status != DaqStatus::kOk)
    return status;
  Vec3 z{}, ifm{};
  sim_.truth(z, ifm);
  const Vec3 s = matrix_(z);
  for (std::size_t i = 0; i < ai_V.size(); ++i)
    ai_V[i] = scaling_[i].sgs_offset_V + s[i] / scaling_[i].sgs_um_per_V;
  return status;
}

}  // namespace piezoshift::runtime
