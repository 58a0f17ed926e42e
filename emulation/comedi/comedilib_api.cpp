// libcomedi's C API (comedilib.h, Comedilib's reference manual) over the emulated board: the
// functions piezoshift's Comedi backend calls and the common ones around them, each returning
// what the manual documents (-1 or NULL with comedi_errno() set on failure). Built as
// libcomedi.so.0 with libcomedi's symbol versions (libcomedi.map), so the unchanged piezoshift
// program loads it in place of Debian's libcomedi0 when LD_LIBRARY_PATH names its folder.
// Functions not listed here are absent: a client calling one fails to load, never silently.
#include <comedilib.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "emulated_board.hpp"

struct comedi_t_struct {
  std::unique_ptr<piezoshift::emulation::EmulatedBoard> board;
  std::string calibration_path;
};

namespace {

using piezoshift::emulation::BoardModel;
using piezoshift::emulation::EmulatedBoard;
using piezoshift::emulation::SubdeviceModel;

thread_local int last_error = 0;

int fail(int error) {
  last_error = error;
  errno = error;
  return -1;
}

// The calibrations comedi_parse_calibration_file() hands out, by the default path of the board
// that was opened (the emulation reads no calibration file: the board's polynomials are known).
struct CalibrationStore {
  std::mutex mutex;
  std::map<std::string, BoardModel> boards;  // default calibration path -> its board
  std::map<const comedi_calibration_t*, std::shared_ptr<void>> owned;
};
CalibrationStore& store() {
  static CalibrationStore s;
  return s;
}

const SubdeviceModel* subdevice(comedi_t* it, unsigned subd) {
  if (it == nullptr || subd >= it->board->model().subdevices.size()) {
    fail(EINVAL);
    return nullptr;
  }
  return &it->board->model().subdevices[subd];
}

// The minor number of /dev/comediN, for the calibration file's name.
std::string minor_of(const std::string& device) {
  std::size_t i = device.size();
  while (i > 0 && device[i - 1] >= '0' && device[i - 1] <= '9')
    --i;
  return i < device.size() ? device.substr(i) : "0";
}

struct OwnedCalibration {
  comedi_calibration_t calibration{};
  std::vector<comedi_calibration_setting_t> settings;
  std::vector<unsigned> numbers;  // channels and ranges, one each per setting
  std::vector<comedi_polynomial_t> polynomials;
  std::string driver, board;
};

std::shared_ptr<OwnedCalibration> make_calibration(const BoardModel& b) {
  auto c = std::make_shared<OwnedCalibration>();
  c->driver = b.driver;
  c->board = b.name;
  std::size_t n = 0;
  for (unsigned sub : {piezoshift::emulation::kAiSubdevice, piezoshift::emulation::kAoSubdevice})
    if (b.subdevices[sub].type != COMEDI_SUBD_UNUSED)
      n += b.subdevices[sub].n_chan * b.subdevices[sub].ranges.size();
  c->settings.resize(n);
  c->numbers.resize(2 * n);
  c->polynomials.resize(n);
  std::size_t k = 0;
  for (unsigned sub : {piezoshift::emulation::kAiSubdevice, piezoshift::emulation::kAoSubdevice}) {
    const SubdeviceModel& s = b.subdevices[sub];
    if (s.type == COMEDI_SUBD_UNUSED)
      continue;
    for (unsigned ch = 0; ch < s.n_chan; ++ch) {
      for (unsigned r = 0; r < s.ranges.size(); ++r, ++k) {
        const auto raw = sub == piezoshift::emulation::kAiSubdevice ? b.ai_raw(ch) : b.ao_raw(ch);
        comedi_calibration_setting_t& set = c->settings[k];
        set.subdevice = sub;
        c->numbers[2 * k] = ch;
        c->numbers[2 * k + 1] = r;
        set.channels = &c->numbers[2 * k];
        set.num_channels = 1;
        set.ranges = &c->numbers[2 * k + 1];
        set.num_ranges = 1;
        // An AI setting converts codes to volts, an AO setting volts to codes (M Series).
        comedi_polynomial_t& p = c->polynomials[k];
        if (sub == piezoshift::emulation::kAiSubdevice) {
          p = piezoshift::emulation::to_physical_polynomial(s.ranges[r], s.maxdata, raw);
          set.soft_calibration.to_phys = &p;
        } else {
          p = piezoshift::emulation::from_physical_polynomial(s.ranges[r], s.maxdata, raw);
          set.soft_calibration.from_phys = &p;
        }
      }
    }
  }
  c->calibration.driver_name = c->driver.data();
  c->calibration.board_name = c->board.data();
  c->calibration.settings = c->settings.data();
  c->calibration.num_settings = static_cast<unsigned>(n);
  return c;
}

double polynomial(double x, const comedi_polynomial_t& p) {
  double sum = 0.0;
  double term = 1.0;
  for (unsigned i = 0; i <= p.order && i < COMEDI_MAX_NUM_POLYNOMIAL_COEFFICIENTS; ++i) {
    sum += p.coefficients[i] * term;
    term *= x - p.expansion_origin;
  }
  return sum;
}

}  // namespace

