#pragma once
// A camera behind one interface, with a lifecycle like the DAQ backends' (daq_backend.hpp):
//
//   configure(settings)  set-up: open the device, apply size, pixel format, exposure, gain,
//                        trigger; throws core::InputError naming the camera and the setting it
//                        cannot take (an unsupported pixel format is refused, never converted)
//   start()              acquisition armed: buffers queued, ready for triggers
//   trigger(t)           software trigger: one exposure starts now; t is the loop's time of the
//                        trigger (the twin camera exposes over the loop's clock; a real camera
//                        records it beside its own device timestamp). Never blocks.
//   poll(frame)          non-blocking: a finished frame if one has arrived (frames move from the
//                        camera's thread to the caller through a lock-free ring, so the loop's
//                        thread may poll between ticks)
//   wait(frame, timeout) blocking, for a caller outside the loop's thread
//   stop()               acquisition stopped, buffers released; safe to call twice
//
// A lost frame (the device or the stream dropped it, or the ring overflowed) is reported as
// kLost with the frame id it should have had, never skipped silently: a phase-shifting sequence
// with a missing frame is a wrong measurement.
#include <cstdint>
#include <string>

#include "piezoshift/camera/frame.hpp"
#include "piezoshift/camera/settings.hpp"

namespace piezoshift::camera {

enum class FrameStatus : std::uint8_t {
  kOk,       //!< frame holds a complete image
  kNone,     //!< poll(): nothing has arrived yet
  kTimeout,  //!< wait(): nothing arrived within the timeout
  kLost,     //!< a frame was dropped (frame.frame_id names it); the sequence is broken
  kError,    //!< the device or its stream failed (message() says how)
};
const char* to_string(FrameStatus status) noexcept;

//! The plate's true pose at one instant, for a camera that renders the plate itself (the twin).
struct PlatePose {
  double time_s = 0.0;        //!< loop time
  double piston_nm = 0.0;     //!< at the pupil centre, relative to the measurement's base
  double theta_x_urad = 0.0;  //!< tip about x
  double theta_y_urad = 0.0;  //!< tilt about y
};

//! pose from origin (piston, tip and tilt each less origin's), at pose's time: what the twin
//! camera renders, relative to the pose its measurement or scan started at.
constexpr PlatePose relative_to(const PlatePose& pose, const PlatePose& origin) noexcept {
  return {pose.time_s, pose.piston_nm - origin.piston_nm, pose.theta_x_urad - origin.theta_x_urad,
          pose.theta_y_urad - origin.theta_y_urad};
}

class Camera {
 public:
  virtual ~Camera() = default;

  virtual void configure(const CameraSettings& settings) = 0;
  virtual void start() = 0;
  //! Starts one exposure at loop time loop_time_s. False (and message() says why) when the
  //! camera cannot take it now: not started, still reading out the previous frame, or (the twin)
  //! every buffer holds a frame not yet polled. A refused trigger takes no frame id.
  virtual bool trigger(double loop_time_s) noexcept = 0;
  virtual FrameStatus poll(Frame& frame) noexcept = 0;
  virtual FrameStatus wait(Frame& frame, double timeout_s) = 0;
  virtual void stop() noexcept = 0;

  //! The twin's optics: the plate's true pose at one loop tick. A real camera sees the plate
  //! through the interferometer and ignores this; the twin camera integrates its exposure from
  //! these samples. Real-time safe.
  virtual void observe_plate(const PlatePose& /*pose*/) noexcept {}

  //! "twin", "files:DIR", "aravis:ID".
  virtual std::string name() const = 0;
  //! The settings in force after configure() (the device's own values where it rounded them).
  virtual const CameraSettings& settings() const = 0;
  //! The last error or refusal, for messages ("" when none): after trigger() returned false,
  //! why; after poll()/wait() returned kLost or kError, what happened to that frame. Not
  //! real-time safe; call it from the thread that got the refusal or the status.
  virtual std::string message() const = 0;
  //! Frames reported kLost since start().
  virtual std::uint64_t lost_frames() const noexcept = 0;
};

//! wait() for a camera whose frames come to poll(): polls every 100 us until a frame (or a
//! failure) arrives or timeout_s has passed (kTimeout).
FrameStatus poll_until(Camera& camera, Frame& frame, double timeout_s);

}  // namespace piezoshift::camera
