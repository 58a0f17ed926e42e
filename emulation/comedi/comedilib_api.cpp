// libcomedi's C API (comedilib.h, Comedilib's reference manual) over the emulated board: opening
// and closing, errors, the device's and subdevices' description, instructions, and the one-sample
// reads and writes. Built as libcomedi.so.0 with every symbol of libcomedi 0.11 at its symbol
// version (libcomedi.map), so any Comedi program loads it in place of Debian's libcomedi0 when
// LD_LIBRARY_PATH names its folder. Each function returns what the manual documents, failing
// where libcomedi or the kernel's ni_pcimio driver would, with the same error codes
// (api_handle.hpp). The other functions: comedilib_calibration.cpp, comedilib_async.cpp
// (commands, buffers, locks), comedilib_config.cpp (configuration instructions, conversions).
#include <comedilib.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <string>

#include <fmt/core.h>

#include "api_handle.hpp"

namespace piezoshift::emulation::api {

namespace {
thread_local int last_error = 0;  // comedi_errno(): per thread, as libcomedi's
int log_level = 1;                // comedi_loglevel(); COMEDILIB_LOGLEVEL sets it at open
}  // namespace

int fail(int error) {
  last_error = error;
  errno = error;
  return -1;
}

int fail_internal(int error) {
  last_error = error;
  if (log_level >= 2)
    comedi_perror("internal error");
  return -1;
}

int fail_from_errno() {
  last_error = errno;
  return -1;
}

int current_error() {
  return last_error;
}

int set_log_level(int level) {
  const int old = log_level;
  log_level = level;
  return old;
}

int current_log_level() {
  return log_level;
}

bool valid_dev(const comedi_t* it) {
  if (it == nullptr || it->magic != comedi_t_struct::kMagic) {
    fail_internal(EBAD_CT);
    return false;
  }
  return true;
}

bool valid_subd(const comedi_t* it, unsigned subd) {
  if (!valid_dev(it))
    return false;
  if (subd >= it->board->model().subdevices.size()) {
    fail_internal(EINVAL_SUBD);
    return false;
  }
  return true;
}

bool valid_chan(const comedi_t* it, unsigned subd, unsigned chan) {
  if (!valid_subd(it, subd))
    return false;
  if (chan >= model_of(it, subd).n_chan) {
    fail_internal(EINVAL_CHAN);
    return false;
  }
  return true;
}

const SubdeviceModel& model_of(const comedi_t* it, unsigned subd) {
  return it->board->model().subdevices[subd];
}

int do_insn(comedi_t* it, comedi_insn& insn) {
  // COMEDI_INSN: more than the kernel's MAX_SAMPLES are cut to it rather than refused.
  if (insn.n > EmulatedBoard::kMaxSamples)
    insn.n = EmulatedBoard::kMaxSamples;
  comedi_insnlist one{1, &insn};
  if (it->board->do_insnlist(one) < 0)
    return fail_from_errno();
  return static_cast<int>(insn.n);
}

int config(comedi_t* it, unsigned subd, unsigned chanspec, lsampl_t* data, unsigned n) {
  if (!valid_dev(it))
    return -1;
  comedi_insn insn{};
  insn.insn = INSN_CONFIG;
  insn.subdev = subd;
  insn.chanspec = chanspec;
  insn.n = n;
  insn.data = data;
  return do_insn(it, insn) < 0 ? -1 : 0;
}

}  // namespace piezoshift::emulation::api

namespace {

using piezoshift::emulation::SubdeviceModel;
using namespace piezoshift::emulation::api;

// The minor number of /dev/comediN, for the calibration file's name.
std::string minor_of(const std::string& device) {
  std::size_t i = device.size();
  while (i > 0 && device[i - 1] >= '0' && device[i - 1] <= '9')
    --i;
  return i < device.size() ? device.substr(i) : "0";
}

// The descriptor comedi_fileno() returns (api_handle.hpp): the read end of a pipe whose write
// end is closed.
int end_of_data_fd() {
  int ends[2] = {-1, -1};
  if (pipe2(ends, O_CLOEXEC) != 0)
    return -1;
  close(ends[1]);
  return ends[0];
}

// libcomedi's messages for its own codes (COMEDI_NOERROR + 0..8), in comedi_errno.h's order.
constexpr const char* kLibraryErrors[] = {
    "No error",          "Unknown error",         "Bad comedi_t structure",
    "Invalid subdevice", "Invalid channel",       "Buffer overflow",
    "Buffer underflow",  "Command not supported", "Not supported"};

}  // namespace

// libcomedi 0.7.18's comedi_get_subdevice_flags: the flags read when the device was opened.
extern "C" int piezoshift_comedi_get_subdevice_flags_v0_7_18(comedi_t* it, unsigned int subd);
__asm__(".symver piezoshift_comedi_get_subdevice_flags_v0_7_18,comedi_get_subdevice_flags@v0.7.18");

