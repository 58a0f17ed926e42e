// libcomedi's digital I/O functions, its wrappers of configuration instructions (INSN_CONFIG:
// counters, clocks, gates, routing, filters, triggers, resets) and its conversions between raw
// codes and physical values through a range (comedilib.h). The wrappers send the instruction
// libcomedi sends (insn_config_wrappers in Comedilib's manual); the board answers it as
// emulated_board.hpp says: the DIO subdevice's direction configuration works, everything else
// the emulation does not model fails with EINVAL.
#include <comedilib.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <initializer_list>

#include "api_handle.hpp"

namespace {

using namespace piezoshift::emulation::api;

std::atomic<int> oor_is_nan{COMEDI_OOR_NUMBER};  // comedi_set_global_oor_behavior

bool is_digital(comedi_t* it, unsigned subd, bool input, bool output) {
  const int type = model_of(it, subd).type;
  if (type == COMEDI_SUBD_DIO || (input && type == COMEDI_SUBD_DI) ||
      (output && type == COMEDI_SUBD_DO))
    return true;
  fail_internal(EINVAL_SUBD);
  return false;
}

// One configuration instruction of up to 6 words on a subdevice's channel: 0, or -1.
int configure(comedi_t* it, unsigned subd, unsigned chanspec, std::initializer_list<lsampl_t> words,
              lsampl_t* out = nullptr) {
  lsampl_t data[6] = {};
  unsigned n = 0;
  for (lsampl_t w : words)
    data[n++] = w;
  const int r = config(it, subd, chanspec, data, n);
  if (r == 0 && out != nullptr)
    std::copy(data, data + n, out);
  return r;
}

int digital_trigger(comedi_t* it, unsigned subd, unsigned id, unsigned op, unsigned a, unsigned b,
                    unsigned c) {
  return configure(it, subd, 0, {INSN_CONFIG_DIGITAL_TRIG, id, op, a, b, c});
}

}  // namespace

// The 0.9.0 versions of the clock source's functions, for channel 0.
extern "C" int piezoshift_comedi_get_clock_source_v0_9_0(comedi_t* device, unsigned subdevice,
                                                         unsigned* clock, unsigned* period_ns);
extern "C" int piezoshift_comedi_set_clock_source_v0_9_0(comedi_t* device, unsigned subdevice,
                                                         unsigned clock, unsigned period_ns);
__asm__(".symver piezoshift_comedi_get_clock_source_v0_9_0,comedi_get_clock_source@v0.9.0");
__asm__(".symver piezoshift_comedi_set_clock_source_v0_9_0,comedi_set_clock_source@v0.9.0");

