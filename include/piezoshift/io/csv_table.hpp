#pragma once
// Reading recorded data from CSV files: a header row of column names, then one row per sample.
//
//   io::CsvTable t = io::CsvTable::load("poses.csv");
//   std::vector<double> z2 = t.column("z2_um");   // by name: order free, extra columns ignored
//
// Format (what the bench and the twin write; see docs/calibration.md):
//   - fields separated by ',', no quoting; spaces and tabs around a field are ignored;
//   - the first line that is neither blank nor a comment is the header; a header name may be
//     written in double quotes ("z2_um"), which are dropped;
//   - a line whose first non-blank character is '#' is a comment; blank lines are skipped, so
//     blank trailing lines are fine; '\r\n' line ends and a UTF-8 byte order mark are accepted;
//   - every data row has as many fields as the header, and the header at most kMaxColumns;
//   - a cell read through column() must be, as a whole, a finite number in the grammar of
//     std::from_chars (decimal or scientific, optional leading '+' or '-'); "nan", "inf",
//     "1.5um", "" and "1,5" are rejected rather than guessed at.
// Every violation throws core::InputError naming the file, the line (1-based, counting every
// physical line) and, for a cell, the column, e.g.
//   poses.csv:7: column 'z2_um' (field 5): 'abc' is not a number
// Memory: the text and 8 bytes a data row, however many cells a row has (a row is counted, not
// split, when read; column() finds its cells again), the rows reserved once from the text's line
// count (no doubling while they are read), so at most 5 times the text's size (a row takes at
// least 2 bytes): 320 MiB for the 64 MiB limit of a data file, which column() adds 8 bytes a row
// to (`analyze linearity` on 64 MiB of "1,1" rows: 600 MB peak before, 469 MB now). A row
// with more or fewer fields than the header is
// refused when read; a text of 4 GiB or more is refused (rows hold 32-bit offsets).
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace piezoshift::io {

class CsvTable {
 public:
  //! The widest header accepted (the widest file piezoshift writes has well under 100 columns).
  static constexpr std::size_t kMaxColumns = 1024;

  //! Reads a file; a file that cannot be opened throws InputError naming it and the reason.
  static CsvTable load(const std::string& path);
  //! Parses text; source_name stands in for the file name in messages (tests, pipes).
  static CsvTable parse(std::string_view text, const std::string& source_name);

  const std::string& source() const { return source_; }
  const std::vector<std::string>& header() const { return header_; }
  //! Number of data rows (comments and blank lines excluded).
  std::size_t rows() const { return rows_.size(); }
  //! Physical line number (1-based) of data row `row`, for messages about a row.
  std::size_t line_of_row(std::size_t row) const { return rows_.at(row).line; }

  bool has_column(std::string_view name) const;
  //! Throws one InputError listing every name that is not in the header (and the header).
  void require_columns(std::initializer_list<std::string_view> names) const;
  //! The named column parsed strictly, one value per data row. Throws InputError for a missing
  //! or ambiguous (repeated) name and for the first cell that is not a finite number.
  std::vector<double> column(std::string_view name) const;

 private:
  struct Row {
    std::uint32_t offset;  // of the row's first byte in text_
    std::uint32_t line;    // physical line, 1-based
  };
  CsvTable() = default;
  static CsvTable from_text(std::string text, const std::string& source_name);
  void read_header(std::string_view line, std::size_t line_no);
  std::size_t index_of(std::string_view name) const;
  //! Field `field` (0-based, trimmed) of data row `row`; the row has header_.size() fields.
  std::string_view cell(std::size_t row, std::size_t field) const;

  std::string source_;
  std::string text_;  // the whole input; rows_ point into it
  std::vector<std::string> header_;
  std::size_t header_line_ = 0;
  std::vector<Row> rows_;
};

//! Parses one cell as a finite double, the whole cell (after trimming blanks) and nothing else.
//! Returns false for anything else; the caller words the message.
bool parse_finite_double(std::string_view cell, double& value);

}  // namespace piezoshift::io
