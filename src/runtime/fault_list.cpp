#include "piezoshift/runtime/fault_list.hpp"

namespace piezoshift::runtime {

const char* value_unit(FaultReason reason) noexcept {
  switch (reason) {
    case FaultReason::kSgsNotFinite:
    case FaultReason::kSgsRail:
    case FaultReason::kSgsRange:
    case FaultReason::kSgsJump:
    case FaultReason::kSaturation:
    case FaultReason::kOutputNotFinite:
      return "V";
    case FaultReason::kTracking:
    case FaultReason::kResponse:
      return "um";
    case FaultReason::kOverruns:
      return "ticks";
    case FaultReason::kOscillation:
      return "reversals";
    case FaultReason::kNone:
    case FaultReason::kDaqRead:  // a DaqStatus code
    case FaultReason::kDaqWrite:
      return "";
  }
  return "";
}

}  // namespace piezoshift::runtime