extern "C" {

comedi_t* comedi_open(const char* fn) {
  using namespace piezoshift::emulation;
  static const bool from_environment = [] {
    if (const char* level = std::getenv("COMEDILIB_LOGLEVEL"))
      set_log_level(static_cast<int>(std::strtol(level, nullptr, 0)));
    return true;
  }();
  (void)from_environment;
  const char* file = std::getenv("PIEZOSHIFT_COMEDI_EMULATION");
  try {
    EmulationSettings settings = load_emulation_settings(file);
    if (fn == nullptr || settings.device != fn) {
      fail(ENOENT);  // open(2) of a path with no device: the one device is settings.device
      return nullptr;
    }
    auto model = ni_m_series_board(settings.model);
    for (comedi_range& r : model->subdevices[kAoSubdevice].ranges)
      r = comedi_range{-settings.ao_reference_V, settings.ao_reference_V, UNIT_volt};
    auto it = std::make_unique<comedi_t_struct>();
    it->calibration_path = fmt::format("/var/lib/comedi/calibrations/{}_{}_comedi{}", model->driver,
                                       model->name, minor_of(settings.device));
    it->locked.assign(model->subdevices.size(), false);
    const bool calibrated = settings.calibrated;
    it->board = std::make_unique<EmulatedBoard>(std::move(settings), *model);
    if (calibrated)
      register_calibration(it->calibration_path, *model);
    it->fd = end_of_data_fd();
    if (it->fd < 0) {
      fail(errno);
      return nullptr;
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
  if (!valid_dev(it))
    return -1;
  it->magic = 0;
  it->board->write_records();
  close(it->fd);
  delete it;
  return 0;
}

int comedi_loglevel(int loglevel) {
  return set_log_level(loglevel);
}

int comedi_errno(void) {
  return current_error();
}

const char* comedi_strerror(int errnum) {
  const int i = errnum - COMEDI_NOERROR;
  if (i < 0 || i >= static_cast<int>(std::size(kLibraryErrors)))
    return std::strerror(errnum);
  return kLibraryErrors[i];
}

void comedi_perror(const char* s) {
  if (current_log_level() >= 3)
    std::fprintf(stderr, "comedi_perror(): __comedi_errno=%d\n", current_error());
  std::fprintf(stderr, "%s: %s\n", s != nullptr ? s : "comedilib",
               comedi_strerror(current_error()));
}

int comedi_get_version_code(comedi_t* it) {
  if (!valid_dev(it))
    return -1;
  return COMEDI_VERSION_CODE(0, 7, 76);  // the kernel's comedi core reports 0.7.76
}

const char* comedi_get_driver_name(comedi_t* it) {
  return valid_dev(it) ? it->board->model().driver.c_str() : nullptr;
}

const char* comedi_get_board_name(comedi_t* it) {
  return valid_dev(it) ? it->board->model().name.c_str() : nullptr;
}

int comedi_get_n_subdevices(comedi_t* it) {
  return valid_dev(it) ? static_cast<int>(it->board->model().subdevices.size()) : -1;
}

int comedi_get_subdevice_type(comedi_t* it, unsigned int subd) {
  return valid_subd(it, subd) ? model_of(it, subd).type : -1;
}

int comedi_find_subdevice_by_type(comedi_t* it, int type, unsigned int subd) {
  if (!valid_subd(it, subd))
    return -1;
  const auto& subs = it->board->model().subdevices;
  for (unsigned i = subd; i < subs.size(); ++i)
    if (subs[i].type == type)
      return static_cast<int>(i);
  return -1;  // none: no error code, as libcomedi
}

int comedi_get_subdevice_flags(comedi_t* it, unsigned int subd) {
  // COMEDI_SUBDINFO's subd_flags now: the driver's flags and the lock's state (no subdevice
  // has a command, so none is ever SDF_CMD, SDF_BUSY or SDF_RUNNING).
  if (!valid_subd(it, subd))
    return -1;
  return model_of(it, subd).flags | (it->locked[subd] ? SDF_LOCKED | SDF_LOCK_OWNER : 0);
}

int piezoshift_comedi_get_subdevice_flags_v0_7_18(comedi_t* it, unsigned int subd) {
  return valid_subd(it, subd) ? model_of(it, subd).flags : 0;
}

int comedi_get_n_channels(comedi_t* it, unsigned int subd) {
  return valid_subd(it, subd) ? static_cast<int>(model_of(it, subd).n_chan) : -1;
}

int comedi_range_is_chan_specific(comedi_t* it, unsigned int subd) {
  return valid_subd(it, subd) ? 0 : -1;  // one range table per subdevice on this board
}

int comedi_maxdata_is_chan_specific(comedi_t* it, unsigned int subd) {
  return valid_subd(it, subd) ? 0 : -1;  // one maxdata per subdevice on this board
}

lsampl_t comedi_get_maxdata(comedi_t* it, unsigned int subd, unsigned int chan) {
  return valid_chan(it, subd, chan) ? model_of(it, subd).maxdata : 0;
}

int comedi_get_rangetype(comedi_t* it, unsigned int subd, unsigned int chan) {
  // COMEDI_SUBDINFO's range_type: subdevice << 24 | table length (0 for an unused subdevice)
  if (!valid_chan(it, subd, chan))
    return -1;
  const auto n = static_cast<int>(model_of(it, subd).ranges.size());
  return n > 0 ? static_cast<int>(subd << 24) | n : 0;
}

int comedi_get_n_ranges(comedi_t* it, unsigned int subd, unsigned int chan) {
  return valid_chan(it, subd, chan) ? static_cast<int>(model_of(it, subd).ranges.size()) : -1;
}

comedi_range* comedi_get_range(comedi_t* it, unsigned int subd, unsigned int chan,
                               unsigned int range) {
  if (!valid_chan(it, subd, chan) || range >= model_of(it, subd).ranges.size())
    return nullptr;  // a range beyond the table: NULL without an error code, as libcomedi
  // The manual's signature is not const; the table is never written through it.
  return const_cast<comedi_range*>(&model_of(it, subd).ranges[range]);
}

int comedi_find_range(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int unit,
                      double min, double max) {
  if (!valid_chan(it, subd, chan))
    return -1;
  const SubdeviceModel& s = model_of(it, subd);
  int best = -1;  // the smallest range of that unit holding [min, max]
  for (std::size_t i = 0; i < s.ranges.size(); ++i) {
    const comedi_range& r = s.ranges[i];
    if (r.unit != unit || r.min > min || r.max < max)
      continue;
    if (best < 0 || r.max - r.min < s.ranges[best].max - s.ranges[best].min)
      best = static_cast<int>(i);
  }
  return best;
}

int comedi_do_insnlist(comedi_t* it, comedi_insnlist* il) {
  if (!valid_dev(it))
    return -1;
  if (il == nullptr || (il->n_insns > 0 && il->insns == nullptr))
    return fail(EFAULT);
  const int r = it->board->do_insnlist(*il);
  return r < 0 ? fail_from_errno() : r;
}

int comedi_do_insn(comedi_t* it, comedi_insn* insn) {
  if (!valid_dev(it))
    return -1;
  if (insn == nullptr)
    return fail(EFAULT);
  return do_insn(it, *insn);  // the number of samples done (insn->n)
}

int comedi_data_read(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range,
                     unsigned int aref, lsampl_t* data) {
  if (!valid_subd(it, subd))
    return -1;
  comedi_insn insn{};
  insn.insn = INSN_READ;
  insn.n = 1;
  insn.data = data;
  insn.subdev = subd;
  insn.chanspec = CR_PACK(chan, range, aref);
  return do_insn(it, insn);
}

int comedi_data_read_n(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range,
                       unsigned int aref, lsampl_t* data, unsigned int n) {
  if (!valid_subd(it, subd))
    return -1;
  // In instructions of at most 100 samples, as libcomedi; 0 when all were read.
  for (unsigned done = 0; done < n;) {
    comedi_insn insn{};
    insn.insn = INSN_READ;
    insn.n = std::min(n - done, 100u);
    insn.data = data + done;
    insn.subdev = subd;
    insn.chanspec = CR_PACK(chan, range, aref);
    if (do_insn(it, insn) < 0)
      return -1;
    done += insn.n;
  }
  return 0;
}

int comedi_data_read_hint(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range,
                          unsigned int aref) {
  if (!valid_subd(it, subd))
    return -1;
  lsampl_t unused = 0;
  comedi_insn insn{};  // a read of no sample: the driver selects the channel
  insn.insn = INSN_READ;
  insn.data = &unused;
  insn.subdev = subd;
  insn.chanspec = CR_PACK(chan, range, aref);
  return do_insn(it, insn);
}

int comedi_data_read_delayed(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range,
                             unsigned int aref, lsampl_t* data, unsigned int nano_sec) {
  if (!valid_chan(it, subd, chan))
    return -1;
  // Select the channel, wait nano_sec, convert: one list of three instructions.
  lsampl_t delay = nano_sec;
  comedi_insn insns[3]{};
  insns[0].insn = INSN_READ;
  insns[0].data = data;
  insns[0].subdev = subd;
  insns[0].chanspec = CR_PACK(chan, range, aref);
  insns[1].insn = INSN_WAIT;
  insns[1].n = 1;
  insns[1].data = &delay;
  insns[2] = insns[0];
  insns[2].n = 1;
  comedi_insnlist list{3, insns};
  return comedi_do_insnlist(it, &list);
}

int comedi_data_write(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range,
                      unsigned int aref, lsampl_t data) {
  if (!valid_chan(it, subd, chan))
    return -1;
  comedi_insn insn{};
  insn.insn = INSN_WRITE;
  insn.n = 1;
  insn.data = &data;
  insn.subdev = subd;
  insn.chanspec = CR_PACK(chan, range, aref);
  return do_insn(it, insn);
}

}  // extern "C"
