// libcomedi's asynchronous side over the emulated board: commands, their buffers, the device's
// descriptor, locks, the read and write subdevices, and the old functions built on the
// long-gone COMEDI_TRIG ioctl (comedilib.h).
//
// The emulated PCI-6229 is the board as ni_pcimio attaches it without an interrupt line
// (board_model.hpp): no subdevice has a command handler or a buffer. Every call answers as the
// kernel then answers it (comedi_fops.c): a command or its test fails with EIO ("does not
// support commands"; comedi_errno() ECMDNOTSUPP, as libcomedi maps it), a subdevice beyond the
// device ENODEV; buffer sizes read 0; buffer positions, cancel and the read/write subdevice's
// change fail with EINVAL; COMEDI_TRIG (comedi_trigger, comedi_sv_measure) fails with ENOTTY.
#define _COMEDILIB_DEPRECATED  // comedi_trigger, comedi_get_timer, comedi_timed_1chan
#include <comedilib.h>

#include <cerrno>

#include "api_handle.hpp"

namespace {

using namespace piezoshift::emulation::api;

// COMEDI_CMD and COMEDI_CMDTEST's checks before the subdevice's handler (__comedi_get_user_cmd).
int refuse_command(comedi_t* it, const comedi_cmd* cmd) {
  if (!valid_dev(it))
    return -1;
  if (cmd == nullptr)
    return fail(EFAULT);
  if (cmd->subdev >= it->board->model().subdevices.size())
    return fail(ENODEV);
  fail(EIO);  // an unused subdevice, or one without commands: every one here
  fail_internal(ECMDNOTSUPP);
  return -1;
}

// COMEDI_BUFINFO: a subdevice without a buffer (or beyond the device) is EINVAL.
int buffer_info(comedi_t* it, unsigned subd) {
  if (!valid_subd(it, subd))
    return -1;
  return fail(EINVAL);
}

// COMEDI_BUFCONFIG on a subdevice without a buffer: sizes 0, no error.
int buffer_config(comedi_t* it, unsigned subd) {
  return valid_subd(it, subd) ? 0 : -1;
}

// COMEDI_SETRSUBD / COMEDI_SETWSUBD: only a subdevice with SDF_CMD_READ / _WRITE may become
// the file's read / write subdevice; none has it.
int set_stream_subdevice(comedi_t* it) {
  if (!valid_dev(it))
    return -1;
  return fail(EINVAL);
}

}  // namespace

// libcomedi 0.7.18's comedi_get_cmd_generic_timed: one channel, the period in ns.
extern "C" int piezoshift_comedi_get_cmd_generic_timed_v0_7_18(comedi_t* it, unsigned int subd,
                                                               comedi_cmd* cmd, unsigned int ns);
__asm__(
    ".symver piezoshift_comedi_get_cmd_generic_timed_v0_7_18,"
    "comedi_get_cmd_generic_timed@v0.7.18");
// Not in comedilib.h: the buffer's write count (the older name of comedi_get_buffer_write_count).
extern "C" int comedi_get_front_count(comedi_t* it, unsigned int subdev);

