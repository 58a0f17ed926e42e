// libcomedi's calibration functions (comedilib.h, "calibration" in Comedilib's reference manual)
// over the emulated board: its calibration file is the one comedi_soft_calibrate would write for
// it, held in memory (the board's polynomials are known), and the conversions through a
// calibration's polynomials or a board's hardware calibration.
#include <comedilib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "api_handle.hpp"

namespace {

using piezoshift::emulation::BoardModel;
using piezoshift::emulation::SubdeviceModel;
using piezoshift::emulation::api::fail;
using piezoshift::emulation::api::fail_internal;
using piezoshift::emulation::api::model_of;
using piezoshift::emulation::api::valid_chan;
using piezoshift::emulation::api::valid_dev;

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

namespace piezoshift::emulation::api {

void register_calibration(const std::string& path, const BoardModel& model) {
  const std::lock_guard lock(store().mutex);
  store().boards.insert_or_assign(path, model);
}

}  // namespace piezoshift::emulation::api

extern "C" {

char* comedi_get_default_calibration_path(comedi_t* dev) {
  if (!valid_dev(dev))
    return nullptr;
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
  if (!valid_chan(dev, subdevice_index, channel))
    return -1;
  const SubdeviceModel* s = &model_of(dev, subdevice_index);
  if (polynomial == nullptr || range >= s->ranges.size() || s->maxdata == 0)
    return fail_internal(EINVAL);
  if ((s->flags & SDF_SOFT_CALIBRATED) != 0)
    return fail_internal(EINVAL);  // its codes need the software calibration's polynomials
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

int comedi_apply_parsed_calibration(comedi_t* dev, unsigned int subdev, unsigned int channel,
                                    unsigned int range, unsigned int aref,
                                    const comedi_calibration_t* calibration) {
  if (!valid_dev(dev))
    return -1;
  if (calibration == nullptr || calibration->driver_name == nullptr ||
      calibration->board_name == nullptr ||
      std::strcmp(calibration->driver_name, dev->board->model().driver.c_str()) != 0 ||
      std::strcmp(calibration->board_name, dev->board->model().name.c_str()) != 0)
    return -1;  // a file for another board: refused without an error code, as libcomedi does
  bool found = false;
  const auto lists = [](const unsigned* v, unsigned n, unsigned x) {
    if (n == 0)
      return true;  // no list: every value
    for (unsigned i = 0; i < n; ++i)
      if (v[i] == x)
        return true;
    return false;
  };
  for (unsigned i = 0; i < calibration->num_settings; ++i) {
    const comedi_calibration_setting_t& s = calibration->settings[i];
    if (s.subdevice != subdev || !lists(s.channels, s.num_channels, channel) ||
        !lists(s.ranges, s.num_ranges, range) || !lists(s.arefs, s.num_arefs, aref))
      continue;
    found = true;
    // A hardware calibration writes its caldacs; an M Series file has none (software only).
    for (unsigned k = 0; k < s.num_caldacs; ++k) {
      const comedi_caldac_t& c = s.caldacs[k];
      if (comedi_data_write(dev, c.subdevice, c.channel, 0, 0, c.value) < 0)
        return -1;
    }
  }
  return found ? 0 : -1;
}

int comedi_apply_calibration(comedi_t* dev, unsigned int subdev, unsigned int channel,
                             unsigned int range, unsigned int aref, const char* cal_file_path) {
  std::string path;
  if (cal_file_path != nullptr) {
    path = cal_file_path;
  } else {
    char* p = comedi_get_default_calibration_path(dev);
    if (p == nullptr)
      return -1;
    path = p;
    std::free(p);
  }
  comedi_calibration_t* parsed = comedi_parse_calibration_file(path.c_str());
  if (parsed == nullptr)
    return -1;
  const int r = comedi_apply_parsed_calibration(dev, subdev, channel, range, aref, parsed);
  comedi_cleanup_calibration(parsed);
  return r;
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
