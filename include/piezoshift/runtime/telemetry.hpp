#pragma once
// One loop tick as handed to the logging thread (through SpscRing), and the CSV columns it
// becomes. Plain, trivially copyable, fixed size: copying it is the loop's whole logging cost.
#include <cstdint>

#include "piezoshift/control/vec3.hpp"

namespace piezoshift::runtime {

using control::Vec3;

struct TelemetryRecord {
  std::uint64_t tick = 0;
  double t_s = 0.0;          //!< scheduled time since the loop started
  Vec3 zd_um{};              //!< Z_d, desired displacements of P1..P3
  Vec3 target_um{};          //!< S, actuator targets (SGS um)
  Vec3 sgs_V{};              //!< the three AI as read
  Vec3 request_V{};          //!< the controller's outputs
  Vec3 ao_V{};               //!< the supervisor's outputs, sent to the DAQ
  Vec3 truth_um{};           //!< the twin's true Z1..Z3 (NaN on hardware)
  Vec3 interferometer_um{};  //!< the twin's interferometer (NaN on hardware)
  double wake_latency_us = 0.0;
  double compute_us = 0.0;
  std::uint8_t overrun = 0;
  std::uint8_t limited = 0;
  std::uint8_t held = 0;          //!< integrators frozen this tick
  std::uint8_t state = 0;         //!< SupervisorState as a number
  std::uint8_t fault_reason = 0;  //!< FaultReason as a number (0 = none)
  std::int8_t fault_channel = -1;
  std::uint8_t read_status = 0;  //!< DaqStatus as a number
  std::uint8_t write_status = 0;
};

}  // namespace piezoshift::runtime
