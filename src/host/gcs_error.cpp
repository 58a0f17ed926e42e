#include "piezoshift/host/gcs_error.hpp"

namespace piezoshift::host {

const char* describe(GcsError error) noexcept {
  switch (error) {
    case GcsError::kNone:
      return "No error";
    case GcsError::kParamSyntax:
      return "Parameter syntax error";
    case GcsError::kUnknownCommand:
      return "Unknown command";
    case GcsError::kCommandTooLong:
      return "Command length out of limits";
    case GcsError::kServoOff:
      return "Move attempted with servo off";
    case GcsError::kPositionOutOfLimits:
      return "Position out of limits";
    case GcsError::kVelocityOutOfLimits:
      return "Velocity out of limits";
    case GcsError::kStopped:
      return "Controller was stopped by command";
    case GcsError::kInvalidAxis:
      return "Invalid axis identifier";
    case GcsError::kParamOutOfRange:
      return "Parameter out of range";
    case GcsError::kDoubleAxis:
      return "Axis identifier specified more than once";
    case GcsError::kParamCount:
      return "Incorrect number of parameters";
    case GcsError::kInvalidReal:
      return "Invalid floating point number";
    case GcsError::kCommunication:
      return "Controller detected communication error";
    case GcsError::kUnknownParameter:
      return "Unknown parameter";
    case GcsError::kNoRecordTable:
      return "Data record table does not exist";
    case GcsError::kNoRecordOption:
      return "Record source option does not exist";
    case GcsError::kInvalidPassword:
      return "Invalid password";
    case GcsError::kParamProtection:
      return "Protected Param: current Command Level (CCL) too low";
    case GcsError::kReadOnlyParameter:
      return "Parameter is read-only";
    case GcsError::kVoltageOutOfLimits:
      return "Voltage out of limits";
    case GcsError::kNotEnoughData:
      return "Data record table does not hold enough recorded data";
    case GcsError::kTableDeactivated:
      return "Data record table is not configured for recording";
    case GcsError::kWaveGeneratorActive:
      return "Motion commands are not allowed when the wave generator is active";
    case GcsError::kWaveIndex:
      return "Wave generator index error";
    case GcsError::kWaveNotDefined:
      return "Wave table not defined";
    case GcsError::kWaveTypeNotSupported:
      return "Wave type not supported";
    case GcsError::kWaveTooLong:
      return "Wave length exceeds limit";
    case GcsError::kWaveParamCount:
      return "Wave parameter number error";
    case GcsError::kWaveParamOutOfRange:
      return "Wave parameter out of range";
    case GcsError::kWgoBitNotSupported:
      return "WGO command bit not supported";
    case GcsError::kOpenLoopWithServoOn:
      return "Open-loop commands are not allowed when servo is on";
    case GcsError::kMotionError:
      return "Motion error: the safety supervisor switched the servo off";
  }
  return "Unknown error";
}

}  // namespace piezoshift::host
