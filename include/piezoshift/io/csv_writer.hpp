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
// Not real-time safe (it formats and writes to a file); a real-time loop hands samples to a
// non-real-time thread that writes them. Non-finite values are written as "nan"/"inf" so a log
// shows them; CsvTable then refuses them with a message naming the line.
#include <cstddef>
#include <cstdio>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace piezoshift::io {

class CsvWriter {
 public:
  //! Creates (truncates) the file and writes the header. A file that cannot be created throws
  //! InputError naming it. decimals: digits after the point for every value (0..17).
  CsvWriter(const std::string& path, std::vector<std::string> columns, int decimals = 6);
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
  void flush();
  //! Flushes and closes; throws InputError if any write failed (disk full, ...).
  void close();

  std::size_t rows_written() const { return rows_; }
  const std::string& path() const { return path_; }

 private:
  void check_write(bool ok);
  std::string path_;
  std::size_t columns_;
  int decimals_;
  std::FILE* file_ = nullptr;
  std::size_t rows_ = 0;
  std::string buffer_;
};

}  // namespace piezoshift::io
