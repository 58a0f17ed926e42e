#include "board_model.hpp"

#include <cmath>

namespace piezoshift::emulation {

namespace {

constexpr comedi_range volts(double lo, double hi) {
  return comedi_range{lo, hi, UNIT_volt};
}

SubdeviceModel subdevice(int type, int flags, unsigned n_chan, lsampl_t maxdata,
                         std::vector<comedi_range> ranges = {}) {
  return SubdeviceModel{type, flags, n_chan, maxdata, std::move(ranges)};
}

double lsb(const comedi_range& range, lsampl_t maxdata) {
  return (range.max - range.min) / (static_cast<double>(maxdata) + 1.0);
}

double mid(lsampl_t maxdata) {
  return (static_cast<double>(maxdata) + 1.0) / 2.0;
}

}  // namespace

std::optional<BoardModel> ni_m_series_board(std::string_view name) {
  const bool b6229 = name == "pci-6229";
  if (!b6229 && name != "pci-6220")
    return std::nullopt;
  BoardModel b;
  b.name = std::string(name);
  // range_digital and range_unknown (comedi's core gives a used subdevice without a range table
  // the latter): both [0, 1] V. An unused subdevice has no ranges.
  const comedi_range unit{0.0, 1.0, UNIT_volt};
  // ni_E_init. The command flags (SDF_CMD_READ on AI, SDF_CMD_WRITE on AO and DIO) and their
  // do_cmd handlers exist only when the board got its interrupt line (dev->irq); the emulation
  // is the board attached without one, so no subdevice takes commands (docs/runtime.md).
  const int ai_flags = SDF_READABLE | SDF_DIFF | SDF_DITHER | SDF_GROUND | SDF_COMMON | SDF_OTHER |
                       SDF_SOFT_CALIBRATED;
  const int ao_flags = SDF_WRITABLE | SDF_DEGLITCH | SDF_GROUND | SDF_SOFT_CALIBRATED;
  const int rw_internal = SDF_READABLE | SDF_WRITABLE | SDF_INTERNAL;
  b.subdevices = {
      subdevice(COMEDI_SUBD_AI, ai_flags, b6229 ? 32 : 16, 0xffff,
                {volts(-10, 10), volts(-5, 5), volts(-1, 1), volts(-0.2, 0.2)}),
      b6229 ? subdevice(COMEDI_SUBD_AO, ao_flags, 4, 0xffff, {volts(-10, 10)})
            : subdevice(COMEDI_SUBD_UNUSED, 0, 0, 0),
      subdevice(COMEDI_SUBD_DIO, SDF_READABLE | SDF_WRITABLE | SDF_LSAMPL, b6229 ? 32 : 8, 1,
                {unit}),
      subdevice(COMEDI_SUBD_UNUSED, 0, 0, 0),  // 8255: none on M Series
      subdevice(COMEDI_SUBD_UNUSED, 0, 0, 0),
      subdevice(COMEDI_SUBD_CALIB, SDF_INTERNAL, 1, 0, {unit}),
      subdevice(COMEDI_SUBD_MEMORY, SDF_READABLE | SDF_INTERNAL, 1024, 0xff, {unit}),
      subdevice(COMEDI_SUBD_DIO, rw_internal, 16, 1, {unit}),  // PFI
      subdevice(COMEDI_SUBD_UNUSED, 0, 0, 0),                  // CS5529: 67xx only
      subdevice(COMEDI_SUBD_SERIAL, rw_internal, 1, 0xff, {unit}),
      subdevice(COMEDI_SUBD_DIO, rw_internal, 8, 1, {unit}),  // RTSI
      subdevice(COMEDI_SUBD_COUNTER, SDF_READABLE | SDF_WRITABLE | SDF_LSAMPL, 3, 0xffffffff,
                {unit}),
      subdevice(COMEDI_SUBD_COUNTER, SDF_READABLE | SDF_WRITABLE | SDF_LSAMPL, 3, 0xffffffff,
                {unit}),
      subdevice(COMEDI_SUBD_COUNTER, SDF_READABLE | SDF_WRITABLE, 1, 0xf, {unit}),  // freq out
  };
  return b;
}

RawConverter BoardModel::ai_raw(unsigned channel) const noexcept {
  // A different small error on every channel, so a client using one channel's polynomial for
  // another is off too.
  const double c = static_cast<double>(channel % 8);
  return RawConverter{2.5 - 0.75 * c, 1.0 + 1e-4 * (1.0 + 0.25 * c)};
}

RawConverter BoardModel::ao_raw(unsigned channel) const noexcept {
  const double c = static_cast<double>(channel % 4);
  return RawConverter{-3.0 + 1.5 * c, 1.0 - 2e-4 * (1.0 + 0.5 * c)};
}

comedi_polynomial_t to_physical_polynomial(const comedi_range& range, lsampl_t maxdata,
                                           const RawConverter& raw) {
  // volts = centre + (code - mid - offset) * lsb / gain, expanded about code = mid
  comedi_polynomial_t p{};
  const double step = lsb(range, maxdata);
  p.order = 1;
  p.expansion_origin = mid(maxdata);
  p.coefficients[0] = 0.5 * (range.min + range.max) - raw.offset_codes * step / raw.gain;
  p.coefficients[1] = step / raw.gain;
  return p;
}

comedi_polynomial_t from_physical_polynomial(const comedi_range& range, lsampl_t maxdata,
                                             const RawConverter& raw) {
  // code = mid + offset + gain * (volts - centre) / lsb, expanded about the range's centre
  comedi_polynomial_t p{};
  p.order = 1;
  p.expansion_origin = 0.5 * (range.min + range.max);
  p.coefficients[0] = mid(maxdata) + raw.offset_codes;
  p.coefficients[1] = raw.gain / lsb(range, maxdata);
  return p;
}

lsampl_t raw_code(double volts, const comedi_range& range, lsampl_t maxdata,
                  const RawConverter& raw) noexcept {
  const double centre = 0.5 * (range.min + range.max);
  const double code = std::nearbyint(mid(maxdata) + raw.offset_codes +
                                     raw.gain * (volts - centre) / lsb(range, maxdata));
  if (!(code > 0.0))
    return 0;  // below the range, or NaN: the converter reads its bottom code
  if (code >= static_cast<double>(maxdata))
    return maxdata;
  return static_cast<lsampl_t>(code);
}

double raw_volts(lsampl_t code, const comedi_range& range, lsampl_t maxdata,
                 const RawConverter& raw) noexcept {
  const double centre = 0.5 * (range.min + range.max);
  return centre + (static_cast<double>(code) - mid(maxdata) - raw.offset_codes) *
                      lsb(range, maxdata) / raw.gain;
}

}  // namespace piezoshift::emulation
