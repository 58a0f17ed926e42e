#include "piezoshift/io/csv_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/input_file.hpp"

namespace piezoshift::io {
namespace {

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos)
    return {};
  const auto last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

std::vector<std::string> split_fields(std::string_view line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    out.emplace_back(
        trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
    if (comma == std::string_view::npos)
      break;
    start = comma + 1;
  }
  return out;
}

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) {
    if (!s.empty())
      s += ',';
    s += n;
  }
  return s;
}

// Shortens a cell for a message so a binary file does not flood the terminal.
std::string shown(std::string_view cell) {
  constexpr std::size_t kMax = 40;
  return cell.size() <= kMax ? std::string(cell) : std::string(cell.substr(0, kMax)) + "...";
}

}  // namespace

bool parse_finite_double(std::string_view cell, double& value) {
  cell = trim(cell);
  // from_chars takes no leading '+'; accept one in front of a digit or point.
  if (cell.size() > 1 && cell.front() == '+' && cell[1] != '-' && cell[1] != '+')
    cell.remove_prefix(1);
  if (cell.empty())
    return false;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec != std::errc() || end != cell.data() + cell.size() || !std::isfinite(v))
    return false;
  value = v;
  return true;
}

CsvTable CsvTable::load(const std::string& path) {
  return from_text(read_input_file(path, kMaxDataFileBytes), path);
}

CsvTable CsvTable::parse(std::string_view text, const std::string& source_name) {
  return from_text(std::string(text), source_name);
}

void CsvTable::read_header(std::string_view line, std::size_t line_no) {
  // Counted before it is split, so a line of millions of commas costs no memory.
  const auto fields = static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1;
  if (fields > kMaxColumns) {
    throw core::InputError(fmt::format("{}:{}: the header has {} fields, more than the limit of {}",
                                       source_, line_no, fields, kMaxColumns));
  }
  header_ = split_fields(line);
  for (std::size_t i = 0; i < header_.size(); ++i) {
    std::string& name = header_[i];
    if (name.size() >= 2 && name.front() == '"' && name.back() == '"')
      name = std::string(trim(std::string_view(name).substr(1, name.size() - 2)));
    if (name.empty()) {
      throw core::InputError(
          fmt::format("{}:{}: header field {} is empty (a trailing comma?); the header names the "
                      "columns, e.g. s1_um,s2_um,s3_um",
                      source_, line_no, i + 1));
    }
  }
  header_line_ = line_no;
}

CsvTable CsvTable::from_text(std::string text, const std::string& source_name) {
  CsvTable t;
  t.source_ = source_name;
  t.text_ = std::move(text);
  const std::string_view all = t.text_;
  if (all.size() >= std::numeric_limits<std::uint32_t>::max())
    throw core::InputError(
        fmt::format("{}: {} bytes; a table is read from less than 4 GiB", source_name, all.size()));
  // One row a line at most: reserved once, so the rows never take twice their size while read.
  t.rows_.reserve(static_cast<std::size_t>(std::count(all.begin(), all.end(), '\n')) + 1);
  std::size_t pos = all.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  std::size_t line_no = 0;
  while (pos < all.size()) {
    const std::size_t begin = pos;
    const auto nl = all.find('\n', pos);
    std::string_view line = all.substr(pos, nl == std::string_view::npos ? all.npos : nl - pos);
    pos = (nl == std::string_view::npos) ? all.size() : nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);
    const std::string_view content = trim(line);
    if (content.empty() || content.front() == '#')
      continue;
    if (t.header_.empty()) {
      t.read_header(line, line_no);
      continue;
    }
    // Counted, not split: the cells are found again by column().
    const auto fields = static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1;
    if (fields != t.header_.size()) {
      throw core::InputError(fmt::format("{}:{}: {} fields, but the header (line {}) has {}",
                                         source_name, line_no, fields, t.header_line_,
                                         t.header_.size()));
    }
    t.rows_.push_back(Row{static_cast<std::uint32_t>(begin), static_cast<std::uint32_t>(line_no)});
  }
  if (t.header_.empty()) {
    throw core::InputError(
        fmt::format("{}: no header row: the file is empty or has only comments", source_name));
  }
  return t;
}

std::string_view CsvTable::cell(std::size_t row, std::size_t field) const {
  const std::string_view all = text_;
  std::size_t begin = rows_[row].offset;
  for (std::size_t f = 0; f < field; ++f)
    begin = all.find(',', begin) + 1;
  const std::size_t end = all.find_first_of(",\n", begin);
  std::string_view c = all.substr(begin, end == std::string_view::npos ? all.npos : end - begin);
  // The last field of a "\r\n" line (an '\r' elsewhere stays and makes the cell no number).
  if ((end == std::string_view::npos || all[end] == '\n') && !c.empty() && c.back() == '\r')
    c.remove_suffix(1);
  return trim(c);
}

bool CsvTable::has_column(std::string_view name) const {
  for (const auto& h : header_) {
    if (h == name)
      return true;
  }
  return false;
}

void CsvTable::require_columns(std::initializer_list<std::string_view> names) const {
  std::string missing;
  std::size_t count = 0;
  for (const auto name : names) {
    if (!has_column(name)) {
      missing += (missing.empty() ? "'" : ", '") + std::string(name) + "'";
      ++count;
    }
  }
  if (count > 0) {
    throw core::InputError(fmt::format("{}:{}: missing column{} {} (the header has: {})", source_,
                                       header_line_, count > 1 ? "s" : "", missing, join(header_)));
  }
}

std::size_t CsvTable::index_of(std::string_view name) const {
  std::size_t found = header_.size();
  for (std::size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] != name)
      continue;
    if (found != header_.size()) {
      throw core::InputError(fmt::format("{}:{}: column '{}' appears twice (fields {} and {})",
                                         source_, header_line_, name, found + 1, i + 1));
    }
    found = i;
  }
  if (found == header_.size()) {
    throw core::InputError(fmt::format("{}:{}: missing column '{}' (the header has: {})", source_,
                                       header_line_, name, join(header_)));
  }
  return found;
}

std::vector<double> CsvTable::column(std::string_view name) const {
  const std::size_t c = index_of(name);
  std::vector<double> values(rows_.size());
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const std::string_view cell = this->cell(r, c);
    if (parse_finite_double(cell, values[r]))
      continue;
    double any = 0.0;
    const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), any);
    const bool non_finite = ec == std::errc() && end == cell.data() + cell.size();
    throw core::InputError(
        fmt::format("{}:{}: column '{}' (field {}): {}", source_, rows_[r].line, name, c + 1,
                    cell.empty() ? std::string("empty cell, expected a number")
                    : non_finite ? fmt::format("'{}' is not a finite number", shown(cell))
                                 : fmt::format("'{}' is not a number", shown(cell))));
  }
  return values;
}

}  // namespace piezoshift::io
