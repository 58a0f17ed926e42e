#pragma once
// The GCS 2.0 error numbers this server sets (read and cleared with ERR?). The numbers and their
// meanings are PI's controller error list (PI_CNTR_* in PI's GCS libraries); the server uses only
// those that can occur on this stage (docs/gcs.md lists when each is set).
namespace piezoshift::host {

enum class GcsError : int {
  kNone = 0,
  kParamSyntax = 1,             //!< Parameter syntax error
  kUnknownCommand = 2,          //!< Unknown command
  kCommandTooLong = 3,          //!< Command length out of limits
  kServoOff = 5,                //!< Move attempted with servo off
  kPositionOutOfLimits = 7,     //!< Position out of limits
  kVelocityOutOfLimits = 8,     //!< Velocity out of limits
  kStopped = 10,                //!< Controller was stopped by command
  kInvalidAxis = 15,            //!< Invalid axis identifier
  kParamOutOfRange = 17,        //!< Parameter out of range
  kDoubleAxis = 22,             //!< Axis identifier specified more than once
  kParamCount = 24,             //!< Incorrect number of parameters
  kInvalidReal = 25,            //!< Invalid floating point number
  kCommunication = 52,          //!< Communication error: the command did not reach the loop
  kUnknownParameter = 54,       //!< Unknown parameter
  kInvalidPassword = 56,        //!< Invalid password (CCL)
  kNoRecordTable = 57,          //!< Data record table does not exist
  kNoRecordOption = 58,         //!< Record source option does not exist
  kParamProtection = 60,        //!< Protected parameter: current command level (CCL) too low
  kReadOnlyParameter = 64,      //!< Parameter is read-only
  kVoltageOutOfLimits = 66,     //!< Voltage out of limits
  kNotEnoughData = 77,          //!< Data record table does not hold enough recorded data
  kTableDeactivated = 78,       //!< Data record table is not configured for recording
  kWaveGeneratorActive = 73,    //!< Motion commands are not allowed while the wave generator runs
  kOpenLoopWithServoOn = 79,    //!< Open-loop commands (SVA) are not allowed when servo is on
  kWaveIndex = 400,             //!< Wave generator (or table) index error
  kWaveNotDefined = 401,        //!< Wave table not defined
  kWaveTypeNotSupported = 402,  //!< Wave type not supported
  kWaveTooLong = 403,           //!< Wave length exceeds limit
  kWaveParamCount = 404,        //!< Wrong number of wave parameters
  kWaveParamOutOfRange = 405,   //!< Wave parameter out of range
  kWgoBitNotSupported = 406,    //!< WGO start-mode bit not supported
  kMotionError = -1024,         //!< Motion error: the safety supervisor switched the servo off
};

//! PI's short description of an error number ("Unknown command"); "Unknown error" otherwise.
const char* describe(GcsError error) noexcept;

}  // namespace piezoshift::host