extern "C" {

comedi_t* comedi_open(const char* fn) {
  using namespace piezoshift::emulation;
  const char* file = std::getenv("PIEZOSHIFT_COMEDI_EMULATION");
  try {
    EmulationSettings settings = load_emulation_settings(file);
    if (fn == nullptr || settings.device != fn) {
      fail(ENOENT);  // the one device this emulation has is settings.device
      return nullptr;
    }
    auto model = ni_m_series_board(settings.model);
    for (comedi_range& r : model->subdevices[kAoSubdevice].ranges)
      r = comedi_range{-settings.ao_reference_V, settings.ao_reference_V, UNIT_volt};
    auto it = std::make_unique<comedi_t_struct>();
    it->calibration_path = fmt::format("/var/lib/comedi/calibrations/{}_{}_comedi{}", model->driver,
                                       model->name, minor_of(settings.device));
    const bool calibrated = settings.calibrated;
    it->board = std::make_unique<EmulatedBoard>(std::move(settings), *model);
    if (calibrated) {
      const std::lock_guard lock(store().mutex);
      store().boards.insert_or_assign(it->calibration_path, *model);
    }
    return it.release();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "piezoshift comedi emulation (PIEZOSHIFT_COMEDI_EMULATION): %s\n",
                 e.what());
    fail(EINVAL);
    return nullptr;
  }
}

int comedi_close(comedi_t* it) {
  if (it == nullptr)
    return fail(EINVAL);
  it->board->write_records();
  delete it;
  return 0;
}

int comedi_errno(void) {
  return last_error;
}

const char* comedi_strerror(int errnum) {
  return std::strerror(errnum);
}

void comedi_perror(const char* s) {
  std::fprintf(stderr, "%s: %s\n", s != nullptr ? s : "", std::strerror(last_error));
}

int comedi_get_version_code(comedi_t* it) {
  if (it == nullptr)
    return fail(EINVAL);
  return (0 << 16) | (7 << 8) | 76;  // comedi 0.7.76, as current kernels report
}

const char* comedi_get_driver_name(comedi_t* it) {
  return it != nullptr ? it->board->model().driver.c_str() : nullptr;
}

const char* comedi_get_board_name(comedi_t* it) {
  return it != nullptr ? it->board->model().name.c_str() : nullptr;
}

int comedi_get_n_subdevices(comedi_t* it) {
  if (it == nullptr)
    return fail(EINVAL);
  return static_cast<int>(it->board->model().subdevices.size());
}

int comedi_get_subdevice_type(comedi_t* it, unsigned int subd) {
  const SubdeviceModel* s = subdevice(it, subd);
  return s != nullptr ? s->type : -1;
}

int comedi_find_subdevice_by_type(comedi_t* it, int type, unsigned int subd) {
  if (it == nullptr)
    return fail(EINVAL);
  const auto& subs = it->board->model().subdevices;
  for (unsigned i = subd; i < subs.size(); ++i)
    if (subs[i].type == type)
      return static_cast<int>(i);
  return fail(ENODEV);
}

