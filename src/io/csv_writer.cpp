#include "piezoshift/io/csv_writer.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"

namespace piezoshift::io {

CsvWriter::CsvWriter(const std::string& path, std::vector<std::string> columns, int decimals,
                     Mode mode)
    : path_(path),
      columns_(columns.size()),
      decimals_(decimals),
      atomic_(mode == Mode::kReplaceAtomically) {
  if (columns.empty())
    throw std::invalid_argument("CsvWriter: no columns");
  if (decimals < 0 || decimals > 17)
    throw std::invalid_argument("CsvWriter: decimals must be in [0, 17]");
  std::string header;
  for (const auto& c : columns) {
    if (c.empty() || c.find_first_of(",\n\r#") != std::string::npos)
      throw std::invalid_argument("CsvWriter: bad column name '" + c + "'");
    header += header.empty() ? c : "," + c;
  }
  header += '\n';
  if (!atomic_) {
    file_ = std::fopen(path.c_str(), "w");
    if (file_ == nullptr)
      throw core::InputError(fmt::format("{}: cannot create: {}", path, std::strerror(errno)));
  }
  put(header);
}

CsvWriter::~CsvWriter() {
  if (file_ != nullptr)
    std::fclose(file_);  // errors are reported by close(); a destructor must not throw
}

void CsvWriter::check_write(bool ok) {
  if (!ok)
    throw core::InputError(fmt::format("{}: write failed: {}", path_, std::strerror(errno)));
}

void CsvWriter::put(const std::string& text) {
  if (atomic_)
    contents_ += text;
  else
    check_write(std::fwrite(text.data(), 1, text.size(), file_) == text.size());
}

void CsvWriter::row(std::span<const double> values) {
  if (values.size() != columns_) {
    throw std::invalid_argument(fmt::format("CsvWriter({}): row of {} values for {} columns", path_,
                                            values.size(), columns_));
  }
  if (!open_)
    throw std::logic_error("CsvWriter: row() after close()");
  buffer_.clear();
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0)
      buffer_ += ',';
    const double v = values[i];
    if (std::isfinite(v)) {
      buffer_ += fmt::format("{:.{}f}", v, decimals_);
    } else {
      buffer_ += std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
    }
  }
  buffer_ += '\n';
  put(buffer_);
  ++rows_;
}

void CsvWriter::comment(const std::string& text) {
  if (!open_)
    throw std::logic_error("CsvWriter: comment() after close()");
  std::string line = "# " + text;
  for (char& ch : line) {
    if (ch == '\n' || ch == '\r')
      ch = ' ';
  }
  line += '\n';
  put(line);
}

void CsvWriter::flush() {
  if (file_ != nullptr)
    check_write(std::fflush(file_) == 0);
}

void CsvWriter::close() {
  if (!open_)
    return;
  open_ = false;
  if (atomic_) {
    write_file_atomically(path_, contents_);
    contents_ = std::string();
    return;
  }
  const bool flushed = std::fflush(file_) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  check_write(flushed && closed);
}

}  // namespace piezoshift::io
