#pragma once
// What the emulated board is and what is on its wires: a TOML file named by the environment
// variable PIEZOSHIFT_COMEDI_EMULATION (absent: every default below). docs/runtime.md,
// "Testing without a board", lists the keys with an example.
#include <cstdint>
#include <string>

namespace piezoshift::emulation {

struct EmulationSettings {
  // [board]
  std::string device = "/dev/comedi0";  //!< the one path comedi_open() accepts
  std::string model = "pci-6229";       //!< or "pci-6220" (no analog output)
  //! comedi_soft_calibrate was run: the calibration file exists (M Series boards need it).
  bool calibrated = true;
  //! The AO's reference: 10 V internal gives +-10 V; a board wired to a smaller external
  //! reference (NI M Series allow one) has only +-ao_reference_V, a range the amplifiers' 0..10 V
  //! does not fit in.
  double ao_reference_V = 10.0;
  // [twin]: the plant on AO 0..2 (amplifiers) and AI 0..2 (gauge conditioners)
  std::string config;  //!< piezoshift configuration (the twin's sections); empty: built in
  std::int64_t seed = 1;
  //! "wall": the twin follows the monotonic clock from the first transaction, in steps of
  //! step_s (a real board's plant does not wait for the host); "transaction": every
  //! transaction advances it by exactly step_s (deterministic, for comparisons with --daq sim).
  std::string clock = "wall";
  double step_s = 1e-4;
  // [faults]: seconds after the first transaction; negative: never. Each lasts to the end.
  double ai_timeout_at_s = -1.0;  //!< AI conversions time out (ETIME, as ni_mio_common's)
  double ao_busy_at_s = -1.0;     //!< AO instructions refused (EBUSY: an AO command runs)
  double io_error_at_s = -1.0;    //!< one transaction fails (EIO, a bus error), then none
  double ai_open_at_s = -1.0;     //!< AI channel ai_open_channel reads maxdata (open input)
  std::int64_t ai_open_channel = 0;
  // [record]
  std::string record;  //!< json: JSON written when the device is closed (final state, counts)
  std::string series;  //!< csv: CSV of t_s, ao_V, truth and interferometer every series_period_s
  double series_period_s = 0.01;  //!< csv_period_s

  // [interferometer]: an XL-80-like single-beam log per place the optics can be (P1.csv, P2.csv,
  // P3.csv, centre.csv: t_s in Unix time, displacement_um, the twin's dynamic interferometer)
  // written live every log_period_s, for `calibrate --interferometer file:` (an operator moving
  // the optics is a link pointing at one of them). Empty: none.
  std::string log_folder;
  double log_period_s = 0.01;

  std::string source = "the built-in defaults";  //!< the file, for messages
};

//! The settings of the file `path` (nullptr or empty: the defaults). Throws core::InputError
//! naming the file and key.
EmulationSettings load_emulation_settings(const char* path);

}  // namespace piezoshift::emulation
