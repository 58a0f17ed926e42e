#pragma once
// Writing logs and results as CSV that CsvTable reads back: a header of column names (with the
// unit in each name, e.g. time_s, z1_um), optional '#' comment lines, then rows of numbers in
// fixed-point notation with a set number of decimals.
//
//   io::CsvWriter log("run.csv", {"time_s", "z_um"}, 6);
//   log.comment("seed 42");
//   log.row({0.001, 1.234567});
//   log.flush();   // e.g. once per second of a long run, so a crash loses little
//
// A log is streamed (kStream): rows reach the file as written, flush() bounds what a crash loses.
// A record another command reads whole is replaced atomically (kReplaceAtomically): rows are
// kept in memory and close() writes them through io::write_file_atomically (atomic_file.hpp), so
// the file holds its old content or every row, never a part; without close() (an exception on
// the way) the file is left as it was.
//
// Not real-time safe (it formats and writes to a file); a real-time loop hands samples to a
// non-real-time thread that writes them. Non-finite values are written as "nan"/"inf" so a log
// shows them; CsvTable then refuses them with a message naming the line.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace piezoshift::io {

class CsvWriter {
 public:
  enum class Mode : std::uint8_t { kStream, kReplaceAtomically };

  //! kStream: creates (truncates) the file and writes the header; a file that cannot be created
  //! throws InputError naming it. kReplaceAtomically: nothing is written before close().
  //! decimals: digits after the point for every value (0..17).
  CsvWriter(const std::string& path, std::vector<std::string> columns, int decimals = 6,
            Mode mode = Mode::kStream);
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  ~CsvWriter();

  //! One data row; its size must equal the number of columns (std::invalid_argument otherwise).
  void row(std::span<const double> values);
  void row(std::initializer_list<double> values) {
    row(std::span<const double>(values.begin(), values.size()));
  }
  //! A '#' comment line (line breaks in text become spaces).
  void comment(const std::string& text);
  //! kStream: to the file; kReplaceAtomically: nothing (the rows are written by close()).
  void flush();
  //! Flushes and closes (kReplaceAtomically: replaces the file with every row); throws
  //! InputError if any write failed (disk full, ...).
  void close();

  std::size_t rows_written() const { return rows_; }
  const std::string& path() const { return path_; }

 private:
  void check_write(bool ok);
  void put(const std::string& text);
  std::string path_;
  std::size_t columns_;
  int decimals_;
  std::FILE* file_ = nullptr;
  std::size_t rows_ = 0;
  std::string buffer_;
  bool atomic_ = false;
  bool open_ = true;
  std::string contents_;  //!< kReplaceAtomically: the file until close()
};

}  // namespace piezoshift::io
