#pragma once
// What an NI M Series board looks like through Comedi's ni_pcimio driver: the subdevice table,
// channel counts, ranges and maxdata a client queries, and the raw converters behind the
// software calibration (no hardware: the emulation's static description of the board).
//
// Facts, from the Linux kernel's comedi drivers (ni_pcimio.c's board table, ni_mio_common.c's
// ni_E_init), read as documentation:
//   - 14 subdevices: 0 AI, 1 AO, 2 DIO (port 0), 3 8255 DIO (unused on M Series), 4 unused,
//     5 calibration, 6 EEPROM, 7 PFI DIO (16 lines), 8 CS5529 (unused), 9 serial, 10 RTSI (8),
//     11 and 12 counters (3 channels, 32 bit), 13 frequency output.
//   - PCI-6229: 32 AI, 16 bit (maxdata 0xffff), ranges +-10, +-5, +-1, +-0.2 V; 4 AO, 16 bit,
//     +-10 V only; 32 DIO lines on port 0. AI and AO are SDF_SOFT_CALIBRATED (M Series: the raw
//     codes are converted by polynomials that comedi_soft_calibrate writes to a file). Digital
//     lines and the subdevices without a range table read [0, 1] V (range_digital,
//     range_unknown).
//   - No interrupt line: the driver then gives no subdevice a command handler (no SDF_CMD_*).
//   - PCI-6220: the same AI (16 channels), no AO (subdevice 1 is COMEDI_SUBD_UNUSED), 8 DIO lines:
//     the board a lab may have in the slot instead, so a client must find the AO missing.
//
// The raw converters: an M Series board's uncalibrated ADC and DAC have offset and gain errors
// that its software calibration removes. The emulation gives each channel a fixed offset of a
// few codes and a gain error of 1e-4 to 3e-4 (illustrative magnitudes, not NI's specification)
// so that a client which skipped the calibration polynomials reads volts off by millivolts.
#include <comedilib.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace piezoshift::emulation {

struct SubdeviceModel {
  int type = COMEDI_SUBD_UNUSED;
  int flags = 0;
  unsigned n_chan = 0;
  lsampl_t maxdata = 0;
  std::vector<comedi_range> ranges;  //!< one list for every channel
};

//! One channel's raw converter: raw code = mid + offset_codes + gain * (volts / lsb).
struct RawConverter {
  double offset_codes = 0.0;
  double gain = 1.0;
};

struct BoardModel {
  std::string name;  //!< "pci-6229"
  std::string driver = "ni_pcimio";
  std::vector<SubdeviceModel> subdevices;  //!< indexed by subdevice number
  //! The raw converter of AI channel i (i < 32) or AO channel i (i < 4).
  RawConverter ai_raw(unsigned channel) const noexcept;
  RawConverter ao_raw(unsigned channel) const noexcept;
};

//! The board of that name ("pci-6229" or "pci-6220"), or nothing.
std::optional<BoardModel> ni_m_series_board(std::string_view name);

//! Subdevice numbers of the ni_pcimio layout.
inline constexpr unsigned kAiSubdevice = 0;
inline constexpr unsigned kAoSubdevice = 1;
inline constexpr unsigned kDioSubdevice = 2;

//! The software-calibration polynomials for a channel and range: the exact inverse of its raw
//! converter (order 1), expanded about the range's mid code as comedi_soft_calibrate does.
comedi_polynomial_t to_physical_polynomial(const comedi_range& range, lsampl_t maxdata,
                                           const RawConverter& raw);
comedi_polynomial_t from_physical_polynomial(const comedi_range& range, lsampl_t maxdata,
                                             const RawConverter& raw);

//! The raw code of an analog value through a channel's converter, saturated at 0 and maxdata.
lsampl_t raw_code(double volts, const comedi_range& range, lsampl_t maxdata,
                  const RawConverter& raw) noexcept;
//! The analog value a raw code stands for through a channel's converter.
double raw_volts(lsampl_t code, const comedi_range& range, lsampl_t maxdata,
                 const RawConverter& raw) noexcept;

}  // namespace piezoshift::emulation
