#pragma once
// The wave tables of `piezoshift serve` as GCS WAV defines them (docs/gcs.md): kTables tables of
// up to kPoints values each, in the unit of the axis a generator plays them into (um or urad).
//
//   WAV t X|&|+ PNT   start n v1 .. vn           n points; start is 1-based: 1 with X; with &
//                                                1 or the table's length + 1, both the end
//                                                (PIPython's writewavepoints sends either, by
//                                                release); + adds from `start`
//   WAV t X|&|+ LIN   seg amp off len start sud  a segment of seg points: off before `start`
//                                                (0-based), a line to off+amp over len points,
//                                                off+amp after; sud speed-up/down points at each
//                                                end blend it with a parabola (constant
//                                                acceleration), so the slope in the middle is
//                                                amp / (len - sud)
//   WAV t X|&|+ SIN_P seg amp off len start ccp  a segment of seg points of the inverted cosine
//                                                  i < ccp: off + amp (1 - cos(pi i / ccp)) / 2
//                                                  else:    off + amp (1 + cos(pi
//                                                  (i-ccp)/(len-ccp)))/2
//                                                with i = (j - start) mod len for point j
//   X clears the table first, & appends the segment, + adds it point by point (a longer segment
//   extends the table). A table never holds more than kPoints (error 403 otherwise, PI's
//   "wave length exceeds limit").
// Not real-time code (the host's storage); the loop plays copies (runtime/wave_generator.hpp).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/host/gcs_error.hpp"

namespace piezoshift::host {

class WaveTables {
 public:
  static constexpr int kTables = 8;
  static constexpr std::size_t kPoints = 8192;

  //! WAV's arguments after the table id ("X PNT 1 3 0 1 2"). kNone on success; on failure the
  //! table is unchanged.
  GcsError define(int table, const std::vector<std::string_view>& args);
  //! The table's values (empty when not defined). table in 1..kTables.
  const std::vector<double>& values(int table) const {
    return tables_[static_cast<std::size_t>(table - 1)];
  }
  bool exists(int table) const noexcept { return table >= 1 && table <= kTables; }

 private:
  std::vector<std::vector<double>> tables_ = std::vector<std::vector<double>>(kTables);
};

}  // namespace piezoshift::host
