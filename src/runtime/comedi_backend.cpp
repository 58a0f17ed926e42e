#include "piezoshift/runtime/comedi_backend.hpp"

#include <charconv>
#include <cstdlib>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

#ifdef PIEZOSHIFT_HAVE_COMEDI
#include <comedilib.h>
#endif

namespace piezoshift::runtime {

ComediOptions::DigitalLine parse_digital_line(std::string_view text, std::string_view option) {
  const auto bad = [&] {
    return core::InputError(fmt::format(
        "{} '{}': expected SUBDEVICE/CHANNEL, two whole numbers (2/0: the PCI-6229's P0.0)", option,
        text));
  };
  const std::size_t slash = text.find('/');
  if (slash == std::string_view::npos)
    throw bad();
  const auto number = [&](std::string_view part) {
    unsigned v = 0;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (part.empty() || ec != std::errc{} || end != part.data() + part.size() || v > 255)
      throw bad();
    return v;
  };
  return {number(text.substr(0, slash)), number(text.substr(slash + 1))};
}

#ifdef PIEZOSHIFT_HAVE_COMEDI

bool comedi_available() noexcept {
  return true;
}

struct ComediBackend::Impl {
  comedi_t* dev = nullptr;
  comedi_calibration_t* calibration = nullptr;
  int ai_subdev = -1;
  int ao_subdev = -1;
  std::array<comedi_polynomial_t, 3> ai_poly{};
  std::array<comedi_polynomial_t, 3> ao_poly{};
  std::array<lsampl_t, 3> ai_maxdata{};
  std::array<lsampl_t, 3> ao_maxdata{};
  std::array<double, 3> ai_lo{}, ai_hi{}, ao_lo{}, ao_hi{};
  // [0..2] AO codes staged, [3..5] AI codes read, [6] the trigger line's level staged
  std::array<lsampl_t, 7> data{};
  // The three AO writes, the trigger line's write (if any), then the three AI reads.
  std::array<comedi_insn, 7> insns{};
  unsigned n_writes = 3;
  comedi_insnlist list{};
  bool active = false;
  int read_errno = 0;  // comedi_errno() of the last failed transaction; 0: none
  int safe_errno = 0;  // of a deactivate() the device refused