extern "C" {

int comedi_dio_config(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int dir) {
  if (!valid_chan(it, subd, chan))
    return -1;
  if (!is_digital(it, subd, false, false))
    return -1;
  if (dir != COMEDI_INPUT && dir != COMEDI_OUTPUT)
    return fail_internal(EINVAL);
  return configure(it, subd, CR_PACK(chan, 0, 0),
                   {dir == COMEDI_OUTPUT ? INSN_CONFIG_DIO_OUTPUT : INSN_CONFIG_DIO_INPUT});
}

int comedi_dio_get_config(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int* dir) {
  if (!valid_chan(it, subd, chan))
    return -1;
  if (!is_digital(it, subd, false, false))
    return -1;
  lsampl_t data[2] = {};
  if (configure(it, subd, CR_PACK(chan, 0, 0), {INSN_CONFIG_DIO_QUERY, 0}, data) < 0)
    return -1;
  if (dir != nullptr)
    *dir = data[1];
  return 0;
}

int comedi_dio_read(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int* bit) {
  if (!valid_chan(it, subd, chan))
    return -1;
  if (!is_digital(it, subd, true, true))
    return -1;
  lsampl_t v = 0;
  comedi_insn insn{};
  insn.insn = INSN_READ;
  insn.n = 1;
  insn.data = &v;
  insn.subdev = subd;
  insn.chanspec = CR_PACK(chan, 0, 0);
  const int r = do_insn(it, insn);
  if (bit != nullptr)
    *bit = v;
  return r;
}

int comedi_dio_write(comedi_t* it, unsigned int subd, unsigned int chan, unsigned int bit) {
  if (!valid_chan(it, subd, chan))
    return -1;
  if (!is_digital(it, subd, false, true))
    return -1;
  lsampl_t v = bit;
  comedi_insn insn{};
  insn.insn = INSN_WRITE;
  insn.n = 1;
  insn.data = &v;
  insn.subdev = subd;
  insn.chanspec = CR_PACK(chan, 0, 0);
  return do_insn(it, insn);
}

int comedi_dio_bitfield2(comedi_t* it, unsigned int subd, unsigned int write_mask,
                         unsigned int* bits, unsigned int base_channel) {
  if (!valid_subd(it, subd))
    return -1;
  if (!is_digital(it, subd, true, true))
    return -1;
  if (bits == nullptr)
    return fail(EFAULT);
  lsampl_t data[2] = {write_mask, *bits};
  comedi_insn insn{};
  insn.insn = INSN_BITS;
  insn.n = 2;
  insn.data = data;
  insn.subdev = subd;
  insn.chanspec = base_channel;
  if (do_insn(it, insn) < 0)
    return -1;
  *bits = data[1];
  return 0;
}

int comedi_dio_bitfield(comedi_t* it, unsigned int subd, unsigned int write_mask,
                        unsigned int* bits) {
  return comedi_dio_bitfield2(it, subd, write_mask, bits, 0);
}

int comedi_reset_channel(comedi_t* device, unsigned subdevice, unsigned channel) {
  return configure(device, subdevice, channel, {INSN_CONFIG_RESET});
}

int comedi_reset(comedi_t* device, unsigned subdevice) {
  return comedi_reset_channel(device, subdevice, 0);
}

int comedi_arm_channel(comedi_t* device, unsigned subdevice, unsigned channel, unsigned target) {
  return configure(device, subdevice, channel, {INSN_CONFIG_ARM, target});
}

int comedi_arm(comedi_t* device, unsigned subdevice, unsigned target) {
  return comedi_arm_channel(device, subdevice, 0, target);
}

int comedi_disarm_channel(comedi_t* device, unsigned subdevice, unsigned channel) {
  return configure(device, subdevice, channel, {INSN_CONFIG_DISARM});
}

int comedi_disarm(comedi_t* device, unsigned subdevice) {
  return comedi_disarm_channel(device, subdevice, 0);
}

int comedi_get_clock_source(comedi_t* device, unsigned subdevice, unsigned channel, unsigned* clock,
                            unsigned* period_ns) {
  lsampl_t data[3] = {};
  if (configure(device, subdevice, channel, {INSN_CONFIG_GET_CLOCK_SRC, 0, 0}, data) < 0)
    return -1;
  if (clock != nullptr)
    *clock = data[1];
  if (period_ns != nullptr)
    *period_ns = data[2];
  return 0;
}

int piezoshift_comedi_get_clock_source_v0_9_0(comedi_t* device, unsigned subdevice, unsigned* clock,
                                              unsigned* period_ns) {
  return comedi_get_clock_source(device, subdevice, 0, clock, period_ns);
}

int comedi_set_clock_source(comedi_t* device, unsigned subdevice, unsigned channel, unsigned clock,
                            unsigned period_ns) {
  return configure(device, subdevice, channel, {INSN_CONFIG_SET_CLOCK_SRC, clock, period_ns});
}

int piezoshift_comedi_set_clock_source_v0_9_0(comedi_t* device, unsigned subdevice, unsigned clock,
                                              unsigned period_ns) {
  return comedi_set_clock_source(device, subdevice, 0, clock, period_ns);
}

int comedi_get_gate_source(comedi_t* device, unsigned subdevice, unsigned channel, unsigned gate,
                           unsigned* source) {
  lsampl_t data[3] = {};
  if (configure(device, subdevice, channel, {INSN_CONFIG_GET_GATE_SRC, gate, 0}, data) < 0)
    return -1;
  if (source != nullptr)
    *source = data[2];
  return 0;
}

int comedi_set_gate_source(comedi_t* device, unsigned subdevice, unsigned channel,
                           unsigned gate_index, unsigned gate_source) {
  return configure(device, subdevice, channel, {INSN_CONFIG_SET_GATE_SRC, gate_index, gate_source});
}

int comedi_set_other_source(comedi_t* device, unsigned subdevice, unsigned channel, unsigned other,
                            unsigned source) {
  return configure(device, subdevice, channel, {INSN_CONFIG_SET_OTHER_SRC, other, source});
}

int comedi_get_routing(comedi_t* device, unsigned subdevice, unsigned channel, unsigned* routing) {
  lsampl_t data[2] = {};
  if (configure(device, subdevice, channel, {INSN_CONFIG_GET_ROUTING, 0}, data) < 0)
    return -1;
  if (routing != nullptr)
    *routing = data[1];
  return 0;
}

int comedi_set_routing(comedi_t* device, unsigned subdevice, unsigned channel, unsigned routing) {
  return configure(device, subdevice, channel, {INSN_CONFIG_SET_ROUTING, routing});
}

int comedi_set_counter_mode(comedi_t* device, unsigned subdevice, unsigned channel,
                            unsigned mode_bits) {
  return configure(device, subdevice, channel, {INSN_CONFIG_SET_COUNTER_MODE, mode_bits});
}

int comedi_set_filter(comedi_t* device, unsigned subdevice, unsigned channel, unsigned filter) {
  return configure(device, subdevice, channel, {INSN_CONFIG_FILTER, filter});
}

int comedi_get_hardware_buffer_size(comedi_t* device, unsigned subdevice,
                                    enum comedi_io_direction direction) {
  lsampl_t data[3] = {};
  const auto dir = static_cast<lsampl_t>(direction);
  if (configure(device, subdevice, 0, {INSN_CONFIG_GET_HARDWARE_BUFFER_SIZE, dir, 0}, data) < 0)
    return -1;
  return static_cast<int>(data[2]);
}

int comedi_digital_trigger_disable(comedi_t* device, unsigned subdevice, unsigned trigger_id) {
  return digital_trigger(device, subdevice, trigger_id, COMEDI_DIGITAL_TRIG_DISABLE, 0, 0, 0);
}

int comedi_digital_trigger_enable_edges(comedi_t* device, unsigned subdevice, unsigned trigger_id,
                                        unsigned base_input, unsigned rising_edge_inputs,
                                        unsigned falling_edge_inputs) {
  return digital_trigger(device, subdevice, trigger_id, COMEDI_DIGITAL_TRIG_ENABLE_EDGES,
                         base_input, rising_edge_inputs, falling_edge_inputs);
}

int comedi_digital_trigger_enable_levels(comedi_t* device, unsigned subdevice, unsigned trigger_id,
                                         unsigned base_input, unsigned high_level_inputs,
                                         unsigned low_level_inputs) {
  return digital_trigger(device, subdevice, trigger_id, COMEDI_DIGITAL_TRIG_ENABLE_LEVELS,
                         base_input, high_level_inputs, low_level_inputs);
}

enum comedi_oor_behavior comedi_set_global_oor_behavior(enum comedi_oor_behavior behavior) {
  return static_cast<comedi_oor_behavior>(oor_is_nan.exchange(behavior));
}

double comedi_to_phys(lsampl_t data, comedi_range* rng, lsampl_t maxdata) {
  if (rng == nullptr || maxdata == 0)
    return NAN;
  if (oor_is_nan.load() == COMEDI_OOR_NAN && (data == 0 || data >= maxdata))
    return NAN;  // the code at either end of the range: the value may lie beyond it
  return rng->min + (rng->max - rng->min) * static_cast<double>(data) / maxdata;
}

lsampl_t comedi_from_phys(double data, comedi_range* rng, lsampl_t maxdata) {
  if (rng == nullptr || maxdata == 0)
    return 0;
  const double code = (data - rng->min) / (rng->max - rng->min) * maxdata;
  if (!(code >= 0.0))
    return 0;
  return code > maxdata ? maxdata : static_cast<lsampl_t>(std::floor(code + 0.5));
}

int comedi_sampl_to_phys(double* dest, int dst_stride, sampl_t* src, int src_stride,
                         comedi_range* rng, lsampl_t maxdata, int n) {
  // Strides in bytes; returns how many codes sat at either end of the range.
  if (rng == nullptr || maxdata == 0)
    return -1;
  const bool nan = oor_is_nan.load() == COMEDI_OOR_NAN;
  int oor = 0;
  for (int i = 0; i < n; ++i) {
    const sampl_t code = *reinterpret_cast<const sampl_t*>(
        reinterpret_cast<const char*>(src) + static_cast<std::ptrdiff_t>(i) * src_stride);
    double& out = *reinterpret_cast<double*>(reinterpret_cast<char*>(dest) +
                                             static_cast<std::ptrdiff_t>(i) * dst_stride);
    const bool at_end = code == 0 || code >= maxdata;
    oor += at_end ? 1 : 0;
    out = nan && at_end ? NAN : rng->min + (rng->max - rng->min) * code / maxdata;
  }
  return oor;
}

int comedi_sampl_from_phys(sampl_t* dest, int dst_stride, double* src, int src_stride,
                           comedi_range* rng, lsampl_t maxdata, int n) {
  // Strides in bytes; a value beyond the range gives its end code and counts as out of range.
  if (rng == nullptr || maxdata == 0)
    return -1;
  int oor = 0;
  for (int i = 0; i < n; ++i) {
    const double v = *reinterpret_cast<const double*>(reinterpret_cast<const char*>(src) +
                                                      static_cast<std::ptrdiff_t>(i) * src_stride);
    sampl_t& out = *reinterpret_cast<sampl_t*>(reinterpret_cast<char*>(dest) +
                                               static_cast<std::ptrdiff_t>(i) * dst_stride);
    if (v < rng->min || v > rng->max)
      ++oor;
    out = static_cast<sampl_t>(comedi_from_phys(v, rng, maxdata));
  }
  return oor;
}

}  // extern "C"