int comedi_get_subdevice_flags(comedi_t* it, unsigned int subdevice_index) {
  const SubdeviceModel* s = subdevice(it, subdevice_index);
  return s != nullptr ? s->flags : -1;
}

int comedi_get_n_channels(comedi_t* it, unsigned int subd) {
  const SubdeviceModel* s = subdevice(it, subd);
  return s != nullptr ? static_cast<int>(s->n_chan) : -1;
}

lsampl_t comedi_get_maxdata(comedi_t* it, unsigned int subd, unsigned int chan) {
  const SubdeviceModel* s = subdevice(it, subd);
  if (s == nullptr || chan >= s->n_chan) {
    fail(EINVAL);
    return 0;
  }
  return s->maxdata;
}

int comedi_get_n_ranges(comedi_t* it, unsigned int subd, unsigned int chan) {
  const SubdeviceModel* s = subdevice(it, subd);
  if (s == nullptr || chan >= s->n_chan)
    return fail(EINVAL);
  return static_cast<int>(s->ranges.size());
}

comedi_range* comedi_get_range(comedi_t* it, unsigned int subd, unsigned int chan,
                               unsigned int range) {
  const SubdeviceModel* s = subdevice(it, subd);
  if (s == nullptr || chan >= s->n_chan || range >= s->ranges.size()) {
    fail(EINVAL);
    return nullptr;
  }
  return const_cast<comedi_range*>(&s->ranges[range]);  // the manual's signature; never written
}

int comedi_find_range(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int unit,
                      double min, double max) {
  const SubdeviceModel* s = subdevice(it, subd);
  if (s == nullptr || chan >= s->n_chan)
    return fail(EINVAL);
  int best = -1;  // the smallest range of that unit holding [min, max]
  for (std::size_t i = 0; i < s->ranges.size(); ++i) {
    const comedi_range& r = s->ranges[i];
    if (r.unit != unit || r.min > min || r.max < max)
      continue;
    if (best < 0 || r.max - r.min < s->ranges[best].max - s->ranges[best].min)
      best = static_cast<int>(i);
  }
  return best >= 0 ? best : fail(EINVAL);
}

int comedi_do_insnlist(comedi_t* it, comedi_insnlist* il) {
  if (it == nullptr || il == nullptr || (il->n_insns > 0 && il->insns == nullptr))
    return fail(EFAULT);
  const int r = it->board->do_insnlist(*il);
  if (r < 0)
    last_error = errno;
  return r;
}

int comedi_do_insn(comedi_t* it, comedi_insn* insn) {
  if (insn == nullptr)
    return fail(EFAULT);
  comedi_insnlist one{1, insn};
  // The manual: the number of samples done (insn->n) for a read or write.
  return comedi_do_insnlist(it, &one) < 0 ? -1 : static_cast<int>(insn->n);
}

int comedi_data_read(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range,
                     unsigned int aref, lsampl_t* data) {
  comedi_insn insn{};
  insn.insn = INSN_READ;
  insn.n = 1;
  insn.data = data;
  insn.subdev = subd;
  insn.chanspec = CR_PACK(chan, range, aref);
  return comedi_do_insn(it, &insn) < 0 ? -1 : 1;
}

int comedi_data_write(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range,
                      unsigned int aref, lsampl_t data) {
  comedi_insn insn{};
  insn.insn = INSN_WRITE;
  insn.n = 1;
  insn.data = &data;
  insn.subdev = subd;
  insn.chanspec = CR_PACK(chan, range, aref);
  return comedi_do_insn(it, &insn) < 0 ? -1 : 1;
}

int comedi_dio_config(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int dir) {
  if (it == nullptr)
    return fail(EINVAL);
  const int r = it->board->dio_config(subd, chan, dir);
  if (r < 0)
    last_error = errno;
  return r;
}

