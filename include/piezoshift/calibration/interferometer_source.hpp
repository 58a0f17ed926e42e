#pragma once
// Where the guided calibration (guided_calibration.hpp) gets each interferometer reading: the
// displacement, in um, at the one point the single-beam optics look at, while the stage holds a
// pose over one averaging window (guided_rig.hpp's RigWindow).
//   PromptSource    typed by the operator (a line per reading on an input stream); a line that is
//                   not a number, or a reading the plausibility checks refuse, is asked again
//   LogFileSource   read from the CSV the interferometer software writes, columns t_s (on the
//                   rig's clock) and displacement_um: the mean of the rows inside the window
//                   (docs/files.md); a log that does not yet reach past the window's end is
//                   read again for a few seconds
//   TwinSource      the twin's own interferometer (`--daq sim`, `--daq sim-rt`)
// read() returns nothing when the source has ended (the operator closed the input): the session
// so far is recorded and a later run resumes it.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <istream>
#include <optional>
#include <string>

#include "piezoshift/rig/guided_rig.hpp"

namespace piezoshift::calibration {

//! Where the optics look: a measurement point of the tripod (paper, Fig. 7) or the centroid of
//! the three (the plate's mean displacement, calibration stage 3).
enum class Optics : std::uint8_t { kP1, kP2, kP3, kCentre };
const char* to_string(Optics optics) noexcept;

struct ReadingRequest {
  std::size_t index = 0;  //!< 0-based, in the session's plan
  std::size_t total = 0;
  Optics optics = Optics::kP1;
  std::string what;  //!< the pose, in words ("P2, repeat 1, actuator 3 moved by 7 um")
  rig::RigWindow window;
};

class InterferometerSource {
 public:
  virtual ~InterferometerSource() = default;
  //! The reading for this request; nothing when the source has ended.
  virtual std::optional<double> read(const ReadingRequest& request) = 0;
  //! True when a refused reading can be asked again (the prompt); otherwise a refusal is an
  //! error naming name().
  virtual bool can_retry() const = 0;
  //! Tells the operator why the last reading was refused (prompt only).
  virtual void refuse(const std::string& why) = 0;
  virtual std::string name() const = 0;
};

//! Reads lines from in and talks to the operator through say (no newline at the end of a prompt).
//! Lines are at most 256 characters (longer: refused); a number with an optional "um" is taken.
class PromptSource final : public InterferometerSource {
 public:
  PromptSource(std::istream& in, std::function<void(const std::string&)> say)
      : in_(in), say_(std::move(say)) {}
  std::optional<double> read(const ReadingRequest& request) override;
  bool can_retry() const override { return true; }
  void refuse(const std::string& why) override;
  std::string name() const override { return "standard input"; }

 private:
  std::istream& in_;
  std::function<void(const std::string&)> say_;
};

class LogFileSource final : public InterferometerSource {
 public:
  //! The log is read whole at each reading; a file larger than max_bytes is refused. A log that
  //! does not yet reach the window's end is read again for up to wait_s (the interferometer
  //! software flushes in its own rhythm).
  explicit LogFileSource(std::string path, std::size_t max_bytes = std::size_t{64} << 20,
                         double wait_s = 5.0)
      : path_(std::move(path)), max_bytes_(max_bytes), wait_s_(wait_s) {}
  //! Throws core::InputError naming the file for a bad file, a log that still ends before the
  //! window does after wait_s, or no row inside the window.
  std::optional<double> read(const ReadingRequest& request) override;
  bool can_retry() const override { return false; }
  void refuse(const std::string&) override {}
  std::string name() const override { return path_; }

 private:
  std::string path_;
  std::size_t max_bytes_;
  double wait_s_;
};

class TwinSource final : public InterferometerSource {
 public:
  //! The window's twin_points_um (the centre: their mean); throws std::logic_error without them.
  std::optional<double> read(const ReadingRequest& request) override;
  bool can_retry() const override { return false; }
  void refuse(const std::string&) override {}
  std::string name() const override { return "the twin's interferometer"; }
};

}  // namespace piezoshift::calibration
