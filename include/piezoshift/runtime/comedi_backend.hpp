#pragma once
// The hardware backend: a Comedi device (libcomedi), e.g. the paper's NI PCI-6229 through the
// ni_pcimio driver. Three AI (differential, the SGS conditioners) and three AO (the amplifiers).
//
//   configure():  comedi_open(path)                       -> core::InputError naming the path
//                 AI/AO subdevices, channel counts, ranges (smallest range holding the span asked
//                 for: AI [-0.5, 10] V -> +-10 V, AO [0, 10] V on the PCI-6229)
//                 converters: soft-calibrated subdevices (SDF_SOFT_CALIBRATED, M-series boards)
//                 use the calibration file's polynomials (comedi_soft_calibrate writes it; a
//                 missing file is an error), others the hardware-calibrated range conversion
//   per tick:     read(): ONE comedi_do_insnlist = 3 INSN_WRITE (the AO staged by the last
//                 write()) then 3 INSN_READ; a short list is kError. A raw AI at 0 or maxdata
//                 reads as the range's end, so the supervisor sees the rail.
//                 write(): clamp to the AO range, then convert (comedi's conversion would clip
//                 silently), then clamp the code to [0, maxdata]; kClamped says it happened.
//   deactivate(): one insnlist writing 0 V to the three AO (and the trigger line low); when the
//                 device refuses it, safe_state_error() says so (the outputs hold their value).
//   read() keeps comedi_errno() of a failed transaction (an int) for device_error().
//
// Trigger line (optional, ComediOptions::trigger_line; the PCI-6229's DIO port 0 is subdevice 2):
// configure() checks that the subdevice is digital (DIO or DO) and has the channel, and makes a
// DIO channel an output (comedi_dio_config); activate() writes it low. The tick's level is one
// more INSN_WRITE of that channel (the instruction comedi_dio_write issues), placed after the
// three AO writes in the same insnlist, so the edge needs no second ioctl and goes out at the
// tick's scheduled time with the AO. Untested on hardware: no board here.
// read()/write()/stage_trigger_line() are real-time safe (no heap; one ioctl per tick).
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "piezoshift/runtime/daq_backend.hpp"

namespace piezoshift::runtime {

struct ComediOptions {
  std::string device = "/dev/comedi0";
  std::array<unsigned, 3> ai_channels{0, 1, 2};
  std::array<unsigned, 3> ao_channels{0, 1, 2};
  double ai_min_V = -0.5;  //!< span the AI range must hold (the conditioner's 0..10 V + margin)
  double ai_max_V = 10.0;
  double ao_min_V = 0.0;  //!< the amplifier's 0..10 V input (Section 4)
  double ao_max_V = 10.0;
  //! The camera's trigger output: a digital channel (none by default).
  struct DigitalLine {
    unsigned subdevice = 2;
    unsigned channel = 0;
  };
  std::optional<DigitalLine> trigger_line;
};

//! Parses "SUBDEVICE/CHANNEL" (e.g. "2/0", the PCI-6229's P0.0); throws core::InputError naming
//! option and text.
ComediOptions::DigitalLine parse_digital_line(std::string_view text, std::string_view option);

//! True when this build has libcomedi (otherwise configure() explains and fails).
bool comedi_available() noexcept;

class ComediBackend final : public DaqBackend {
 public:
  explicit ComediBackend(ComediOptions options);
  ~ComediBackend() override;

  void configure() override;
  void activate() override;
  void deactivate() noexcept override;
  DaqStatus read(const CycleTime& t, Vec3& ai_V) noexcept override;
  DaqStatus write(const CycleTime& t, const Vec3& ao_V) noexcept override;
  std::string name() const override { return "comedi:" + options_.device; }
  std::string device_error() const override;
  std::string safe_state_error() const override;
  bool has_trigger_line() const noexcept override { return options_.trigger_line.has_value(); }
  void stage_trigger_line(bool high) noexcept override;

 private:
  struct Impl;
  void configure_trigger_line(Impl& impl);
  ComediOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace piezoshift::runtime