int comedi_dio_write(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int bit) {
  return comedi_data_write(it, subd, chan, 0, 0, bit != 0 ? 1 : 0);
}

int comedi_dio_read(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int* bit) {
  lsampl_t v = 0;
  const int r = comedi_data_read(it, subd, chan, 0, 0, &v);
  if (r >= 0 && bit != nullptr)
    *bit = v;
  return r;
}

char* comedi_get_default_calibration_path(comedi_t* dev) {
  if (dev == nullptr) {
    fail(EINVAL);
    return nullptr;
  }
  return strdup(dev->calibration_path.c_str());
}

comedi_calibration_t* comedi_parse_calibration_file(const char* cal_file_path) {
  if (cal_file_path == nullptr) {
    fail(EINVAL);
    return nullptr;
  }
  const std::lock_guard lock(store().mutex);
  const auto b = store().boards.find(cal_file_path);
  if (b == store().boards.end()) {
    fail(ENOENT);  // no comedi_soft_calibrate was run for it ([board] calibrated = false)
    return nullptr;
  }
  std::shared_ptr<OwnedCalibration> c = make_calibration(b->second);
  comedi_calibration_t* handle = &c->calibration;
  store().owned[handle] = c;
  return handle;
}

void comedi_cleanup_calibration(comedi_calibration_t* calibration) {
  const std::lock_guard lock(store().mutex);
  store().owned.erase(calibration);
}

int comedi_get_softcal_converter(unsigned subdevice_index, unsigned channel, unsigned range,
                                 enum comedi_conversion_direction direction,
                                 const comedi_calibration_t* calibration,
                                 comedi_polynomial_t* polynomial) {
  if (calibration == nullptr || polynomial == nullptr)
    return fail(EINVAL);
  for (unsigned i = 0; i < calibration->num_settings; ++i) {
    const comedi_calibration_setting_t& s = calibration->settings[i];
    if (s.subdevice != subdevice_index || s.channels[0] != channel || s.ranges[0] != range)
      continue;
    const comedi_polynomial_t* p =
        direction == COMEDI_TO_PHYSICAL ? s.soft_calibration.to_phys : s.soft_calibration.from_phys;
    if (p == nullptr)
      return fail(EINVAL);  // e.g. an AO setting asked to convert codes to volts
    *polynomial = *p;
    return 0;
  }
  return fail(EINVAL);
}

int comedi_get_hardcal_converter(comedi_t* dev, unsigned subdevice_index, unsigned channel,
                                 unsigned range, enum comedi_conversion_direction direction,
                                 comedi_polynomial_t* polynomial) {
  const SubdeviceModel* s = subdevice(dev, subdevice_index);
  if (s == nullptr || polynomial == nullptr || channel >= s->n_chan || range >= s->ranges.size())
    return fail(EINVAL);
  if ((s->flags & SDF_SOFT_CALIBRATED) != 0)
    return fail(EINVAL);  // its codes need the software calibration's polynomials
  const comedi_range& r = s->ranges[range];
  comedi_polynomial_t p{};
  p.order = 1;
  if (direction == COMEDI_TO_PHYSICAL) {
    p.coefficients[0] = r.min;
    p.coefficients[1] = (r.max - r.min) / s->maxdata;
  } else {
    p.expansion_origin = r.min;
    p.coefficients[1] = s->maxdata / (r.max - r.min);
  }
  *polynomial = p;
  return 0;
}

double comedi_to_physical(lsampl_t data, const comedi_polynomial_t* conversion_polynomial) {
  return conversion_polynomial != nullptr
             ? polynomial(static_cast<double>(data), *conversion_polynomial)
             : std::nan("");
}

lsampl_t comedi_from_physical(double data, const comedi_polynomial_t* conversion_polynomial) {
  if (conversion_polynomial == nullptr)
    return 0;
  const double code = std::nearbyint(polynomial(data, *conversion_polynomial));
  if (!(code > 0.0))
    return 0;
  return code >= 4294967295.0 ? 0xffffffffu : static_cast<lsampl_t>(code);
}

}  // extern "C"
