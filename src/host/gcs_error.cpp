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
    case GcsError::kNoRecordTable:
      return "Data record table does not exist";
    case GcsError::kNoRecordOption:
      return "Record source option does not exist";
    case GcsError::kVoltageOutOfLimits:
      return "Voltage out of limits";
    case GcsError::kNotEnoughData:
      return "Data record table does not hold enough recorded data";
    case GcsError::kTableDeactivated:
      return "Data record table is not configured for recording";
    case GcsError::kOpenLoopWithServoOn:
      return "Open-loop commands are not allowed when servo is on";
    case GcsError::kMotionError:
      return "Motion error: the safety supervisor switched the servo off";
  }
  return "Unknown error";
}

}  // namespace piezoshift::host