extern "C" {

int comedi_command(comedi_t* it, comedi_cmd* cmd) {
  return refuse_command(it, cmd);
}

int comedi_command_test(comedi_t* it, comedi_cmd* cmd) {
  return refuse_command(it, cmd);
}

int comedi_get_cmd_src_mask(comedi_t* it, unsigned int subd, comedi_cmd* cmd) {
  if (!valid_subd(it, subd))
    return -1;
  comedi_cmd mask{};  // every source allowed: the driver's test narrows them to what it takes
  mask.subdev = subd;
  mask.start_src = mask.scan_begin_src = mask.convert_src = TRIG_ANY;
  mask.scan_end_src = mask.stop_src = TRIG_ANY;
  if (comedi_command_test(it, &mask) < 0)
    return -1;
  if (cmd != nullptr)
    *cmd = mask;
  return 0;
}

int comedi_get_cmd_generic_timed(comedi_t* it, unsigned int subd, comedi_cmd* cmd,
                                 unsigned chanlist_len, unsigned scan_period_ns) {
  (void)scan_period_ns;
  if (!valid_subd(it, subd))
    return -1;
  if (chanlist_len < 1)
    return -EINVAL;  // libcomedi returns -EINVAL itself here, not -1
  comedi_cmd mask{};
  return comedi_get_cmd_src_mask(it, subd, cmd != nullptr ? cmd : &mask);
}

int piezoshift_comedi_get_cmd_generic_timed_v0_7_18(comedi_t* it, unsigned int subd,
                                                    comedi_cmd* cmd, unsigned int ns) {
  return comedi_get_cmd_generic_timed(it, subd, cmd, 1, ns);
}

int comedi_cancel(comedi_t* it, unsigned int subd) {
  (void)subd;
  if (!valid_dev(it))
    return -1;
  return fail(EINVAL);  // beyond the device, or a subdevice without commands
}

int comedi_poll(comedi_t* it, unsigned int subd) {
  if (!valid_dev(it))
    return -1;
  if (subd >= it->board->model().subdevices.size())
    return fail(EINVAL);
  return 0;  // no command running: nothing to bring into the buffer
}

int comedi_fileno(comedi_t* it) {
  return valid_dev(it) ? it->fd : -1;
}

int comedi_get_read_subdevice(comedi_t* it) {
  valid_dev(it);
  return -1;  // none: no subdevice takes input commands
}

int comedi_get_write_subdevice(comedi_t* it) {
  valid_dev(it);
  return -1;  // none: no subdevice takes output commands
}

int comedi_set_read_subdevice(comedi_t* it, unsigned int subd) {
  (void)subd;
  return set_stream_subdevice(it);
}

int comedi_set_write_subdevice(comedi_t* it, unsigned int subd) {
  (void)subd;
  return set_stream_subdevice(it);
}

int comedi_lock(comedi_t* it, unsigned int subd) {
  if (!valid_dev(it))
    return -1;
  if (subd >= it->locked.size())
    return fail(EINVAL);
  if (it->locked[subd])
    return fail(EBUSY);  // COMEDI_LOCK: already locked, even by this file
  it->locked[subd] = true;
  return 0;
}

int comedi_unlock(comedi_t* it, unsigned int subd) {
  if (!valid_dev(it))
    return -1;
  if (subd >= it->locked.size())
    return fail(EINVAL);
  it->locked[subd] = false;
  return 0;
}

int comedi_get_buffer_size(comedi_t* it, unsigned int subd) {
  return buffer_config(it, subd);
}

int comedi_get_max_buffer_size(comedi_t* it, unsigned int subd) {
  return buffer_config(it, subd);
}

int comedi_set_buffer_size(comedi_t* it, unsigned int subd, unsigned int len) {
  (void)len;
  return buffer_config(it, subd);
}

int comedi_set_max_buffer_size(comedi_t* it, unsigned int subd, unsigned int max_size) {
  (void)max_size;
  return buffer_config(it, subd);
}

int comedi_get_buffer_contents(comedi_t* it, unsigned int subd) {
  return buffer_info(it, subd);
}

int comedi_mark_buffer_read(comedi_t* it, unsigned int subd, unsigned int bytes) {
  (void)bytes;
  return buffer_info(it, subd);
}

int comedi_mark_buffer_written(comedi_t* it, unsigned int subd, unsigned int bytes) {
  (void)bytes;
  return buffer_info(it, subd);
}

int comedi_get_buffer_read_offset(comedi_t* it, unsigned int subd) {
  return buffer_info(it, subd);
}

int comedi_get_buffer_write_offset(comedi_t* it, unsigned int subd) {
  return buffer_info(it, subd);
}

int comedi_get_buffer_offset(comedi_t* it, unsigned int subd) {
  return buffer_info(it, subd);
}

int comedi_get_front_count(comedi_t* it, unsigned int subd) {
  return buffer_info(it, subd);
}

int comedi_get_buffer_read_count(comedi_t* it, unsigned int subd, unsigned int* read_count) {
  if (read_count != nullptr)
    *read_count = 0;
  return buffer_info(it, subd);
}

int comedi_get_buffer_write_count(comedi_t* it, unsigned int subd, unsigned int* write_count) {
  if (write_count != nullptr)
    *write_count = 0;
  return buffer_info(it, subd);
}

int comedi_internal_trigger(comedi_t* dev, unsigned subd, unsigned trignum) {
  if (!valid_dev(dev))
    return -1;
  lsampl_t data = trignum;
  comedi_insn insn{};
  insn.insn = INSN_INTTRIG;
  insn.subdev = subd;
  insn.n = 1;
  insn.data = &data;
  return do_insn(dev, insn) < 0 ? -1 : 0;
}

int comedi_trigger(comedi_t* it, comedi_trig* trig) {
  if (!valid_dev(it) || trig == nullptr)
    return -1;
  return fail(ENOTTY);  // the kernel has no COMEDI_TRIG ioctl any more
}

int comedi_get_timer(comedi_t* it, unsigned int subd, double freq, unsigned int* trigvar,
                     double* actual_freq) {
  // Every subdevice's timer is in nanoseconds (COMEDI_SUBDINFO's TIMER_nanosec).
  if (!valid_subd(it, subd) || trigvar == nullptr || actual_freq == nullptr)
    return -1;
  *trigvar = static_cast<unsigned>(1e9 / freq);
  *actual_freq = 1e9 / *trigvar;
  return 0;
}

int comedi_timed_1chan(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int range,
                       unsigned int aref, double freq, unsigned int n_samples, double* data) {
  (void)range, (void)aref, (void)freq, (void)n_samples;
  if (!valid_chan(it, subd, chan) || data == nullptr)
    return -1;
  // libcomedi starts it with COMEDI_TRIG (refused) and reads the device, which fails with EIO
  // where no subdevice streams.
  errno = EIO;
  return -1;
}

int comedi_sv_init(comedi_sv_t* sv, comedi_t* dev, unsigned int subd, unsigned int chan) {
  if (!valid_chan(dev, subd, chan) || sv == nullptr)
    return -1;
  *sv = comedi_sv_t{};
  sv->dev = dev;
  sv->subdevice = subd;
  sv->chan = chan;
  sv->n = 100;
  return comedi_sv_update(sv);
}

int comedi_sv_update(comedi_sv_t* sv) {
  if (sv == nullptr || !valid_chan(sv->dev, sv->subdevice, sv->chan))
    return -1;
  sv->maxdata = model_of(sv->dev, sv->subdevice).maxdata;
  return 0;
}

int comedi_sv_measure(comedi_sv_t* sv, double* data) {
  (void)data;
  if (sv == nullptr || !valid_subd(sv->dev, sv->subdevice))
    return -1;
  return fail(ENOTTY);  // libcomedi measures through COMEDI_TRIG, which the kernel lacks
}

}  // extern "C"
