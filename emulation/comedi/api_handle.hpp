#pragma once
// What the emulation's libcomedi functions share: the opened device behind a comedi_t, the
// library's error state, and the argument checks libcomedi makes before it asks the kernel.
//
// libcomedi keeps two kinds of errors in comedi_errno(): the kernel's errno of a failed ioctl
// (errno is then set too), and the library's own codes (comedi_errno.h: EBAD_CT for a bad handle,
// EINVAL_SUBD, EINVAL_CHAN, ECMDNOTSUPP, ...) for arguments it refuses itself, which leave errno
// alone. The functions below keep that split, so a program's comedi_perror, strerror(errno) and
// comedi_strerror(comedi_errno()) say what they say with the real library.
#include <comedi_errno.h>
#include <comedilib.h>

#include <memory>
#include <string>
#include <vector>

#include "emulated_board.hpp"

struct comedi_t_struct {
  static constexpr unsigned kMagic = 0xc001dafe;  // a handle comedi_close has not freed
  unsigned magic = kMagic;
  std::unique_ptr<piezoshift::emulation::EmulatedBoard> board;
  std::string calibration_path;
  //! What comedi_fileno() returns: a pipe's read end whose write end is closed (no character
  //! device here), so read() ends at once, write() fails (EBADF), mmap() fails (ENODEV).
  int fd = -1;
  std::vector<bool> locked;  //!< comedi_lock'ed subdevices
};

namespace piezoshift::emulation::api {

//! A kernel refusal: comedi_errno() and errno both become `error`; returns -1.
int fail(int error);
//! A refusal by the library itself (comedi_errno.h's codes, or EINVAL for a bad argument):
//! comedi_errno() becomes `error`, errno is left as it was; returns -1.
int fail_internal(int error);
//! Records errno as comedi_errno() after a failed call into the board; returns -1.
int fail_from_errno();

//! comedi_errno()'s value, and comedi_loglevel()'s (returns the old level).
int current_error();
int set_log_level(int level);
int current_log_level();

//! Makes comedi_parse_calibration_file(path) give the board's calibration (a board whose
//! comedi_soft_calibrate was run).
void register_calibration(const std::string& path, const BoardModel& model);

//! libcomedi's checks: the handle (EBAD_CT), the subdevice (EINVAL_SUBD), the channel
//! (EINVAL_CHAN). False with comedi_errno() set.
bool valid_dev(const comedi_t* it);
bool valid_subd(const comedi_t* it, unsigned subd);
bool valid_chan(const comedi_t* it, unsigned subd, unsigned chan);

//! The subdevice's description (after valid_subd).
const SubdeviceModel& model_of(const comedi_t* it, unsigned subd);

//! One instruction through the board, as comedi_do_insn: its result, or -1 with the errors set.
int do_insn(comedi_t* it, comedi_insn& insn);
//! An INSN_CONFIG of `data` on subdevice/channel: 0, or -1 with the errors set.
int config(comedi_t* it, unsigned subd, unsigned chanspec, lsampl_t* data, unsigned n);

}  // namespace piezoshift::emulation::api
