#pragma once
// The recorded test vector the firmware replays, and the record it writes back per tick. Shared by
// the host tool that records the vector (firmware/tools/make_test_vector.cpp), the firmware that
// replays it (firmware/src/main.cpp) and the host test that compares (tests/mcu/). docs/mcu.md.
//
// Vector (one binary blob, little-endian, linked into the firmware's flash as it is):
//   VectorHeader
//   SetpointSegment[segments]       Z_d per point, piecewise constant from start_tick on
//   int16 ai_code[ticks][3]         the SGS inputs as the 16-bit DAQ's ADC codes
// A tick k's inputs: Z_d of the last segment with start_tick <= k, sgs_V_i = ai_code[k][i] *
// ai_lsb_V. Set-points are floats and the LSB is 20 V / 2^16 = 5 * 2^-14 V, so both controllers
// (float firmware, double host) receive exactly the same input values.
//
// Firmware output (a binary file written through semihosting):
//   TickRecord[ticks]               every tick's outputs, as the float controller computed them
//   RunStats                        code timing, counted under QEMU -icount
//
// Freestanding: fixed-size types only, usable on the target and the host.
#include <cstddef>
#include <cstdint>

namespace piezoshift::firmware {

inline constexpr std::uint32_t kVectorMagic = 0x56535a50;  // "PZSV"
inline constexpr std::uint32_t kStatsMagic = 0x54535a50;   // "PZST"
inline constexpr std::uint32_t kFormatVersion = 1;

struct VectorHeader {
  std::uint32_t magic = kVectorMagic;
  std::uint32_t version = kFormatVersion;
  std::uint32_t ticks = 0;     //!< number of control ticks
  std::uint32_t segments = 0;  //!< number of SetpointSegment entries
  float ai_lsb_V = 0.0F;       //!< V per ADC code (exact in float: 5 * 2^-14)
  float sample_time_s = 0.0F;  //!< the period the vector was recorded at
  std::uint32_t seed = 0;      //!< the twin's seed
  std::uint32_t reserved = 0;
};

struct SetpointSegment {
  std::uint32_t start_tick = 0;
  float zd_um[3] = {0.0F, 0.0F, 0.0F};  //!< desired displacements of P1..P3
};

struct TickRecord {
  float dac_V[3] = {0.0F, 0.0F, 0.0F};
  float command_um[3] = {0.0F, 0.0F, 0.0F};
  std::uint32_t saturated_mask = 0;
};

//! Timer counts are SysTick counts; under `qemu -icount shift=0` the virtual clock advances 1 ns
//! per instruction, so counts / counts_per_instruction = instructions.
struct RunStats {
  std::uint32_t magic = kStatsMagic;
  std::uint32_t ticks = 0;
  std::uint64_t calibration_instructions = 0;  //!< a loop of known length, timed
  std::uint64_t calibration_counts = 0;
  std::uint64_t update_counts = 0;      //!< sum over ticks of the timed controller update
  std::uint64_t empty_counts = 0;       //!< the same timing around nothing, over as many ticks
  std::uint32_t update_counts_max = 0;  //!< the longest single update
  std::uint32_t update_counts_min = 0;  //!< the shortest single update
  std::uint32_t empty_counts_max = 0;
  std::uint32_t empty_counts_min = 0;
};

static_assert(sizeof(VectorHeader) == 32 && sizeof(SetpointSegment) == 16);
static_assert(sizeof(TickRecord) == 28 && sizeof(RunStats) == 56);
static_assert(offsetof(RunStats, update_counts_max) == 40);

//! Byte offsets of the parts of a vector blob.
constexpr std::size_t segments_offset() noexcept {
  return sizeof(VectorHeader);
}
constexpr std::size_t codes_offset(const VectorHeader& h) noexcept {
  return sizeof(VectorHeader) + h.segments * sizeof(SetpointSegment);
}
constexpr std::size_t vector_size(const VectorHeader& h) noexcept {
  return codes_offset(h) + std::size_t{h.ticks} * 3 * sizeof(std::int16_t);
}

}  // namespace piezoshift::firmware
