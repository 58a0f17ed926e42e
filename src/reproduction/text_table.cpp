#include "piezoshift/reproduction/text_table.hpp"

#include <algorithm>

namespace piezoshift::reproduction {

std::size_t display_width(const std::string& s) {
  // Continuation bytes (10xxxxxx) do not start a character.
  return static_cast<std::size_t>(std::count_if(
      s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

std::string text_table(const std::vector<std::vector<std::string>>& rows, int indent) {
  std::vector<std::size_t> width;
  for (const auto& row : rows) {
    if (width.size() < row.size())
      width.resize(row.size(), 0);
    for (std::size_t c = 0; c < row.size(); ++c)
      width[c] = std::max(width[c], display_width(row[c]));
  }
  const std::string margin(static_cast<std::size_t>(std::max(indent, 0)), ' ');
  std::string out;
  const auto line = [&](const std::vector<std::string>& row) {
    std::string text = margin;
    for (std::size_t c = 0; c < width.size(); ++c) {
      const std::string cell = c < row.size() ? row[c] : "";
      const std::string pad(width[c] - display_width(cell), ' ');
      if (c > 0)
        text += "  ";
      text += c == 0 ? cell + pad : pad + cell;
    }
    while (!text.empty() && text.back() == ' ')
      text.pop_back();
    out += text + '\n';
  };
  for (std::size_t r = 0; r < rows.size(); ++r) {
    line(rows[r]);
    if (r == 0) {
      std::size_t total = 0;
      for (std::size_t c = 0; c < width.size(); ++c)
        total += width[c] + (c > 0 ? 2 : 0);
      std::string rule = margin;
      for (std::size_t k = 0; k < total; ++k)
        rule += "─";
      out += rule + '\n';
    }
  }
  return out;
}

}  // namespace piezoshift::reproduction