  ~Impl() {
    if (calibration != nullptr)
      comedi_cleanup_calibration(calibration);
    if (dev != nullptr)
      comedi_close(dev);
  }
};

namespace {
std::string comedi_error() {
  return comedi_strerror(comedi_errno());
}
}  // namespace

ComediBackend::ComediBackend(ComediOptions options) : options_(std::move(options)) {}
ComediBackend::~ComediBackend() {
  deactivate();
}

void ComediBackend::configure() {
  auto impl = std::make_unique<Impl>();
  const std::string& path = options_.device;
  impl->dev = comedi_open(path.c_str());
  if (impl->dev == nullptr) {
    throw core::InputError(
        fmt::format("{}: cannot open the DAQ device: {} (is the board's comedi driver loaded, "
                    "e.g. ni_pcimio for the PCI-6229, and the device readable?)",
                    path, comedi_error()));
  }
  impl->ai_subdev = comedi_find_subdevice_by_type(impl->dev, COMEDI_SUBD_AI, 0);
  impl->ao_subdev = comedi_find_subdevice_by_type(impl->dev, COMEDI_SUBD_AO, 0);
  if (impl->ai_subdev < 0 || impl->ao_subdev < 0)
    throw core::InputError(fmt::format("{}: the device has no analog {} subdevice", path,
                                       impl->ai_subdev < 0 ? "input" : "output"));
  const auto ai_sub = static_cast<unsigned>(impl->ai_subdev);
  const auto ao_sub = static_cast<unsigned>(impl->ao_subdev);

  const bool soft = ((comedi_get_subdevice_flags(impl->dev, ai_sub) |
                      comedi_get_subdevice_flags(impl->dev, ao_sub)) &
                     SDF_SOFT_CALIBRATED) != 0;
  if (soft) {
    char* cal_path = comedi_get_default_calibration_path(impl->dev);
    const std::string cal = cal_path != nullptr ? cal_path : "(none)";
    std::free(cal_path);
    impl->calibration = comedi_parse_calibration_file(cal.c_str());
    if (impl->calibration == nullptr) {
      throw core::InputError(fmt::format(
          "{}: the board is software-calibrated but its calibration file {} cannot be read; run "
          "comedi_soft_calibrate first",
          path, cal));
    }
  }

  const auto setup = [&](unsigned sub, unsigned ch, double lo, double hi,
                         comedi_conversion_direction dir, comedi_polynomial_t& poly,
                         lsampl_t& maxdata, double& range_lo, double& range_hi) -> unsigned {
    const int n = comedi_get_n_channels(impl->dev, sub);
    if (n < 0 || ch >= static_cast<unsigned>(n))
      throw core::InputError(fmt::format("{}: subdevice {} has no channel {}", path, sub, ch));
    const int range = comedi_find_range(impl->dev, sub, ch, UNIT_volt, lo, hi);
    if (range < 0) {
      throw core::InputError(
          fmt::format("{}: subdevice {} channel {} has no range holding "
                      "[{}, {}] V",
                      path, sub, ch, lo, hi));
    }
    const auto r = static_cast<unsigned>(range);
    const comedi_range* info = comedi_get_range(impl->dev, sub, ch, r);
    maxdata = comedi_get_maxdata(impl->dev, sub, ch);
    if (info == nullptr || maxdata == 0)
      throw core::InputError(
          fmt::format("{}: cannot query subdevice {} channel {}", path, sub, ch));
    range_lo = info->min;
    range_hi = info->max;
    const int ok = soft ? comedi_get_softcal_converter(sub, ch, r, dir, impl->calibration, &poly)
                        : comedi_get_hardcal_converter(impl->dev, sub, ch, r, dir, &poly);
    if (ok < 0) {
      throw core::InputError(fmt::format("{}: no {} converter for subdevice {} channel {}: {}",
                                         path, soft ? "software-calibration" : "range", sub, ch,
                                         comedi_error()));
    }
    return r;
  };

  for (std::size_t i = 0; i < 3; ++i) {
    const unsigned ao_ch = options_.ao_channels[i];
    const unsigned ao_range =
        setup(ao_sub, ao_ch, options_.ao_min_V, options_.ao_max_V, COMEDI_FROM_PHYSICAL,
              impl->ao_poly[i], impl->ao_maxdata[i], impl->ao_lo[i], impl->ao_hi[i]);
    const unsigned ai_ch = options_.ai_channels[i];
    const unsigned ai_range =
        setup(ai_sub, ai_ch, options_.ai_min_V, options_.ai_max_V, COMEDI_TO_PHYSICAL,
              impl->ai_poly[i], impl->ai_maxdata[i], impl->ai_lo[i], impl->ai_hi[i]);
    comedi_insn& w = impl->insns[i];
    w.insn = INSN_WRITE;
    w.n = 1;
    w.data = &impl->data[i];
    w.subdev = ao_sub;
    w.chanspec = CR_PACK(ao_ch, ao_range, AREF_GROUND);
    comedi_insn& rd = impl->insns[(options_.trigger_line ? 4 : 3) + i];
    rd.insn = INSN_READ;
    rd.n = 1;
    rd.data = &impl->data[3 + i];
    rd.subdev = ai_sub;
    rd.chanspec = CR_PACK(ai_ch, ai_range, AREF_DIFF);  // the PCI-6229's differential inputs
  }
  if (options_.trigger_line)
    configure_trigger_line(*impl);
  impl->list.n_insns = impl->n_writes + 3;
  impl->list.insns = impl->insns.data();
  impl_ = std::move(impl);
}

void ComediBackend::configure_trigger_line(Impl& impl) {
  const ComediOptions::DigitalLine line = *options_.trigger_line;
  const std::string what =
      fmt::format("{}: trigger line {}/{}", options_.device, line.subdevice, line.channel);
  const int n_subdevices = comedi_get_n_subdevices(impl.dev);
  if (n_subdevices < 0 || line.subdevice >= static_cast<unsigned>(n_subdevices))
    throw core::InputError(fmt::format("{}: the device has {} subdevices", what, n_subdevices));
  const int type = comedi_get_subdevice_type(impl.dev, line.subdevice);
  if (type != COMEDI_SUBD_DIO && type != COMEDI_SUBD_DO)
    throw core::InputError(
        fmt::format("{}: subdevice {} is not a digital output (DIO or DO)", what, line.subdevice));
  const int n = comedi_get_n_channels(impl.dev, line.subdevice);
  if (n < 0 || line.channel >= static_cast<unsigned>(n))
    throw core::InputError(fmt::format("{}: the subdevice has {} channels", what, n));
  if (type == COMEDI_SUBD_DIO &&
      comedi_dio_config(impl.dev, line.subdevice, line.channel, COMEDI_OUTPUT) < 0)
    throw core::InputError(fmt::format("{}: cannot make it an output: {}", what, comedi_error()));
  comedi_insn& w = impl.insns[3];
  w.insn = INSN_WRITE;  // what comedi_dio_write issues, here in the tick's one insnlist
  w.n = 1;
  w.data = &impl.data[6];
  w.subdev = line.subdevice;
  w.chanspec = CR_PACK(line.channel, 0, 0);
  impl.data[6] = 0;
  impl.n_writes = 4;
}

void ComediBackend::stage_trigger_line(bool high) noexcept {
  if (impl_)
    impl_->data[6] = high ? 1 : 0;
}

void ComediBackend::activate() {
  if (!impl_)
    throw core::InputError(fmt::format("{}: activate() before configure()", options_.device));
  impl_->active = true;
  Vec3 ai{};
  write(CycleTime{}, Vec3{});
  stage_trigger_line(false);
  if (read(CycleTime{}, ai) != DaqStatus::kOk) {
    impl_->active = false;
    throw core::InputError(fmt::format("{}: the first read/write transaction failed: {}",
                                       options_.device, comedi_error()));
  }
}

void ComediBackend::deactivate() noexcept {
  if (!impl_ || !impl_->active)
    return;
  write(CycleTime{}, Vec3{});
  stage_trigger_line(false);
  comedi_insnlist zeros{impl_->n_writes, impl_->insns.data()};  // the writes only
  impl_->safe_errno = comedi_do_insnlist(impl_->dev, &zeros) == static_cast<int>(zeros.n_insns)
                          ? 0
                          : comedi_errno();
  impl_->active = false;
}

std::string ComediBackend::device_error() const {
  return impl_ && impl_->read_errno != 0 ? comedi_strerror(impl_->read_errno) : std::string();
}

std::string ComediBackend::safe_state_error() const {
  if (!impl_ || impl_->safe_errno == 0)
    return {};
  return fmt::format("{}: writing 0 V to the outputs failed: {}", name(),
                     comedi_strerror(impl_->safe_errno));
}

DaqStatus ComediBackend::read(const CycleTime&, Vec3& ai_V) noexcept {
  if (!impl_ || !impl_->active)
    return DaqStatus::kInactive;
  if (comedi_do_insnlist(impl_->dev, &impl_->list) != static_cast<int>(impl_->list.n_insns)) {
    impl_->read_errno = comedi_errno();
    return DaqStatus::kError;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const lsampl_t code = impl_->data[3 + i];
    if (code == 0)
      ai_V[i] = impl_->ai_lo[i];  // clipped low: report the rail itself
    else if (code >= impl_->ai_maxdata[i])
      ai_V[i] = impl_->ai_hi[i];
    else
      ai_V[i] = comedi_to_physical(code, &impl_->ai_poly[i]);
  }
  return DaqStatus::kOk;
}

DaqStatus ComediBackend::write(const CycleTime&, const Vec3& ao_V) noexcept {
  if (!impl_ || !impl_->active)
    return DaqStatus::kInactive;
  bool clamped = false;
  for (std::size_t i = 0; i < 3; ++i) {
    const double lo = options_.ao_min_V > impl_->ao_lo[i] ? options_.ao_min_V : impl_->ao_lo[i];
    const double hi = options_.ao_max_V < impl_->ao_hi[i] ? options_.ao_max_V : impl_->ao_hi[i];
    double v = ao_V[i];
    if (!(v == v)) {  // NaN: the safe state
      v = 0.0;
      clamped = true;
    }
    if (v < lo) {
      v = lo;
      clamped = true;
    }
    if (v > hi) {
      v = hi;
      clamped = true;
    }
    // The calibration polynomial may map the range's end a code or two past maxdata.
    lsampl_t code = comedi_from_physical(v, &impl_->ao_poly[i]);
    if (code > impl_->ao_maxdata[i])
      code = impl_->ao_maxdata[i];
    impl_->data[i] = code;
  }
  return clamped ? DaqStatus::kClamped : DaqStatus::kOk;
}

#else  // no libcomedi in this build

bool comedi_available() noexcept {
  return false;
}
struct ComediBackend::Impl {};
ComediBackend::ComediBackend(ComediOptions options) : options_(std::move(options)) {}
ComediBackend::~ComediBackend() = default;
void ComediBackend::configure() {
  throw core::InputError(fmt::format(
      "{}: this piezoshift was built without libcomedi (install libcomedi-dev and rebuild)",
      options_.device));
}
void ComediBackend::activate() {
  configure();
}
void ComediBackend::deactivate() noexcept {}
std::string ComediBackend::device_error() const {
  return {};
}
std::string ComediBackend::safe_state_error() const {
  return {};
}
void ComediBackend::stage_trigger_line(bool) noexcept {}
DaqStatus ComediBackend::read(const CycleTime&, Vec3&) noexcept {
  return DaqStatus::kInactive;
}
DaqStatus ComediBackend::write(const CycleTime&, const Vec3&) noexcept {
  return DaqStatus::kInactive;
}

#endif

}  // namespace piezoshift::runtime
